#pragma once
// The SIMD kernels of ReceiverFixedBatch (receiver_batch.hpp): the fixed bandpass cascade and
// the correlator bank's full-rate front end and decimated outputs, on kBatchLanes independent
// streams in lockstep, one stream per 64-bit lane. The arithmetic is the scalar model's
// (BandpassFixed's kernel, CorrelatorBankFixed::feed / decimated_output), operation for
// operation on exact integers, so every lane is bit for bit the scalar stream: the tests
// compare them (tests/test_receiver_batch.cpp).
//
// receiver_batch_kernels_v4.cpp is compiled for x86-64-v4 (AVX-512 F/DQ/VL/BW) and called only
// when the CPU has it (batch_kernels_available()); elsewhere ReceiverFixedBatch runs the scalar
// receiver per stream. This header therefore holds plain data only: no inline code a
// differently compiled translation unit could share (std containers stay out of the kernel TU).
#include <cstddef>
#include <cstdint>

#include "model/dsp/fixed_point.hpp"

namespace ranging::batch {

constexpr int kBatchLanes = 8;
constexpr int kBatchMaxSections = 8;

// One value per lane, 64-byte aligned (one AVX-512 register).
struct alignas(64) Lanes {
  std::int64_t v[kBatchLanes];
};

// Bandpass cascade: the constants and the state of every lane (BandpassFixed's, per lane).
struct BandpassBatch {
  int sections = 0;
  std::int64_t coef[kBatchMaxSections][5] = {};  // {b0, b1, b2, a1, a2}, coef_frac fraction bits
  int input_shift = 0;                           // input code << input_shift: the data format
  int qshift = 0;                                // accumulator -> data: bits dropped (coef_frac)
  Rounding rounding = Rounding::RoundHalfUp;
  Overflow overflow = Overflow::Saturate;
  FxRange range{};                               // the data format
  bool narrow = false;  // every multiplicand fits int32: 32 x 32 -> 64 multiplies
  bool sym = false;     // every numerator is b0 [1, 0, -1]: b0 (x - x2), one multiply
  Lanes x1{}, x2{};     // section 0's input history
  Lanes y1[kBatchMaxSections] = {}, y2[kBatchMaxSections] = {};
  OverflowCounter* events = nullptr;  // kBatchLanes counters: the section outputs' overflows
};

// Correlator bank: the layout's constants (CorrelatorFixedLayout) and every lane's state, in
// arrays the owner allocates (sizes in the comments).
struct BankBatch {
  int period = 0, decimation = 0, taps = 0, chips = 0, codes = 0, step = 0;  // step = Nc / D
  int mix_shift = 0, chip_shift = 0, corr_shift = 0;
  FxRange mix_range{}, chip_range{}, corr_range{};
  bool fir_narrow = false;    // taps and Bd fit int32
  bool power_narrow = false;  // C_q fits int32
  bool weight_narrow = false; // P and w fit uint32: Q = P w by a 32 x 32 -> 64 unsigned multiply
  const std::int64_t* lo_cos = nullptr;    // period
  const std::int64_t* lo_nsin = nullptr;   // period: -lo_sin (the mixer's imaginary product)
  const std::int64_t* taps_rev = nullptr;  // taps, reversed
  const std::int64_t* sign_mask = nullptr; // codes x chips: 0 for chip 1 (+1), -1 for chip 0
  const std::int64_t* weights = nullptr;   // codes
  std::size_t window = 0, bd_n = 0, f_n = 0;
  // state
  int phase = 0, dec_phase = 0;
  std::size_t y_idx = 0, bd_idx = 0, f_idx = 0;
  Lanes acc_re{}, acc_im{}, energy{};
  Lanes* b_re = nullptr;  // period
  Lanes* b_im = nullptr;
  Lanes* y2h = nullptr;   // window
  Lanes* bd_re = nullptr; // 2 bd_n (a ring stored twice)
  Lanes* bd_im = nullptr;
  Lanes* f_re = nullptr;  // 2 f_n
  Lanes* f_im = nullptr;
  Lanes* q = nullptr;     // codes: Q_j of the last decimated output
  OverflowCounter* mix_events = nullptr;  // kBatchLanes counters each
  OverflowCounter* chip_events = nullptr;
  OverflowCounter* corr_events = nullptr;
};

// ---- the float receiver (ReceiverFloatBatch): the same structure in double ----------------
// IEEE double operations per lane in the scalar model's order (BandpassFloat's expression left
// to right, CorrelatorBankFloat::feed / decimated_output), compiled without contraction
// (-ffp-contract=off: no fused multiply-add the scalar build does not do), so every lane is the
// scalar stream's doubles bit for bit.
struct alignas(64) LanesF {
  double v[kBatchLanes];
};

struct FloatBandpassBatch {
  int sections = 0;
  double coef[kBatchMaxSections][5] = {};  // {b0, b1, b2, a1, a2}
  LanesF x1[kBatchMaxSections] = {}, x2[kBatchMaxSections] = {};
  LanesF y1[kBatchMaxSections] = {}, y2[kBatchMaxSections] = {};
};

struct FloatBankBatch {
  int period = 0, decimation = 0, chips = 0, codes = 0, step = 0;
  std::size_t window = 0, bd_n = 0, f_n = 0;
  const double* lo_cos = nullptr;  // period (CorrelatorBankFloat's tables)
  const double* lo_sin = nullptr;
  const double* taps = nullptr;    // bd_n chip taps g[i]
  const double* signs = nullptr;   // codes x chips: +1.0 or -1.0
  const double* gain = nullptr;    // codes: K_j
  // state
  std::size_t b_idx = 0, y_idx = 0, bd_idx = 0, f_idx = 0;
  int dec_phase = 0;
  LanesF acc_re{}, acc_im{}, energy{};
  LanesF* b_re = nullptr;  // period
  LanesF* b_im = nullptr;
  LanesF* y2h = nullptr;   // window
  LanesF* bd_re = nullptr; // 2 bd_n
  LanesF* bd_im = nullptr;
  LanesF* f_re = nullptr;  // 2 f_n
  LanesF* f_im = nullptr;
  LanesF* q = nullptr;     // codes
};

void bandpass_batch_float(FloatBandpassBatch& s, const LanesF* in, LanesF* out, std::size_t n);
std::size_t bank_feed_batch_float(FloatBankBatch& s, const LanesF* in, std::size_t n, bool* ready);
// PeakDetectorFloat::gate of the decimated output in s.q / s.energy, lane by lane: bit l is set
// when (E > 0 ? top / E : 0) >= threshold and E >= min_energy, top = max_j Q_j (compared in
// code order, as the detector's argmax).
unsigned gate_batch_float(const FloatBankBatch& s, double threshold, double min_energy);

// ---- one stream's cascade on the lanes: the wavefront --------------------------------------
// Section k of ONE stream runs on lane k (N <= kBatchMaxSections sections), kWaveSkew samples
// behind section k - 1: at step i lane k computes sample i - kWaveSkew k, from the output lane
// k - 1 computed kWaveSkew steps before. Every section's sample is the scalar kernel's expression
// on the same values (BandpassFixed's exact integers, rounding and overflow; BandpassFloat's
// doubles left to right, no contraction), so the output and the final state are the scalar
// kernel's bit for bit; only the order in which the CPU meets the operations differs. The skew
// takes the output of the previous section off the loop-carried path: a step waits on its own
// lane's y1 only (the a1 y1 product and two subtractions), and the N recursions overlap in one
// register. The first and last kWaveSkew (N - 1) steps have lanes outside the block: their state
// is kept (mask blends) and their overflows are not counted. n = 0 is allowed.
constexpr int kWaveSkew = 3;

// Lane k: section k's state (BandpassFixed::State / BandpassFloat::State): its input history
// x1, x2 and output history y1, y2. Lanes >= sections are unused.
struct WaveState {
  Lanes x1{}, x2{}, y1{}, y2{};
};
struct WaveStateF {
  LanesF x1{}, x2{}, y1{}, y2{};
};

// out[i] = the cascade of in[i] for i < n (input codes in range: the caller checks), with the
// constants of c (c's own state and events are not used); `bias`: round half up by a folded
// 2^(qshift-1) (BandpassFixed's bias_ok: |acc| < 2^61 and qshift >= 1), else c.rounding.
// Overflows of section outputs are handled by c.overflow and counted in `events`. in and out
// may be the same array, not otherwise overlapping.
void bandpass_wave(const BandpassBatch& c, bool bias, WaveState& s, const std::int64_t* in, std::int64_t* out,
                   std::size_t n, OverflowCounter& events);
void bandpass_wave_float(const FloatBandpassBatch& c, WaveStateF& s, const double* in, double* out, std::size_t n);

// True when this build has the kernels and the CPU runs them.
bool batch_kernels_available();

// Interleave: out[i].v[l] = src[l][i] * gain (one IEEE multiply, as the scalar receiver's
// input scaling) for i < n and every lane l < kBatchLanes (src[l] has n readable values), by
// 8 x 8 transposes.
void interleave_batch_float(const double* const* src, double gain, LanesF* out, std::size_t n);
// out[i].v[l] = src[l][i]; *lo and *hi become min(*lo, every value) and max(*hi, every value).
void interleave_batch(const std::int64_t* const* src, Lanes* out, std::size_t n, std::int64_t* lo, std::int64_t* hi);

// The inverse: dst[l][i] = in[i].v[l] for i < n and every lane l (dst[l] has n writable values).
void deinterleave_batch(const Lanes* in, std::int64_t* const* dst, std::size_t n);
void deinterleave_batch_float(const LanesF* in, double* const* dst, std::size_t n);

// out[i] = the cascade of in[i] (input codes, in range: the caller checks) for i < n, per lane.
void bandpass_batch(BandpassBatch& s, const Lanes* in, Lanes* out, std::size_t n);

// Feeds y[0..] up to and including the sample that completes a decimated output (then computes
// it: s.q and s.energy hold it, and *ready is set) or to n; returns how many were consumed.
std::size_t bank_feed_batch(BankBatch& s, const Lanes* y, std::size_t n, bool* ready);

}  // namespace ranging::batch
