#include "model/peak_detector.hpp"

#include <algorithm>
#include <cmath>

#include "model/error.hpp"

namespace ranging {
namespace {

template <class T>
void best_two(const std::vector<T>& p, int& best, T& second) {
  best = 0;
  for (int j = 1; j < static_cast<int>(p.size()); ++j) {
    if (p[j] > p[best]) best = j;
  }
  second = T{};
  for (int j = 0; j < static_cast<int>(p.size()); ++j) {
    if (j != best && p[j] > second) second = p[j];
  }
}

void validate(const DetectorConfig& cfg) {
  require_in_range("detector.threshold", cfg.threshold, 0.0, 1.0);
  require_in_range("detector.min_energy", cfg.min_energy, 0.0, 1e12);
  require_in_range("detector.frac_bits", cfg.frac_bits, 0, 16);
  if (cfg.holdoff != -1) require_in_range("detector.holdoff", cfg.holdoff, 1, 1 << 24);
}

}  // namespace

Event EventFixed::to_float(int frac_bits, int score_bits) const {
  Event e;
  e.code = code;
  e.arrival = std::ldexp(static_cast<double>(arrival), -frac_bits);
  e.score = std::ldexp(static_cast<double>(score), -score_bits);
  e.margin = std::ldexp(static_cast<double>(margin), -score_bits);
  return e;
}

std::int64_t parabolic_fraction(std::int64_t p_prev, std::int64_t p, std::int64_t p_next,
                                int frac_bits) {
  const std::int64_t den = 2 * (2 * p - p_prev - p_next);
  if (den <= 0) return 0;
  const __int128 num = static_cast<__int128>(p_next - p_prev) * (std::int64_t{1} << frac_bits);
  std::int64_t q = static_cast<std::int64_t>(num / den);  // truncates toward zero
  const std::int64_t half = frac_bits > 0 ? (std::int64_t{1} << (frac_bits - 1)) : 0;
  return std::clamp(q, -half, half);
}

// ---------------------------------------------------------------------------------------

PeakDetectorFloat::PeakDetectorFloat(const DetectorConfig& cfg, int code_window_samples)
    : cfg_(cfg), holdoff_(cfg.holdoff == -1 ? code_window_samples : cfg.holdoff) {
  validate(cfg);
}

void PeakDetectorFloat::reset() {
  n_ = 0;
  prev_.clear();
  cand_.reset();
}

Event PeakDetectorFloat::make_event(const Candidate& c) const {
  Event e;
  e.code = c.code + 1;
  const double den = 2.0 * (2.0 * c.p - c.p_prev - c.p_next);
  const double delta = den > 0 ? std::clamp((c.p_next - c.p_prev) / den, -0.5, 0.5) : 0.0;
  e.arrival = static_cast<double>(c.n) + delta;
  e.score = c.score;
  e.margin = c.margin;
  return e;
}

std::optional<Event> PeakDetectorFloat::execute(const CorrelatorBankFloat& bank) {
  const std::vector<double>& p = bank.power();
  if (prev_.empty()) prev_.assign(p.size(), 0.0);
  std::optional<Event> out;
  int best;
  double second;
  best_two(p, best, second);
  if (cand_ && !cand_->has_next) {
    cand_->p_next = p[cand_->code];
    cand_->has_next = true;
  }
  const double rho2 = bank.rho2(best);
  const bool gate = rho2 >= cfg_.threshold && bank.energy() >= cfg_.min_energy;
  if (gate && (!cand_ || p[best] > cand_->p)) {
    // margin: rho^2(best) - rho^2(second), both normalized by the same energy
    const double margin = p[best] > 0 ? rho2 * (p[best] - second) / p[best] : 0.0;
    cand_ = Candidate{n_, best, prev_[best], p[best], 0.0, rho2, margin, false};
  } else if (cand_ && cand_->has_next && n_ - cand_->n >= holdoff_) {
    out = make_event(*cand_);
    cand_.reset();
  }
  prev_ = p;
  ++n_;
  return out;
}

std::optional<Event> PeakDetectorFloat::flush() {
  std::optional<Event> out;
  if (cand_) {
    if (!cand_->has_next) cand_->p_next = cand_->p_prev;  // no right neighbour: symmetric
    out = make_event(*cand_);
    cand_.reset();
  }
  return out;
}

// ---------------------------------------------------------------------------------------

PeakDetectorFixed::PeakDetectorFixed(const DetectorConfig& cfg, const CorrelatorFixedLayout& layout,
                                     const CorrelatorFixedConfig& corr)
    : cfg_(cfg),
      score_bits_(corr.score_bits),
      rho_scale_(layout.rho_scale),
      holdoff_(cfg.holdoff == -1 ? layout.chips * layout.chip_samples : cfg.holdoff) {
  validate(cfg);
  const std::uint64_t cap = (std::uint64_t{1} << score_bits_) - 1;
  thr_q_ = std::min<std::uint64_t>(cap, static_cast<std::uint64_t>(
                                            std::llround(std::ldexp(cfg.threshold, score_bits_))));
  // min_energy is in full-scale units^2: E_raw = E * 2^(2 data_frac); norm = E_raw >> shift.
  const double e_raw = std::ldexp(cfg.min_energy, 2 * corr.data_frac - layout.energy_shift);
  require_in_range("detector.min_energy (in norm units)", e_raw, 0.0, 9.0e18);
  min_norm_ = static_cast<std::uint64_t>(std::ceil(e_raw));
}

void PeakDetectorFixed::reset() {
  n_ = 0;
  prev_.clear();
  cand_.reset();
}

EventFixed PeakDetectorFixed::make_event(const Candidate& c) const {
  EventFixed e;
  e.code = c.code + 1;
  e.arrival = c.n * (std::int64_t{1} << cfg_.frac_bits) +
              parabolic_fraction(c.p_prev, c.p, c.p_next, cfg_.frac_bits);
  e.score = correlation_score(c.p, c.norm, rho_scale_, score_bits_);
  e.margin = e.score - correlation_score(c.p_second, c.norm, rho_scale_, score_bits_);
  return e;
}

std::optional<EventFixed> PeakDetectorFixed::execute(const CorrelatorBankFixed& bank) {
  const std::vector<std::int64_t>& p = bank.power();
  if (prev_.empty()) prev_.assign(p.size(), 0);
  std::optional<EventFixed> out;
  int best;
  std::int64_t second;
  best_two(p, best, second);
  if (cand_ && !cand_->has_next) {
    cand_->p_next = p[cand_->code];
    cand_->has_next = true;
  }
  const std::uint64_t norm = bank.norm();
  const unsigned __int128 lhs =
      static_cast<unsigned __int128>(p[best]) * static_cast<std::uint64_t>(rho_scale_);
  const unsigned __int128 rhs =
      static_cast<unsigned __int128>(thr_q_) * std::max<std::uint64_t>(norm, 1);
  const bool gate = lhs >= rhs && norm >= min_norm_;
  if (gate && (!cand_ || p[best] > cand_->p)) {
    cand_ = Candidate{n_, best, prev_[best], p[best], 0, second, norm, false};
  } else if (cand_ && cand_->has_next && n_ - cand_->n >= holdoff_) {
    out = make_event(*cand_);
    cand_.reset();
  }
  prev_ = p;
  ++n_;
  return out;
}

std::optional<EventFixed> PeakDetectorFixed::flush() {
  std::optional<EventFixed> out;
  if (cand_) {
    if (!cand_->has_next) cand_->p_next = cand_->p_prev;  // no right neighbour: symmetric
    out = make_event(*cand_);
    cand_.reset();
  }
  return out;
}

}  // namespace ranging
