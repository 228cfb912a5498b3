#include "model/correlator_bank.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <string>

#include "model/error.hpp"

namespace ranging {
namespace {

int ceil_log2(std::int64_t v) {
  int b = 0;
  while ((std::int64_t{1} << b) < v) ++b;
  return b;
}

std::vector<std::vector<int>> code_signs(const std::vector<std::vector<std::uint8_t>>& codes) {
  if (codes.empty()) throw InputError("correlator bank: the code family has no codes");
  std::vector<std::vector<int>> signs;
  for (const auto& c : codes) {
    if (c.size() != codes.front().size() || c.empty()) {
      throw InputError("correlator bank: all codes must have the same, non-zero length");
    }
    std::vector<int> s;
    for (std::uint8_t chip : c) s.push_back(chip ? 1 : -1);
    signs.push_back(std::move(s));
  }
  return signs;
}

void check_geometry(int period, int chip_samples) {
  require_in_range("correlator: samples per carrier cycle (fs/f)", period, 2, 4096);
  require_in_range("correlator: samples per chip", chip_samples, period, 1 << 16);
  if (chip_samples % period != 0) {
    throw InputError("correlator: samples per chip must be a whole number of carrier cycles");
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Layout: every width follows from the bound of its node, so no exact node can overflow.

CorrelatorFixedLayout resolve_correlator_layout(const CorrelatorFixedConfig& cfg, int period,
                                                int chip_samples, int chips, int codes) {
  check_geometry(period, chip_samples);
  require_in_range("correlator.data_bits", cfg.data_bits, 2, 32);
  require_in_range("correlator.data_frac", cfg.data_frac, 0, cfg.data_bits - 1);
  require_in_range("correlator.lo_bits", cfg.lo_bits, 3, 24);
  require_in_range("correlator.mix_bits", cfg.mix_bits, 2, 32);
  require_in_range("correlator.corr_bits", cfg.corr_bits, 2, 31);
  require_in_range("correlator.score_bits", cfg.score_bits, 4, 24);
  require_in_range("code length (chips)", chips, 1, 1023);

  CorrelatorFixedLayout l;
  l.period = period;
  l.chip_samples = chip_samples;
  l.chips = chips;
  l.codes = codes;
  const int int_bits = cfg.data_bits - cfg.data_frac;  // integer bits of y (incl. sign)
  l.mix_frac = cfg.mix_bits - int_bits;
  l.mix_shift = cfg.data_frac + cfg.lo_bits - 1 - l.mix_frac;
  if (l.mix_shift < 0) {
    throw InputError("correlator.mix_bits: " + std::to_string(cfg.mix_bits) +
                     " keeps more fraction bits than the product has; valid range is [2, " +
                     std::to_string(cfg.data_bits + cfg.lo_bits - 1) + "]");
  }
  l.chip_bits = cfg.mix_bits + ceil_log2(chip_samples);
  l.comb_bits = l.chip_bits + ceil_log2(chips);
  if (l.comb_bits > 62) {
    throw InputError("correlator: combiner width " + std::to_string(l.comb_bits) +
                     " bits exceeds 62; lower correlator.mix_bits");
  }
  if (cfg.corr_shift >= 0) {
    l.corr_shift = cfg.corr_shift;
  } else {
    // A full-scale matched sine gives |C| = L*Nc/2 * 2^mix_frac * 2^(int_bits-1); aim at
    // 2^(corr_bits-1) so the complex magnitude has ~3 dB headroom per component.
    const double full = std::log2(chips * chip_samples / 2.0) + l.mix_frac + (int_bits - 1);
    l.corr_shift = std::max(0, static_cast<int>(std::ceil(full)) - (cfg.corr_bits - 1));
  }
  require_in_range("correlator.corr_shift", l.corr_shift, 0, l.comb_bits);
  l.power_bits = 2 * cfg.corr_bits - 1;
  l.energy_bits = 2 * cfg.data_bits - 1 + ceil_log2(std::int64_t{chips} * chip_samples);
  if (l.energy_bits > 63) {
    throw InputError("correlator: energy width exceeds 63 bits; lower correlator.data_bits");
  }

  // rho^2 = 2 P 2^(2 cs - 2 mf + 2 df) / (L Nc E);  score = rho^2 * 2^score_bits
  //       = P * rho_scale / (E >> es),  rho_scale = 2^(score_bits + 1 + 2cs - 2mf + 2df - es) / (L Nc)
  const double base = cfg.score_bits + 1 + 2.0 * l.corr_shift - 2.0 * l.mix_frac +
                      2.0 * cfg.data_frac - std::log2(double(chips) * chip_samples);
  if (cfg.energy_shift >= 0) {
    l.energy_shift = cfg.energy_shift;
  } else {
    // Keep rho_scale in [2^(score_bits-1), 2^score_bits): the most precision that still
    // fits a score_bits-wide constant multiplier.
    l.energy_shift = std::max(0, static_cast<int>(std::floor(base)) - (cfg.score_bits - 1));
  }
  require_in_range("correlator.energy_shift", l.energy_shift, 0, l.energy_bits);
  const double scale = std::exp2(base - l.energy_shift);
  if (scale < 1.0 || scale >= std::exp2(cfg.score_bits + 1)) {
    throw InputError("correlator.energy_shift: " + std::to_string(l.energy_shift) +
                     " gives a score scale of " + std::to_string(scale) +
                     "; valid range keeps it in [1, 2^(score_bits+1))");
  }
  l.rho_scale = std::llround(scale);

  const double amp = std::exp2(cfg.lo_bits - 1) - 1.0;
  for (int k = 0; k < period; ++k) {
    const double w = 2.0 * std::numbers::pi * k / period;
    l.lo_cos.push_back(std::llround(amp * std::cos(w)));
    l.lo_sin.push_back(std::llround(amp * std::sin(w)));
  }
  return l;
}

// ---------------------------------------------------------------------------------------
// Float reference.

CorrelatorBankFloat::CorrelatorBankFloat(const std::vector<std::vector<std::uint8_t>>& codes,
                                         int period, int chip_samples)
    : signs_(code_signs(codes)),
      period_(period),
      chip_samples_(chip_samples),
      chips_(static_cast<int>(codes.front().size())) {
  check_geometry(period, chip_samples);
  reset();
}

void CorrelatorBankFloat::reset() {
  n_ = 0;
  b_re_.assign(chip_samples_, 0.0);
  b_im_.assign(chip_samples_, 0.0);
  z_re_.assign(static_cast<std::size_t>(chips_ - 1) * chip_samples_ + 1, 0.0);
  z_im_.assign(z_re_.size(), 0.0);
  y2_.assign(static_cast<std::size_t>(chips_) * chip_samples_, 0.0);
  zsum_re_ = zsum_im_ = energy_ = 0.0;
  power_.assign(signs_.size(), 0.0);
}

void CorrelatorBankFloat::execute(double y) {
  const double w = 2.0 * std::numbers::pi * static_cast<double>(n_ % period_) / period_;
  const double bre = y * std::cos(w);
  const double bim = -y * std::sin(w);
  const std::size_t bi = static_cast<std::size_t>(n_ % chip_samples_);
  zsum_re_ += bre - b_re_[bi];
  zsum_im_ += bim - b_im_[bi];
  b_re_[bi] = bre;
  b_im_[bi] = bim;

  const std::size_t zn = z_re_.size();
  const std::size_t zi = static_cast<std::size_t>(n_ % static_cast<std::int64_t>(zn));
  z_re_[zi] = zsum_re_;
  z_im_[zi] = zsum_im_;

  const std::size_t yn = y2_.size();
  const std::size_t yi = static_cast<std::size_t>(n_ % static_cast<std::int64_t>(yn));
  energy_ += y * y - y2_[yi];
  y2_[yi] = y * y;
  if (energy_ < 0) energy_ = 0;  // running-sum rounding in double

  for (std::size_t j = 0; j < signs_.size(); ++j) {
    double cre = 0, cim = 0;
    for (int m = 0; m < chips_; ++m) {
      const std::size_t back = static_cast<std::size_t>(chips_ - 1 - m) * chip_samples_;
      const std::size_t k = (zi + zn - back) % zn;
      cre += signs_[j][m] * z_re_[k];
      cim += signs_[j][m] * z_im_[k];
    }
    power_[j] = cre * cre + cim * cim;
  }
  ++n_;
}

double CorrelatorBankFloat::rho2(int code) const {
  if (energy_ <= 0) return 0.0;
  return 2.0 * power_.at(code) / (static_cast<double>(chips_) * chip_samples_ * energy_);
}

// ---------------------------------------------------------------------------------------
// Bit-accurate model.

CorrelatorBankFixed::CorrelatorBankFixed(const std::vector<std::vector<std::uint8_t>>& codes,
                                         int period, int chip_samples,
                                         const CorrelatorFixedConfig& cfg)
    : cfg_(cfg), signs_(code_signs(codes)) {
  layout_ = resolve_correlator_layout(cfg, period, chip_samples,
                                      static_cast<int>(codes.front().size()),
                                      static_cast<int>(codes.size()));
  mix_fmt_ = FixedFormat{cfg.mix_bits, layout_.mix_frac, true, Rounding::RoundHalfUp,
                         Overflow::Saturate};
  corr_fmt_ = FixedFormat{cfg.corr_bits, 0, true, Rounding::RoundHalfUp, Overflow::Saturate};
  reset();
}

void CorrelatorBankFixed::reset() {
  const auto& l = layout_;
  phase_ = 0;
  b_idx_ = z_idx_ = y_idx_ = 0;
  b_re_.assign(l.chip_samples, 0);
  b_im_.assign(l.chip_samples, 0);
  z_re_.assign(static_cast<std::size_t>(l.chips - 1) * l.chip_samples + 1, 0);
  z_im_.assign(z_re_.size(), 0);
  y2_.assign(static_cast<std::size_t>(l.chips) * l.chip_samples, 0);
  zsum_re_ = zsum_im_ = 0;
  energy_ = 0;
  corr_re_.assign(signs_.size(), 0);
  corr_im_.assign(signs_.size(), 0);
  power_.assign(signs_.size(), 0);
  counter_ = {};
  // Ring positions: index of the newest entry; the first execute() moves to slot 0.
  b_idx_ = b_re_.size() - 1;
  z_idx_ = z_re_.size() - 1;
  y_idx_ = y2_.size() - 1;
}

void CorrelatorBankFixed::execute(std::int64_t y) {
  const auto& l = layout_;
  // 1. mixer: exact product, then round half up into mix format (data int bits kept).
  const __int128 pre = static_cast<__int128>(y) * l.lo_cos[phase_];
  const __int128 pim = -static_cast<__int128>(y) * l.lo_sin[phase_];
  const int product_frac = cfg_.data_frac + cfg_.lo_bits - 1;
  const std::int64_t bre = fx_quantize(pre, product_frac, mix_fmt_, &counter_);
  const std::int64_t bim = fx_quantize(pim, product_frac, mix_fmt_, &counter_);
  phase_ = (phase_ + 1) % l.period;

  // 2. chip integrator: running sum over Nc samples, exact (chip_bits hold the bound).
  b_idx_ = (b_idx_ + 1) % b_re_.size();
  zsum_re_ += bre - b_re_[b_idx_];
  zsum_im_ += bim - b_im_[b_idx_];
  b_re_[b_idx_] = bre;
  b_im_[b_idx_] = bim;

  z_idx_ = (z_idx_ + 1) % z_re_.size();
  z_re_[z_idx_] = zsum_re_;
  z_im_[z_idx_] = zsum_im_;

  // 5. energy: running sum of y^2 over L*Nc samples, exact.
  y_idx_ = (y_idx_ + 1) % y2_.size();
  const std::uint64_t y2 = static_cast<std::uint64_t>(y * y);
  energy_ = energy_ + y2 - static_cast<std::uint64_t>(y2_[y_idx_]);
  y2_[y_idx_] = static_cast<std::int64_t>(y2);

  // 3-4. code combiner (exact), quantize to corr_bits, power.
  const std::size_t zn = z_re_.size();
  for (std::size_t j = 0; j < signs_.size(); ++j) {
    std::int64_t cre = 0, cim = 0;
    for (int m = 0; m < l.chips; ++m) {
      const std::size_t back = static_cast<std::size_t>(l.chips - 1 - m) * l.chip_samples;
      const std::size_t k = pos(z_idx_, back, zn);
      cre += signs_[j][m] * z_re_[k];
      cim += signs_[j][m] * z_im_[k];
    }
    corr_re_[j] = fx_quantize(cre, l.corr_shift, corr_fmt_, &counter_);
    corr_im_[j] = fx_quantize(cim, l.corr_shift, corr_fmt_, &counter_);
    power_[j] = corr_re_[j] * corr_re_[j] + corr_im_[j] * corr_im_[j];
  }
}

std::uint64_t correlation_score(std::int64_t power, std::uint64_t norm, std::int64_t rho_scale,
                                int score_bits) {
  const std::uint64_t cap = (std::uint64_t{1} << score_bits) - 1;
  const unsigned __int128 q = static_cast<unsigned __int128>(power) *
                              static_cast<std::uint64_t>(rho_scale) /
                              std::max<std::uint64_t>(norm, 1);
  return q > cap ? cap : static_cast<std::uint64_t>(q);
}

std::uint64_t CorrelatorBankFixed::score(int code) const {
  return correlation_score(power_.at(code), norm(), layout_.rho_scale, cfg_.score_bits);
}

}  // namespace ranging
