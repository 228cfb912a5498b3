#pragma once
// The receiver's bandpass filter as a cascade of second-order sections (paper 3.3.1), in two
// precisions behind one interface (liquid-dsp style: create, execute, reset):
//   * BandpassFloat: double precision reference, Direct Form I;
//   * BandpassFixed: the bit-accurate model of the hardware, Direct Form I per section:
//       acc = b0*x + b1*x1 + b2*x2 - a1*y1 - a2*y2     (exact integer, acc_bits wide)
//       y   = fx_quantize(acc, coef_frac + data_frac, data format, rounding, overflow)
//     one quantizer per section, nothing else rounds or overflows. Every word length is
//     configuration; see docs/fixed-point.md for the node-by-node table.
// Samples are in full-scale units: the ADC range is [-1, 1).
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "model/dsp/fixed_point.hpp"
#include "model/dsp/receiver_batch_kernels.hpp"
#include "model/dsp/sos.hpp"

namespace ranging {

struct BandpassFixedConfig {  // every word length is configuration
  int input_bits = 12;        // ADC word: signed, Q0.(input_bits-1), full scale [-1, 1)
  int coef_bits = 16;         // coefficients: signed, coef_frac fraction bits,
  int coef_frac = 14;         //   quantized by quantize_coefficient (refused if not fitting)
  int data_bits = 16;         // every section's output (and the cascade output): signed,
  int data_frac = 14;         //   Q2.14 = [-2, 2): the worst-case gain of the paper's
                              //   design (~1.93) needs the second integer bit
  int acc_bits = 40;          // section accumulator; validate() refuses it unless it holds
                              //   the worst case sum of products
  Rounding rounding = Rounding::RoundHalfUp;  // accumulator -> section output
  Overflow overflow = Overflow::Saturate;     // section output (counted)
};

// Throws InputError naming the field and its valid range unless the configuration is
// realizable for `filter`: input_bits 2..32, coef_bits 2..62, coef_frac 0..62, data_bits
// 2..64, data_frac input_bits-1..62 (the input aligns to the data format without rounding),
// every coefficient fits (field "section k b0" etc.), and acc_bits >= the minimum below.
void validate(const BandpassFixedConfig& config, const SosFilter& filter);

// The integers the fixed-point cascade computes with, derived without a filter object (what
// the hardware generator and design_receiver need): per section {b0, b1, b2, a1, a2}, each
// round(c 2^coef_frac) (ties away from zero) in a signed coef_bits word. Validates first
// (validate() above: InputError naming the field); BandpassFixed holds exactly these.
struct BandpassFixedLayout {
  std::vector<std::vector<std::int64_t>> coefficients;
  std::size_t sections() const { return coefficients.size(); }
  std::vector<std::int64_t> flat() const;  // section-major: b0 b1 b2 a1 a2 of section 0, ...
};
BandpassFixedLayout resolve_bandpass_layout(const SosFilter& filter, const BandpassFixedConfig& config);

// Smallest accumulator (signed bits) that holds sum |b_i| * max|x| + sum |a_i| * max|y| for
// every section, with the quantized coefficients and the full ranges of the input and data
// words. With it the accumulator cannot overflow for any input.
int bandpass_min_acc_bits(const BandpassFixedConfig& config, const SosFilter& filter);

// Worst-case magnitude bound at each section output (full-scale units), for inputs in the
// input word's range and no saturation upstream:
//   signal_gain[k]  = ||h_k||_1, h_k the impulse response from the input to node k with the
//                     quantized coefficients (the gain the worst-case input reaches);
//   noise_bound[k]  = sum over sections j <= k of (LSB/2 or LSB for Truncate) * ||g_jk||_1,
//                     g_jk the response from section j's quantizer to node k;
//   peak_bound[k]   = signal_gain[k] * 1 + noise_bound[k];
//   limit[k]        = largest value the data word holds;
//   no_overflow     = peak_bound[k] <= limit for every k: the configuration's headroom claim.
struct BandpassHeadroom {
  std::vector<double> signal_gain, noise_bound, peak_bound;
  double limit = 0;
  bool no_overflow = false;
};
BandpassHeadroom bandpass_headroom(const BandpassFixedConfig& config, const SosFilter& filter);

// Long blocks (when the CPU has AVX-512: fixed >= 540672 samples, float >= 73728) run as 8
// segments in lockstep on SIMD lanes, each lane after the first starting a warm-up early from the
// zero state (fixed 16384 samples, float 8192); a lane whose state at its segment's start is not
// bit for bit the true one is recomputed by the scalar kernel (bandpass_filter.cpp, "time
// split"). The float cascade's lanes meet the true state sooner (no rounding of the state to a
// grid, so no limit cycle to meet) and its split pays from shorter blocks on: decode's 128
// k-sample blocks (measured: docs/results/speed.md). Noise makes the lanes meet the true state; a
// noiseless periodic input can keep them an LSB apart for ever, so after a block with 2 or more
// lanes redone the filter runs the next long blocks plainly (1, 2, 4 .. 64 of them, the count
// doubling while the split keeps failing). Results never depend on any of it; the counts say how
// often it ran, how often a lane had to be redone and how many blocks backed off.
inline constexpr std::size_t kBandpassSplitMin = 540672;  // BandpassFixed's shortest block split (16384 + 8 * 65536)
inline constexpr std::size_t kBandpassFloatSplitMin = 73728;  // BandpassFloat's (8192 + 8 * 8192)
struct BandpassSplitStats {
  std::size_t blocks = 0;      // blocks that ran on the lanes
  std::size_t recomputed = 0;  // lanes recomputed by the scalar kernel
  std::size_t skipped = 0;     // long blocks run plainly, backing off after a failed split
};
struct BandpassSplitBackoff {  // the filter's back-off (kept by reset(): the input is alike)
  std::size_t skip = 0, backoff = 0;
};

// The SIMD kernels' constants of a cascade (receiver_batch_kernels.hpp), zero state, no event
// counters: the float coefficients; for the fixed filter also its shifts, rounding, overflow,
// data range, one-multiply form and whether every factor fits a 32 x 32 multiply. What
// ReceiverFixedBatch / ReceiverFloatBatch, the time split and the wavefront run. The kernels
// hold at most batch::kBatchMaxSections sections: a longer cascade throws InputError (the
// callers run such a cascade on the scalar kernel). Defined after the classes.
class BandpassFixed;
batch::BandpassBatch bandpass_batch_constants(const BandpassFixed& filter);
batch::FloatBandpassBatch bandpass_batch_constants(const std::vector<Biquad>& sections);

class BandpassFilter {  // same API for every precision
 public:
  virtual ~BandpassFilter();
  virtual void reset() = 0;                 // back to the all-zero initial state
  virtual double execute(double x) = 0;     // one sample in, one out (full-scale units)
  // out[i] = execute(in[i]); throws InputError unless the sizes match.
  void execute_block(std::span<const double> in, std::span<double> out);
};

class BandpassFloat final : public BandpassFilter {
 public:
  explicit BandpassFloat(const SosFilter& filter);  // throws InputError if no sections
  void reset() override;
  double execute(double x) override;
  // Block form: out[i] = execute(in[i]) for every i, bit for bit (the same expression per
  // section, in the same order; section_outputs() then holds the last sample's). A block of
  // >= 64 samples with up to 8 sections runs on the wavefront when the CPU has AVX-512
  // (section k on SIMD lane k, kWaveSkew samples behind section k - 1: the recursions
  // overlap in one register, receiver_batch_kernels.hpp); otherwise the state lives in locals
  // (specialized for 1..8 sections) and the out-of-order core overlaps the recursions. Sizes
  // must match (InputError); in and out may alias (an aliased block never takes the time
  // split: its recomputation needs the input; a partly overlapping one runs the scalar loop).
  void execute_block(std::span<const double> in, std::span<double> out);
  const std::vector<double>& section_outputs() const { return out_; }
  BandpassSplitStats split_stats() const { return split_; }  // since construction

  struct State {
    double x1 = 0, x2 = 0, y1 = 0, y2 = 0;
  };

 private:
  std::vector<Biquad> sections_;
  std::vector<State> state_;
  std::vector<double> out_;
  BandpassSplitStats split_;
  BandpassSplitBackoff backoff_;
};

class BandpassFixed final : public BandpassFilter {
 public:
  BandpassFixed(const SosFilter& filter, const BandpassFixedConfig& config);  // validates
  void reset() override;  // also clears the overflow counters
  // Quantizes x to the input word (RoundHalfUp, Saturate, counted in
  // input_overflow_events()) and returns the output as a double.
  double execute(double x) override;
  // Input: signed input_bits integer (InputError if outside); output: signed data_bits
  // integer with data_frac fraction bits.
  std::int64_t execute_raw(std::int64_t x);
  // Block form: out[i] = execute_raw(in[i]) for every i, bit for bit, with the same overflow
  // counts and final state (section_outputs() holds the last sample's). The input range is
  // checked once for the whole block: an out-of-range sample throws InputError and the state
  // and the counters are left as they were (a block that takes the time split checks on its
  // lanes' reads, so `out` may have been written). Sizes must match (InputError).
  // Kernel: the wavefront as BandpassFloat's (>= 64 samples, up to 8 sections, AVX-512; exact
  // integers, overflows counted only for the lanes whose section has a sample at that step),
  // else sample-major with every section's state in registers (specialized per section
  // count 1..8, rounding and overflow at compile time); a long block that does not alias
  // takes the time split (BandpassSplitStats above).
  using BandpassFilter::execute_block;
  void execute_block(std::span<const std::int64_t> in, std::span<std::int64_t> out);
  // Throws InputError naming the first sample of `in` outside the signed input_bits range.
  void check_input(std::span<const std::int64_t> in) const;
  bool sym() const { return sym_ok_; }  // every numerator is b0 [1, 0, -1] (one-multiply form)

  const std::vector<std::int64_t>& section_outputs() const { return out_; }  // last sample, per section
  const std::vector<std::vector<std::int64_t>>& coefficients() const { return coef_; }  // {b0,b1,b2,a1,a2}
  OverflowCounter overflow_events() const { return section_events_; }  // section outputs
  BandpassSplitStats split_stats() const { return split_; }  // since construction
  OverflowCounter input_overflow_events() const { return input_events_; }  // execute(double)
  const BandpassFixedConfig& config() const { return config_; }
  FixedFormat input_format() const { return input_fmt_; }
  FixedFormat data_format() const { return data_fmt_; }
  int accumulator_frac() const { return config_.coef_frac + config_.data_frac; }
  // The designed filter with the quantized coefficients: what the integers implement.
  SosFilter quantized_filter() const;

 private:
  struct State {
    std::int64_t x1 = 0, x2 = 0, y1 = 0, y2 = 0;
  };
  SosFilter filter_;
  BandpassFixedConfig config_;
  FixedFormat input_fmt_, data_fmt_;
  int input_shift_ = 0;  // data_frac - (input_bits - 1)
  std::vector<std::vector<std::int64_t>> coef_;
  std::vector<State> state_;
  std::vector<std::int64_t> out_;
  FxRange data_range_{};
  bool bias_ok_ = false;
  bool sym_ok_ = false;   // every numerator is b0 [1, 0, -1]: one multiply (see .cpp)  // the RoundHalfUp kernel may fold its rounding constant (see .cpp)
  OverflowCounter section_events_, input_events_;
  BandpassSplitStats split_;
  BandpassSplitBackoff backoff_;
  [[noreturn]] void throw_input_range(std::int64_t x_in) const;
};

}  // namespace ranging
