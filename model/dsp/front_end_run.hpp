#pragma once
// The correlator bank's front end (stages 1, 2 and 7 of correlator_bank.hpp: the mixer, the
// moving sum over one carrier cycle, the energy window) walks three indices sample by sample:
//   phase      the LO table's and the moving sum's slot, 0 .. P - 1, then back to 0;
//   y_idx      the energy ring's newest slot, 0 .. W - 1: it advances before the sample uses it;
//   dec_phase  samples since the last decimated output, 0 .. D - 1: an output every D samples.
// A run is the samples up to the next wrap or output (at most D): inside one, sample u uses
// slot phase + u and energy slot y0 + u, and nothing is tested. The banks loop over runs and
// do each sample's work in the order the per-sample loop did, so the results are the same bits.
// Used by CorrelatorBankFloat::front_end, CorrelatorBankFixed::feed and their 8-lane kernels
// (receiver_batch_kernels_v4.cpp, built for AVX-512): the functions have internal linkage (an
// unnamed namespace), so each translation unit compiles its own copy for its own ISA.
#include <algorithm>
#include <cstddef>

namespace ranging {
namespace {

struct FrontEndRun {
  std::size_t len = 0;  // samples in the run, >= 1 while samples are left
  std::size_t y0 = 0;   // the energy ring's slot of its first sample
};

// The next run of at most `left` samples (phase < period, y_idx < window, dec_phase < decimation).
template <class Phase>
inline FrontEndRun front_end_run(std::size_t left, Phase phase, Phase period, std::size_t y_idx, std::size_t window,
                                 int dec_phase, int decimation) {
  FrontEndRun r;
  r.y0 = y_idx + 1 == window ? 0 : y_idx + 1;
  r.len = std::min({left, static_cast<std::size_t>(period - phase), window - r.y0,
                    static_cast<std::size_t>(decimation - dec_phase)});
  return r;
}

// The indices after the run r; true when its last sample completed a decimated output.
template <class Phase>
inline bool front_end_advance(const FrontEndRun& r, Phase& phase, Phase period, std::size_t& y_idx, int& dec_phase,
                              int decimation) {
  phase += static_cast<Phase>(r.len);
  if (phase == period) phase = 0;
  y_idx = r.y0 + r.len - 1;
  dec_phase += static_cast<int>(r.len);
  if (dec_phase != decimation) return false;
  dec_phase = 0;
  return true;
}

}  // namespace
}  // namespace ranging
