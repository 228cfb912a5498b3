#pragma once
// Parallel matched-filter bank, baseband architecture ("baseband" in configs/).
//
// Every code of the family is correlated on every sample. A direct full-rate FIR per code
// (L*Nc = 700 taps x 9 codes at 5 MS/s = 31.5 GMAC/s) cannot fit a small FPGA, so the
// matched filter to the ideal BPSK excitation is factored (docs/architecture.md):
//
//   1. mixer      B[n] = y[n] * exp(-j*2*pi*f*n/fs)      2 real multiplies / sample
//                  (fs/f = P samples per carrier cycle must be an integer: a P-entry LO table)
//   2. chip       Z[n] = sum_{k=0}^{Nc-1} B[n-k]            running sum, 0 multiplies
//      integrator (boxcar of one chip, Nc = q*fs/f samples; it also cancels the 2f image exactly)
//   3. code       C_j[n] = sum_{m=0}^{L-1} c_j(m) Z[n-(L-1-m)*Nc],  c = +1 for chip 1, -1 for chip 0
//      combiner   (taps one chip apart, shared by all codes; L adds per code, 0 multiplies)
//   4. power      P_j[n] = Re(C_j)^2 + Im(C_j)^2             2 multiplies per code
//   5. energy     E[n] = sum_{k=0}^{L*Nc-1} y[n-k]^2         1 multiply / sample (running sum)
//
// The correlation peak of code j sits at n = n0 + L*Nc - 1 for a burst whose first chip starts
// at n0 (plus the filter's and transducers' group delay). rho^2 = 2 P / (L Nc E) is the
// baseband equivalent of the squared Pearson coefficient (eq. 9) against the ideal excitation.
//
// CorrelatorBankFloat computes this in double; CorrelatorBankFixed is the bit-accurate model
// of the hardware (every node's width, rounding and overflow is listed in CorrelatorFixedConfig).
#include <cstdint>
#include <span>
#include <vector>

#include "model/fixed_point.hpp"

namespace ranging {

// Word lengths of the fixed-point correlator bank. Input y is signed data_bits with data_frac
// fraction bits (the bandpass output).
struct CorrelatorFixedConfig {
  int data_bits = 16, data_frac = 14;  // input y (the bandpass output, Q2.14)
  int lo_bits = 16;                    // LO table: round((2^(lo_bits-1)-1) * cos|sin), signed
  int mix_bits = 18;                   // mixer output B: signed, same integer bits as y;
                                       // round half up, saturate (cannot happen; counted)
  int corr_bits = 16;                  // C_j quantized for squaring: signed corr_bits,
                                       // round half up of C / 2^corr_shift, saturate (counted)
  int corr_shift = -1;                 // -1: automatic (full-scale matched input -> ~0.7 FS)
  int energy_shift = -1;               // norm = E >> energy_shift (truncate); -1: automatic
  int score_bits = 16;                 // rho^2 as an unsigned score_bits fraction
};

// Derived, fully resolved sizes and shifts (what the generator emits as parameters).
struct CorrelatorFixedLayout {
  int period = 0;          // P = fs/f: LO table length
  int chip_samples = 0;    // Nc
  int chips = 0;           // L
  int codes = 0;           // eta
  int mix_frac = 0;        // fraction bits of B
  int mix_shift = 0;       // product (data_frac + lo_bits - 1 frac bits) >> mix_shift -> B
  int chip_bits = 0;       // Z width: mix_bits + ceil(log2 Nc), exact
  int comb_bits = 0;       // C width before quantization: chip_bits + ceil(log2 L), exact
  int corr_shift = 0;
  int power_bits = 0;      // P width: 2*corr_bits - 1 (unsigned, exact)
  int energy_bits = 0;     // E width: 2*data_bits - 1 + ceil(log2 (L*Nc)) (unsigned, exact)
  int energy_shift = 0;
  std::int64_t rho_scale = 0;        // score = floor(P * rho_scale / max(norm, 1)), capped
  std::vector<std::int64_t> lo_cos;  // P entries
  std::vector<std::int64_t> lo_sin;  // P entries
};

// Resolve the layout for a family of `chips`-chip codes. Throws InputError naming the field
// when a width or shift cannot hold the stated bound.
CorrelatorFixedLayout resolve_correlator_layout(const CorrelatorFixedConfig& cfg, int period,
                                                int chip_samples, int chips, int codes);

// rho^2 as an unsigned score_bits fraction: min(2^score_bits - 1, floor(P * rho_scale / max(norm, 1))).
std::uint64_t correlation_score(std::int64_t power, std::uint64_t norm, std::int64_t rho_scale,
                                int score_bits);

class CorrelatorBankFloat {
 public:
  // codes: chips 0/1, all of equal length. period = fs/f, chip_samples = Nc.
  CorrelatorBankFloat(const std::vector<std::vector<std::uint8_t>>& codes, int period,
                      int chip_samples);
  void reset();
  // Feeds one filtered sample; afterwards power() and energy() hold this sample's values.
  void execute(double y);
  const std::vector<double>& power() const { return power_; }  // P_j, j = 0..eta-1
  double energy() const { return energy_; }
  double rho2(int code) const;  // 2 P / (L Nc E), 0 when E == 0
  int codes() const { return static_cast<int>(signs_.size()); }

 private:
  std::vector<std::vector<int>> signs_;
  int period_, chip_samples_, chips_;
  std::int64_t n_ = 0;
  std::vector<double> b_re_, b_im_;  // mixer history, Nc long (ring)
  std::vector<double> z_re_, z_im_;  // chip integrator history, (L-1)*Nc + 1 long (ring)
  std::vector<double> y2_;           // y^2 history, L*Nc long (ring)
  double zsum_re_ = 0, zsum_im_ = 0, energy_ = 0;
  std::vector<double> power_;
};

class CorrelatorBankFixed {
 public:
  CorrelatorBankFixed(const std::vector<std::vector<std::uint8_t>>& codes, int period,
                      int chip_samples, const CorrelatorFixedConfig& cfg);
  void reset();
  // Feeds one filtered sample (signed data_bits integer); afterwards the taps hold its values.
  void execute(std::int64_t y);

  // Stage taps of the last sample, for stage-by-stage comparison with the hardware.
  std::int64_t mix_re() const { return b_re_[pos(b_idx_, 0, b_re_.size())]; }
  std::int64_t mix_im() const { return b_im_[pos(b_idx_, 0, b_im_.size())]; }
  std::int64_t chip_re() const { return zsum_re_; }
  std::int64_t chip_im() const { return zsum_im_; }
  const std::vector<std::int64_t>& corr_re() const { return corr_re_; }  // quantized C_j
  const std::vector<std::int64_t>& corr_im() const { return corr_im_; }
  const std::vector<std::int64_t>& power() const { return power_; }      // P_j
  std::uint64_t energy() const { return energy_; }                       // E, exact
  std::uint64_t norm() const { return energy_ >> layout_.energy_shift; }
  // rho^2 of code j as an unsigned score_bits fraction: floor(P*rho_scale / max(norm,1)), capped.
  std::uint64_t score(int code) const;

  const CorrelatorFixedLayout& layout() const { return layout_; }
  const CorrelatorFixedConfig& config() const { return cfg_; }
  OverflowCounter overflow_events() const { return counter_; }
  int codes() const { return static_cast<int>(signs_.size()); }

 private:
  static std::size_t pos(std::size_t idx, std::size_t back, std::size_t size) {
    return (idx + size - back) % size;
  }
  CorrelatorFixedConfig cfg_;
  CorrelatorFixedLayout layout_;
  FixedFormat mix_fmt_, corr_fmt_;
  std::vector<std::vector<int>> signs_;
  std::int64_t phase_ = 0;
  std::size_t b_idx_ = 0, z_idx_ = 0, y_idx_ = 0;
  std::vector<std::int64_t> b_re_, b_im_, z_re_, z_im_, y2_;
  std::int64_t zsum_re_ = 0, zsum_im_ = 0;
  std::uint64_t energy_ = 0;
  std::vector<std::int64_t> corr_re_, corr_im_, power_;
  OverflowCounter counter_;
};

}  // namespace ranging
