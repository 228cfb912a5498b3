#include "model/dsp/peak_detector.hpp"

#include <algorithm>
#include <cmath>

#include "model/base/error.hpp"

namespace ranging {
namespace {

template <class T>
int argmax(std::span<const T> q) {  // the first of the largest
  int best = 0;
  for (int j = 1; j < static_cast<int>(q.size()); ++j) {
    if (q[j] > q[best]) best = j;
  }
  return best;
}

template <class T>
T second_best(std::span<const T> q, int best) {  // the largest of the others (0 if none)
  T second{};
  for (int j = 0; j < static_cast<int>(q.size()); ++j) {
    if (j != best && q[j] > second) second = q[j];
  }
  return second;
}

// The candidate's life cycle, the same in both precisions. The output after the candidate's
// peak is its right neighbour (the parabola's third point).
template <class Cand, class T>
void take_right_neighbour(std::optional<Cand>& cand, std::span<const T> q) {
  if (cand && !cand->has_next) {
    cand->q_next = q[static_cast<std::size_t>(cand->code)];
    cand->has_next = true;
  }
}

// The candidate as an event, and no candidate after it (none: no event). One without a right
// neighbour (the stream ended first: flush) takes its left one, a symmetric parabola.
template <class Cand, class Make>
auto release(std::optional<Cand>& cand, Make&& make_event) -> std::optional<decltype(make_event(*cand))> {
  if (!cand) return std::nullopt;
  if (!cand->has_next) cand->q_next = cand->q_prev;
  auto out = make_event(*cand);
  cand.reset();
  return out;
}

// One output of the bank: `fresh` becomes the candidate when `take` (the gate is open and the
// best code's rho^2 beats the candidate's); else the candidate is released as the event once
// holdoff outputs have followed it.
template <class Cand, class Make>
auto next_candidate(std::optional<Cand>& cand, bool take, const Cand& fresh, std::int64_t n, int holdoff,
                    Make&& make_event) -> std::optional<decltype(make_event(*cand))> {
  if (take) {
    cand = fresh;
    return std::nullopt;
  }
  if (cand && cand->has_next && n - cand->n >= holdoff) return release(cand, make_event);
  return std::nullopt;
}

}  // namespace

void validate(const DetectorConfig& cfg) {
  require_in_range("detector.threshold", cfg.threshold, 0.0, 1.0);
  require_in_range("detector.min_energy", cfg.min_energy, 0.0, 1e12);
  require_in_range("detector.frac_bits", cfg.frac_bits, 0, 16);
  if (cfg.holdoff != -1) require_in_range("detector.holdoff", cfg.holdoff, 1, 1 << 24);
}

Event EventFixed::to_float(int frac_bits, int score_bits) const {
  Event e;
  e.code = code;
  e.arrival = std::ldexp(static_cast<double>(arrival), -frac_bits);
  e.score = std::ldexp(static_cast<double>(score), -score_bits);
  e.margin = std::ldexp(static_cast<double>(margin), -score_bits);
  return e;
}

std::int64_t parabolic_fraction(std::uint64_t q_prev, std::uint64_t q, std::uint64_t q_next,
                                int frac_bits) {
  const int128_t den = 2 * (2 * static_cast<int128_t>(q) - q_prev - q_next);
  if (den <= 0) return 0;
  const int128_t num = (static_cast<int128_t>(q_next) - q_prev) * (int128_t{1} << frac_bits);
  const std::int64_t half = frac_bits > 0 ? (std::int64_t{1} << (frac_bits - 1)) : 0;
  const int128_t r = num / den;  // truncates toward zero
  return static_cast<std::int64_t>(std::clamp<int128_t>(r, -half, half));
}

// ---------------------------------------------------------------------------------------

PeakDetectorFloat::PeakDetectorFloat(const DetectorConfig& cfg, const CorrelatorReference& ref)
    : cfg_(cfg), holdoff_(cfg.holdoff == -1 ? ref.window : cfg.holdoff), decimation_(ref.decimation) {
  validate(cfg);
}

Event PeakDetectorFloat::make_event(const Candidate& c) const {
  Event e;
  e.code = c.code + 1;
  const double den = 2.0 * (2.0 * c.q - c.q_prev - c.q_next);
  const double delta = den > 0 ? std::clamp((c.q_next - c.q_prev) / den, -0.5, 0.5) : 0.0;
  e.arrival = static_cast<double>(c.n) + decimation_ * delta;
  e.score = c.score;
  e.margin = c.margin;
  return e;
}

std::optional<Event> PeakDetectorFloat::execute(const CorrelatorBankFloat& bank) {
  return execute(bank.weighted_power(), bank.sample_index(), bank.energy());
}

std::optional<Event> PeakDetectorFloat::execute(std::span<const double> q, std::int64_t n, double energy) {
  if (prev_.empty()) prev_.assign(q.size(), 0.0);
  auto out = execute(q, prev_, n, energy);
  prev_.assign(q.begin(), q.end());
  return out;
}

std::optional<Event> PeakDetectorFloat::execute(std::span<const double> q, std::span<const double> prev,
                                                std::int64_t n, double energy) {
  const int best = argmax(q);
  const bool open = gate(q[static_cast<std::size_t>(best)], energy);
  if (!cand_ && !open) return std::nullopt;  // no candidate (most outputs): nothing changes
  const double second = second_best(q, best);
  take_right_neighbour(cand_, q);
  const double rho2 = energy > 0 ? q[static_cast<std::size_t>(best)] / energy : 0.0;  // CorrelatorBankFloat::rho2
  const double margin = rho2 - (energy > 0 ? second / energy : 0.0);
  return next_candidate(cand_, open && (!cand_ || rho2 > cand_->score),
                        Candidate{n, best, prev[static_cast<std::size_t>(best)], q[static_cast<std::size_t>(best)],
                                  0.0, rho2, margin, false},
                        n, holdoff_, [this](const Candidate& c) { return make_event(c); });
}

std::optional<Event> PeakDetectorFloat::flush() {
  return release(cand_, [this](const Candidate& c) { return make_event(c); });
}

// ---------------------------------------------------------------------------------------

PeakDetectorFixedLayout resolve_detector_layout(const DetectorConfig& cfg, const CorrelatorFixedLayout& layout,
                                                const CorrelatorFixedConfig& corr) {
  validate(cfg);
  PeakDetectorFixedLayout l;
  l.holdoff = cfg.holdoff == -1 ? layout.window : cfg.holdoff;
  const std::uint64_t cap = (std::uint64_t{1} << corr.score_bits) - 1;
  l.threshold_q = std::min<std::uint64_t>(
      cap, static_cast<std::uint64_t>(std::llround(std::ldexp(cfg.threshold, corr.score_bits))));
  // min_energy is in full-scale units^2: E_raw = E 2^(2 data_frac); norm = E_raw >> shift.
  const double e_raw = std::ldexp(cfg.min_energy, 2 * corr.data_frac - layout.energy_shift);
  require_in_range("detector.min_energy (in norm units)", e_raw, 0.0, 9.0e18);
  l.min_norm_q = static_cast<std::uint64_t>(std::ceil(e_raw));
  return l;
}

PeakDetectorFixed::PeakDetectorFixed(const DetectorConfig& cfg, const CorrelatorFixedLayout& layout,
                                     const CorrelatorFixedConfig& corr)
    : cfg_(cfg), score_bits_(corr.score_bits), decimation_(layout.decimation) {
  const PeakDetectorFixedLayout l = resolve_detector_layout(cfg, layout, corr);
  thr_q_ = l.threshold_q;
  min_norm_ = l.min_norm_q;
  holdoff_ = l.holdoff;
}

EventFixed PeakDetectorFixed::make_event(const Candidate& c) const {
  EventFixed e;
  e.code = c.code + 1;
  e.arrival = c.n * (std::int64_t{1} << cfg_.frac_bits) +
              decimation_ * parabolic_fraction(c.q_prev, c.q, c.q_next, cfg_.frac_bits);
  e.score = correlation_score(c.q, c.norm, score_bits_);
  e.margin = e.score - correlation_score(c.q_second, c.norm, score_bits_);
  return e;
}

std::optional<EventFixed> PeakDetectorFixed::execute(const CorrelatorBankFixed& bank) {
  return execute(bank.weighted_power(), bank.sample_index(), bank.norm());
}

std::optional<EventFixed> PeakDetectorFixed::execute(std::span<const std::uint64_t> q, std::int64_t n,
                                                     std::uint64_t norm) {
  if (prev_.empty()) prev_.assign(q.size(), 0);
  auto out = execute(q, prev_, n, norm);
  prev_.assign(q.begin(), q.end());
  return out;
}

std::optional<EventFixed> PeakDetectorFixed::execute(std::span<const std::uint64_t> q,
                                                     std::span<const std::uint64_t> prev, std::int64_t n,
                                                     std::uint64_t norm) {
  const int best = argmax(q);
  const bool open = gate(q[static_cast<std::size_t>(best)], norm);
  if (!cand_ && !open) return std::nullopt;  // no candidate (most outputs): nothing changes
  const std::uint64_t second = second_best(q, best);
  take_right_neighbour(cand_, q);
  // rho^2 of the best code beats the candidate's: Q / norm > Q_c / norm_c, cross-multiplied.
  const bool better = !cand_ || static_cast<uint128_t>(q[best]) * std::max<std::uint64_t>(cand_->norm, 1) >
                                    static_cast<uint128_t>(cand_->q) * std::max<std::uint64_t>(norm, 1);
  return next_candidate(cand_, open && better,
                        Candidate{n, best, prev[static_cast<std::size_t>(best)], q[static_cast<std::size_t>(best)], 0,
                                  second, norm, false},
                        n, holdoff_, [this](const Candidate& c) { return make_event(c); });
}

std::optional<EventFixed> PeakDetectorFixed::flush() {
  return release(cand_, [this](const Candidate& c) { return make_event(c); });
}

}  // namespace ranging
