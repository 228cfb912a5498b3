#pragma once
// Parallel matched-filter bank (architecture "baseband", docs/architecture.md).
//
// Every code of the family is correlated on every decimated sample. A direct full-rate FIR per
// code (9 codes x ~900 taps at 5 MS/s = 40 GMAC/s) cannot fit a small FPGA, so the matched
// filter to the received burst of code j, sum_m c_j(m) h(n - m Nc) with h the received
// response to one chip, is factored into stages shared by all codes:
//
//   1. mixer        B[n]  = y[n] exp(-j 2 pi n / P)            P = fs/f samples per carrier cycle
//   2. decimator    Bd[k] = sum_{i<P} B[kD + D-1 - i]           one carrier cycle of B, every D-th
//                   (a moving sum over exactly one cycle cancels the mixer's 2f image exactly)
//   3. chip filter  F[k]  = sum_{i<M} g[i] Bd[k-i]              g: the chip template, time reversed
//   4. combiner     C_j[k] = sum_m c_j(m) F[k - (L-1-m) Nc/D]   c = +1 for chip 1, -1 for chip 0
//   5. power        P_j[k] = |C_j[k]|^2
//   6. weight       Q_j[k] = P_j[k] w_j                         w_j = 1 / (P/E of code j's own template)
//   7. energy       E[n]  = sum_{i<W} y[n-i]^2                  over the template span W
// so rho_j^2 = Q_j / E is 1 when the input is exactly code j's template (any amplitude), and by
// Cauchy-Schwarz no other code's template reaches it: argmax_j Q_j is the matched-filter
// decision. The combiner taps are one chip apart and shared, so a code costs L adds, not a FIR.
//
// CorrelatorBankFloat computes this in double; CorrelatorBankFixed is the bit-accurate model
// of the hardware: every node's width, rounding and overflow is in CorrelatorFixedLayout.
#include <complex>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "model/dsp/fixed_point.hpp"

namespace ranging {

struct FixedBankLanes;  // bank_lanes.hpp: the bank on the SIMD lanes

// What the bank correlates against, derived by the receiver design (receiver.hpp) from the
// configuration: the chip template and every code's normalization.
struct CorrelatorReference {
  int period = 25;              // P = fs / f
  int chip_samples = 100;       // Nc = q fs / f
  int decimation = 5;           // D, divides Nc
  int window = 900;             // W: energy window (the template span), samples
  std::vector<double> chip_taps;          // g[i], i < M (real, peak 1)
  std::vector<std::vector<std::uint8_t>> codes;  // chips 0/1, all of length L
  std::vector<double> code_gain;          // K_j = P_j / E at code j's template peak (float)
  // Largest |F| and |C_j| (float bank) over all code templates, per unit peak input amplitude:
  // they place a full-scale input 6 dB below the top of the fixed chip and corr words.
  double chip_peak = 0, corr_peak = 0;
};

// Word lengths of the fixed-point bank. Input y is signed data_bits with data_frac fraction bits.
struct CorrelatorFixedConfig {
  int data_bits = 16, data_frac = 14;  // input y (the bandpass output, Q2.14)
  int lo_bits = 16;                    // LO table: round((2^(lo_bits-1)-1) cos|sin), signed
  int mix_bits = 18;                   // mixer output B: same integer bits as y; round half up,
                                       //   saturate (cannot trigger; counted)
  int tap_bits = 16;                   // chip template taps: signed, tap_bits-1 fraction bits
  int chip_bits = 20;                  // F quantized: round half up of F / 2^chip_shift,
                                       //   saturate (counted); a full-scale template peaks
                                       //   6 dB below the top
  int corr_bits = 16;                  // C_j quantized for squaring: round half up of
                                       //   C / 2^corr_shift, saturate (counted)
  int corr_shift = -1;                 // -1: automatic (a full-scale template peaks 6 dB
                                       //   below the top of corr_bits)
  int weight_bits = 16;                // w_j: unsigned, normalized per code
  int energy_shift = -1;               // norm = E >> energy_shift (truncate); -1: automatic
  int score_bits = 16;                 // rho^2 as an unsigned score_bits fraction
};

// Derived, fully resolved sizes, shifts and constants (what the generator emits).
struct CorrelatorFixedLayout {
  int period = 0, chip_samples = 0, decimation = 0, chips = 0, codes = 0, taps = 0, window = 0;
  int mix_frac = 0;        // fraction bits of B
  int mix_shift = 0;       // product (data_frac + lo_bits - 1 fraction bits) >> mix_shift -> B
  int dec_bits = 0;        // Bd: mix_bits + ceil(log2 P), exact
  int fir_bits = 0;        // F before quantization: exact bound of sum |g_q| |Bd| (the
                           //   accumulator width; it cannot overflow)
  int chip_shift = 0;      // F_q = round(F / 2^chip_shift), chip_bits wide
  int comb_bits = 0;       // C: chip_bits + ceil(log2 L), exact
  int corr_shift = 0;      // C_q = round(C / 2^corr_shift), corr_bits wide
  int power_bits = 0;      // P: 2 corr_bits, unsigned, exact (holds 2 (2^(corr_bits-1))^2)
  int weighted_bits = 0;   // Q = P w: power_bits + weight_bits, unsigned, exact
  int energy_bits = 0;     // E: 2 data_bits - 1 + ceil(log2 W), unsigned, exact
  int energy_shift = 0;    // norm = E >> energy_shift
  std::vector<std::int64_t> lo_cos, lo_sin;  // P entries each
  std::vector<std::int64_t> taps_q;          // M chip template taps
  std::vector<std::int64_t> weights;         // w_j, one per code
};

// score = min(2^score_bits - 1, floor(Q / max(norm, 1))): rho^2 as a score_bits fraction.
std::uint64_t correlation_score(std::uint64_t weighted_power, std::uint64_t norm, int score_bits);

class CorrelatorBankFloat {
 public:
  explicit CorrelatorBankFloat(const CorrelatorReference& ref);
  void reset();
  // Feeds one filtered sample. Returns true when a decimated output was produced; then
  // weighted_power() and energy() hold its values.
  bool execute(double y);
  // Block form: feeds y[0], y[1], ... up to and including the first sample that completes a
  // decimated output, or to the end of y; returns how many were consumed, and output_ready()
  // tells whether the last one completed an output. The same operations in the same order as
  // execute() on each sample (bit for bit; the state is held in locals, which the per-sample
  // form cannot do: its stores to the histories may alias the members); execute() is a feed
  // of one.
  std::size_t feed(std::span<const double> y);
  bool output_ready() const { return ready_; }
  // Block form with its outputs handed over: feeds all of y, as feed() over it would, and calls
  // out(Q_j, prev, n, E) for every decimated output in order (prev the previous output's Q_j,
  // zeros before the first, n the full-rate index of its last input, E its energy: what
  // PeakDetectorFloat::execute reads). The state and the accessors afterwards
  // are feed()'s, bit for bit. The front end runs sample by sample (its running sums are
  // sequential); then the chip filter and the combiner of a run of outputs are computed across
  // the outputs (one output per SIMD lane, each with execute()'s operations in execute()'s
  // order: the same doubles), before the outputs go to `out` (which must not use this bank:
  // its accessors are the block's last output's only at the end). An empty y changes nothing.
  using OutputSink =
      std::function<void(std::span<const double> q, std::span<const double> prev, std::int64_t n, double energy)>;
  void feed_outputs(std::span<const double> y, const OutputSink& out);
  const std::vector<double>& weighted_power() const { return q_; }  // Q_j = P_j / K_j
  double energy() const { return energy_; }
  double rho2(int code) const { return energy_ > 0 ? q_.at(code) / energy_ : 0.0; }
  // |F| and max_j |C_j| of the last output (std::hypot, computed when asked: only the
  // design-time scaling probe reads them, so the per-output path keeps F and C_j instead).
  double chip_magnitude() const;
  double max_corr_magnitude() const;
  std::int64_t sample_index() const { return n_ - 1; }  // full-rate index of the last input
  int codes() const { return static_cast<int>(q_.size()); }
  const CorrelatorReference& reference() const { return ref_; }
  // The LO tables cos / sin(2 pi p / P), p < P (ReceiverFloatBatch mixes with the very values).
  const std::vector<double>& lo_cos() const { return lo_cos_; }
  const std::vector<double>& lo_sin() const { return lo_sin_; }

 private:
  CorrelatorReference ref_;
  int chips_;
  std::int64_t n_ = 0;
  double acc_re_ = 0, acc_im_ = 0;             // moving sum of B over one carrier cycle
  std::vector<double> b_re_, b_im_;            // B history, P long
  std::size_t b_idx_ = 0;                      // = n mod P: also the LO phase
  std::vector<double> lo_cos_, lo_sin_;        // cos / sin(2 pi p / P), p < P (as computed per sample)
  // Bd (M) and F ((L-1) Nc/D + 1) histories, each ring stored twice (slots i and i + size):
  // a window ending at the newest entry is contiguous, no modulo per tap.
  std::vector<double> bd_re_, bd_im_;
  std::vector<double> f_re_, f_im_;
  std::vector<double> y2_;                     // y^2 history, W long
  std::size_t bd_idx_ = 0, f_idx_ = 0, y_idx_ = 0, bd_n_ = 0, f_n_ = 0;
  int dec_phase_ = 0;
  double energy_ = 0, f_last_re_ = 0, f_last_im_ = 0;
  bool ready_ = false;
  std::vector<double> q_, c_re_, c_im_;  // Q_j and C_j of the last output
  // feed_outputs' buffers: per output Bd, F, E, n (after the histories), C_j, Q_j code-major and
  // Q_j row by row after the previous output's
  std::vector<double> run_bd_re_, run_bd_im_, run_f_re_, run_f_im_, run_e_, run_cre_, run_cim_, run_q_, run_rows_;
  std::vector<std::int64_t> run_n_;
  std::vector<double> signs_;  // codes x chips: +1.0 for chip 1, -1.0 for chip 0
  void decimated_output();
  void output_run(std::size_t k, const OutputSink& out);
  template <class AtOutput>
  std::size_t front_end(std::span<const double> in, AtOutput&& at_output);
};

class CorrelatorBankFixed {
 public:
  // The reference's float taps and gains are quantized here (layout); bad widths throw InputError.
  CorrelatorBankFixed(const CorrelatorReference& ref, const CorrelatorFixedConfig& cfg);
  void reset();
  // Feeds one filtered sample (signed data_bits integer). Returns true on a decimated output.
  bool execute(std::int64_t y);
  // Block form: feeds y[0], y[1], ... up to and including the first sample that completes a
  // decimated output, or to the end of y; returns how many were consumed. output_ready() then
  // says whether the last one consumed produced an output (the state every accessor below
  // reads is then that output's). Bit for bit the same as execute() on each sample; execute()
  // is a feed of one. Ranges are not checked (the bandpass output is in range by construction).
  std::size_t feed(std::span<const std::int64_t> y);
  bool output_ready() const { return ready_; }

  // Long-block form (the time split): feeds all of y, as feed() over it would, and calls
  // out(Q_j, n, norm) for every decimated output in order (n the full-rate index of its last
  // input, norm = E >> energy_shift: what PeakDetectorFixed::execute reads). The state, the
  // accessors and the overflow counts afterwards are feed()'s, bit for bit. Runs only when the
  // block is long enough for it (split_min_samples()) and the CPU has the SIMD kernels
  // (receiver_batch_kernels.hpp); returns false, having done nothing, otherwise.
  //   The bank has finite memory: its state after sample t is a function of the last
  // split_memory() samples and of t mod lcm(P, D) alone (exact integers: the moving sums and
  // the energy add and subtract exactly; every ring is overwritten within that span), and the
  // reset state is the state after that many zeros. So the block runs as kBatchLanes segments
  // in lockstep, one per SIMD lane: lane 0 from the bank's state, lane l >= 1 from reset,
  // split_memory() samples before its segment (a whole number of lcm(P, D) after lane 0, so
  // all lanes share the LO and decimation phases), its outputs and overflow counts taken from
  // its segment's first sample on. No check is needed (the bandpass's IIR split must check):
  // the warm-up lane is in the true state by construction. The outputs wait per lane and go
  // to `out` in sample order; then the bank re-runs the split_memory() samples before the end
  // of the last segment from reset (the same argument) and feeds the rest of the block.
  // prev: the previous output's Q_j (the bank's weighted_power() before the block for the first).
  using OutputSink = std::function<void(std::span<const std::uint64_t> q, std::span<const std::uint64_t> prev,
                                        std::int64_t n, std::uint64_t norm)>;
  bool feed_split(std::span<const std::int64_t> y, const OutputSink& out);
  std::size_t split_memory() const;      // H = max(W, D (f_n + M - 1) + P), rounded up to lcm(P, D)
  std::size_t split_min_samples() const; // the shortest block feed_split takes
  // The longest piece split at once: the lanes' outputs wait in at most 32 MiB; a longer block
  // is split piece by piece (and none is split when this is under twice split_min_samples()).
  std::size_t split_max_samples() const;
  std::size_t split_blocks() const { return split_blocks_; }  // pieces split since construction

  // Stage taps of the last decimated output, for stage-by-stage comparison with the hardware.
  std::int64_t mix_re() const { return mix_re_; }  // last full-rate mixer output
  std::int64_t mix_im() const { return mix_im_; }
  std::int64_t dec_re() const { return bd_re_[bd_idx_]; }
  std::int64_t dec_im() const { return bd_im_[bd_idx_]; }
  std::int64_t chip_re() const { return f_re_[f_idx_]; }  // F_q
  std::int64_t chip_im() const { return f_im_[f_idx_]; }
  const std::vector<std::int64_t>& corr_re() const { return corr_re_; }  // C_q per code
  const std::vector<std::int64_t>& corr_im() const { return corr_im_; }
  const std::vector<std::uint64_t>& power() const { return p_; }           // P_j
  const std::vector<std::uint64_t>& weighted_power() const { return q_; }  // Q_j
  std::uint64_t energy() const { return energy_; }                         // E, exact
  std::uint64_t norm() const { return energy_ >> layout_.energy_shift; }
  std::uint64_t score(int code) const {
    return correlation_score(q_.at(code), norm(), cfg_.score_bits);
  }
  std::int64_t sample_index() const { return n_ - 1; }

  const CorrelatorFixedLayout& layout() const { return layout_; }
  const CorrelatorFixedConfig& config() const { return cfg_; }
  // Saturation events: all nodes, and per saturating node (mixer B, chip F_q, corr C_q).
  OverflowCounter overflow_events() const { return mix_events_ + chip_events_ + corr_events_; }
  OverflowCounter mix_overflow_events() const { return mix_events_; }
  OverflowCounter chip_overflow_events() const { return chip_events_; }
  OverflowCounter corr_overflow_events() const { return corr_events_; }
  // Exact values before quantization of the last decimated output: the chip filter's
  // accumulator F (fir_bits) and the combiner's C_j (comb_bits) of every code.
  std::int64_t chip_acc_re() const { return chip_acc_re_; }
  std::int64_t chip_acc_im() const { return chip_acc_im_; }
  const std::vector<std::int64_t>& comb_re() const { return comb_re_; }
  const std::vector<std::int64_t>& comb_im() const { return comb_im_; }
  int codes() const { return static_cast<int>(q_.size()); }

 private:
  CorrelatorFixedConfig cfg_;
  CorrelatorFixedLayout layout_;
  std::vector<std::vector<int>> signs_;
  std::vector<std::int64_t> sign_mask_;     // signs_ row-major, codes x chips, as masks: 0 for +1, -1 for -1
  std::vector<std::int64_t> taps_rev_;      // taps_q reversed: the FIR reads forward
  FixedFormat mix_fmt_, chip_fmt_, corr_fmt_;
  FxRange mix_range_, chip_range_, corr_range_;
  std::int64_t n_ = 0;
  int phase_ = 0;      // LO phase = index into b_ (they advance together), wraps by compare
  int dec_phase_ = 0;  // samples since the last decimated output
  bool ready_ = false;
  void decimated_output();
  std::int64_t mix_re_ = 0, mix_im_ = 0, acc_re_ = 0, acc_im_ = 0;
  std::vector<std::int64_t> b_re_, b_im_;  // B history, P long (slot phase_)
  // Bd (M taps) and F ((L-1) Nc/D + 1) histories as rings stored twice (slot i and i + size)
  // so that a window ending at the newest entry is contiguous: no modulo in the loops.
  std::vector<std::int64_t> bd_re_, bd_im_, f_re_, f_im_;
  std::size_t bd_n_ = 0, f_n_ = 0;  // ring sizes (half the vectors)
  std::vector<std::uint64_t> y2_;
  std::size_t bd_idx_ = 0, f_idx_ = 0, y_idx_ = 0;
  std::uint64_t energy_ = 0;
  std::vector<std::int64_t> corr_re_, corr_im_;
  std::vector<std::uint64_t> p_, q_;
  std::int64_t chip_acc_re_ = 0, chip_acc_im_ = 0;
  std::vector<std::int64_t> comb_re_, comb_im_;
  OverflowCounter mix_events_, chip_events_, corr_events_;
  // feed_split's scratch: every lane's outputs (Q_j, norm; n follows from the phase), kept
  // for the next block.
  std::vector<std::uint64_t> split_q_, split_norm_;
  std::size_t split_blocks_ = 0;
  friend struct FixedBankLanes;
  void clear_state();  // reset() but the overflow counters and the sample index
  void split_piece(std::span<const std::int64_t> y, const OutputSink& out);
};

// The float front end (mixer + one-cycle moving sum + decimation by D) applied to a whole
// signal from rest: what the bank's chip filter sees. Used to derive the chip template.
std::vector<std::complex<double>> baseband_decimate(std::span<const double> x, int period,
                                                    int decimation);

// Resolve the layout: widths from the bounds of every node, the LO table, the quantized taps
// and the per-code weights w_j = 2^(score_bits + 2 data_frac - energy_shift) / (K_j s_P), where
// s_P is the exact scale from float P to fixed P, so that score = Q / norm = rho^2 2^score_bits.
// Throws InputError naming the field when a width cannot hold its bound.
CorrelatorFixedLayout resolve_correlator_layout(const CorrelatorReference& ref,
                                                const CorrelatorFixedConfig& cfg);

}  // namespace ranging
