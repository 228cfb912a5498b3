// The bandpass wavefront (batch::bandpass_wave, receiver_batch_kernels.hpp): a block of one
// stream runs with section k on SIMD lane k, kWaveSkew samples behind section k - 1. It must be
// the scalar kernel bit for bit: every output, the section outputs after every block, the
// overflow counts and the state the next block starts from. The reference is the per-sample
// form (execute_raw / execute: a block of one, below the wavefront's minimum, so the scalar
// kernel), over cascades of 1 to 8 sections, every rounding and overflow mode, narrow and wide
// words, symmetric and general numerators, blocks shorter and longer than the wavefront's
// prologue, and a block filtered in place.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "model/dsp/bandpass_filter.hpp"
#include "model/dsp/filter_design.hpp"
#include "model/dsp/fixed_point.hpp"
#include "model/dsp/receiver_batch_kernels.hpp"

using namespace ranging;

namespace {

// The paper's Butterworth sections (numerators b0 [1, 0, -1]) then elliptic ones (b1 != 0):
// the first k of them for a cascade of k sections.
std::vector<Biquad> all_sections() {
  std::vector<Biquad> s = design_bandpass(BandpassSpec{}, FilterType::Butterworth).sections;
  const auto e = design_bandpass(BandpassSpec{}, FilterType::Elliptic).sections;
  s.insert(s.end(), e.begin(), e.end());
  return s;
}

SosFilter cascade(std::size_t k) {
  SosFilter f = design_bandpass(BandpassSpec{}, FilterType::Butterworth);
  const auto s = all_sections();
  f.sections.assign(s.begin(), s.begin() + static_cast<long>(k));
  return f;
}

// Tone bursts, full-scale noise, a full-scale square wave (drives the narrow words into
// overflow) and silence, as input codes of `bits`.
std::vector<std::int64_t> stimulus(int bits, std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  const std::int64_t hi = (std::int64_t{1} << (bits - 1)) - 1, lo = -hi - 1;
  std::uniform_int_distribution<std::int64_t> any(lo, hi);
  std::vector<std::int64_t> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    switch ((i / 300) % 4) {
      case 0: x[i] = std::llround(0.7 * static_cast<double>(hi) * std::sin(0.2513 * static_cast<double>(i))); break;
      case 1: x[i] = any(rng); break;
      case 2: x[i] = (i / 12) % 2 ? hi : lo; break;
      default: x[i] = 0;
    }
  }
  return x;
}

// Block lengths cycled over the stream: below, at and above the wavefront's minimum and its
// prologue, and long ones.
const std::size_t kBlocks[] = {64, 1, 65, 700, 13, 4093, 100, 2000, 63, 128};

void expect_fixed_wave_exact(const SosFilter& f, const BandpassFixedConfig& cfg, const std::string& what,
                             bool expect_overflow) {
  const auto x = stimulus(cfg.input_bits, 12000, 7);
  BandpassFixed ref(f, cfg), blocks(f, cfg), inplace(f, cfg);
  std::vector<std::int64_t> y(x.size()), buf;
  std::size_t diff = 0, sect_diff = 0, b = 0;
  for (std::size_t i = 0; i < x.size(); ++b) {
    const std::size_t m = std::min(kBlocks[b % std::size(kBlocks)], x.size() - i);
    blocks.execute_block(std::span<const std::int64_t>(x.data() + i, m), std::span<std::int64_t>(y.data() + i, m));
    buf.assign(x.begin() + static_cast<long>(i), x.begin() + static_cast<long>(i + m));
    inplace.execute_block(std::span<const std::int64_t>(buf), std::span<std::int64_t>(buf));
    for (std::size_t j = 0; j < m; ++j) {
      const std::int64_t r = ref.execute_raw(x[i + j]);
      diff += (r != y[i + j]) + (r != buf[j]);
    }
    sect_diff += (ref.section_outputs() != blocks.section_outputs()) + (ref.section_outputs() != inplace.section_outputs());
    i += m;
  }
  std::printf("[ wave ] %s: %llu overflows\n", what.c_str(), static_cast<unsigned long long>(ref.overflow_events().total()));
  EXPECT_EQ(diff, 0u) << what;
  EXPECT_EQ(sect_diff, 0u) << what;
  for (const BandpassFixed* d : {&blocks, &inplace}) {
    EXPECT_EQ(d->overflow_events().saturations, ref.overflow_events().saturations) << what;
    EXPECT_EQ(d->overflow_events().wraps, ref.overflow_events().wraps) << what;
  }
  if (expect_overflow) {
    EXPECT_GT(ref.overflow_events().total(), 0u) << what << ": the stimulus was meant to overflow";
  } else {
    EXPECT_EQ(ref.overflow_events().total(), 0u) << what;
  }
}

}  // namespace

TEST(BandpassWave, FixedBlocksAreThePerSampleKernelBitForBit) {
  if (!batch::batch_kernels_available()) std::printf("[ wave ] no AVX-512 here: the scalar kernel on both sides\n");
  BandpassFixedConfig base;
  base.coef_frac = 13;  // the elliptic sections need |coef| < 4
  base.acc_bits = 48;
  for (std::size_t k = 1; k <= 8; ++k) {
    const SosFilter f = cascade(k);
    const std::string n = std::to_string(k) + " sections, ";
    expect_fixed_wave_exact(f, base, n + "round half up (folded bias), Q2.14 saturate", false);
    BandpassFixedConfig c = base;
    c.rounding = Rounding::Truncate;
    expect_fixed_wave_exact(f, c, n + "truncate", false);
    c = base;
    c.data_bits = 8;  // Q1.7: overflows on the full-scale input
    c.data_frac = 7;
    c.input_bits = 8;
    c.rounding = Rounding::Convergent;
    expect_fixed_wave_exact(f, c, n + "convergent, Q1.7 saturate", true);
    c.overflow = Overflow::Wrap;
    c.rounding = Rounding::RoundHalfUp;
    expect_fixed_wave_exact(f, c, n + "round half up, Q1.7 wrap", true);
    // 64-bit multiplies (factors beyond int32): an accumulator of at most 62 bits (round half
    // up by the folded bias) and one of 63-64 bits (the bias cannot be folded)
    for (const int data_bits : {22, 28}) {
      c = base;
      c.coef_bits = 36;
      c.coef_frac = 33;
      c.data_bits = data_bits;
      c.data_frac = data_bits - 2;
      c.acc_bits = 64;
      c.acc_bits = bandpass_min_acc_bits(c, f);
      expect_fixed_wave_exact(f, c, n + "coef Q3.33, data Q2." + std::to_string(c.data_frac) + ", acc " +
                                        std::to_string(c.acc_bits) + " bits", false);
    }
  }
}

TEST(BandpassWave, FloatBlocksAreThePerSampleCascadeBitForBit) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> nz(0.0, 0.3);
  std::vector<double> x(12000);
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = ((i / 1500) % 3 == 2) ? 0.0 : 0.6 * std::sin(0.2513 * static_cast<double>(i)) + nz(rng);
  }
  for (std::size_t k = 1; k <= 8; ++k) {
    const SosFilter f = cascade(k);
    BandpassFloat ref(f), blocks(f), inplace(f);
    std::vector<double> y(x.size()), buf;
    std::size_t diff = 0, sect_diff = 0, b = 0;
    for (std::size_t i = 0; i < x.size(); ++b) {
      const std::size_t m = std::min(kBlocks[b % std::size(kBlocks)], x.size() - i);
      blocks.execute_block(std::span<const double>(x.data() + i, m), std::span<double>(y.data() + i, m));
      buf.assign(x.begin() + static_cast<long>(i), x.begin() + static_cast<long>(i + m));
      inplace.execute_block(std::span<const double>(buf), std::span<double>(buf));
      for (std::size_t j = 0; j < m; ++j) {
        const double r = ref.execute(x[i + j]);  // bit patterns: -0.0 is not 0.0
        diff += (std::memcmp(&r, &y[i + j], sizeof r) != 0) + (std::memcmp(&r, &buf[j], sizeof r) != 0);
      }
      const auto& so = ref.section_outputs();
      for (const BandpassFloat* d : {&blocks, &inplace}) {
        sect_diff += std::memcmp(so.data(), d->section_outputs().data(), so.size() * sizeof(double)) != 0;
      }
      i += m;
    }
    EXPECT_EQ(diff, 0u) << k << " sections";
    EXPECT_EQ(sect_diff, 0u) << k << " sections";
  }
}

// The first and last steps of a block hold lanes whose section has no sample there: they keep
// their state and count nothing. Wrapping words leave states off the signal's trajectory (a
// section output jumps by 2^data_bits), from which such a lane's idle computation can overflow:
// many block boundaries on a wrapping, resonating stream, the counts against the per-sample form.
TEST(BandpassWave, IdleLanesCountNoOverflow) {
  BandpassFixedConfig c;
  c.coef_frac = 13;
  c.acc_bits = 48;
  c.input_bits = 8;
  c.data_bits = 8;
  c.data_frac = 7;
  c.overflow = Overflow::Wrap;
  for (const std::size_t k : {2u, 5u, 8u}) {
    const SosFilter f = cascade(k);
    BandpassFixed ref(f, c), blocks(f, c);
    std::vector<std::int64_t> x(20000), y(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = (i / 12) % 2 ? 127 : -128;
    std::size_t diff = 0;
    for (std::size_t i = 0, b = 0; i < x.size(); ++b) {
      const std::size_t m = std::min<std::size_t>(64 + b % 17, x.size() - i);
      blocks.execute_block(std::span<const std::int64_t>(x.data() + i, m), std::span<std::int64_t>(y.data() + i, m));
      for (std::size_t j = 0; j < m; ++j) diff += ref.execute_raw(x[i + j]) != y[i + j];
      i += m;
    }
    EXPECT_EQ(diff, 0u) << k << " sections";
    EXPECT_GT(ref.overflow_events().wraps, 0u) << k << " sections";
    EXPECT_EQ(blocks.overflow_events().wraps, ref.overflow_events().wraps) << k << " sections";
  }
}
