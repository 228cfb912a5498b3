#pragma once
// Streaming detection on the correlator bank: turns the weighted powers Q_j[k] (every code,
// every decimated sample k) into events {code j, arrival sample with a sub-sample fraction,
// score, margin}.
//
// Per decimated output (identical in float and fixed point; the hardware implements the fixed
// one), with n the full-rate index of the bank's last input sample:
//   best   = argmax_j Q_j  (lowest j on ties);  second = max_{j != best} Q_j
//   gate   = rho^2_best >= threshold  and  E >= min_energy
//   if the candidate was set at the previous output: record Q_code of its code as Q_next
//   if gate and (no candidate or rho^2_best > rho^2_candidate): candidate := (n, best, Q_prev, Q, ...)
//   else if a candidate exists, its Q_next is known and n - n_candidate >= holdoff: emit it
// The fraction is the vertex of the parabola through Q[k-1], Q[k], Q[k+1] of the winning code,
//   delta = (Q_next - Q_prev) / (2 (2 Q - Q_prev - Q_next)),  clamped to [-1/2, 1/2],
// in decimated samples; arrival = n + D delta full-rate samples.
// The candidate is the best *normalized* match so far (rho^2 = Q / E), not the largest Q: the
// next burst's correlation, already rising while this one waits out its holdoff (bursts every
// T ~ 1.4 template spans overlap in the window), has more raw power in the mixed window but a
// lower rho^2 than a clean peak, so it cannot take the candidate over; sidelobes before a
// peak have a lower rho^2 than the peak, so the candidate still climbs to it.
// Event latency: holdoff samples after the peak. Two bursts closer than holdoff merge into the
// stronger one, so holdoff <= the transmit period (the paper's T >= 1.5 T_d).
//
// Fixed point: the gate is the exact integer test Q >= thr_q * max(norm, 1) and the candidate
// test the exact cross product Q * max(norm_cand, 1) > Q_cand * max(norm, 1) (no divider per
// sample); score = min(2^score_bits - 1, floor(Q / max(norm, 1))) and margin = score(best) -
// score(second) are computed only at an event. The fraction is (Q_next - Q_prev) 2^frac_bits /
// (2 den) truncated toward zero (parabolic_fraction), then multiplied by D.
#include <algorithm>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "model/dsp/correlator_bank.hpp"

namespace ranging {

struct DetectorConfig {
  double threshold = 0.5;    // on rho^2 (0..1): noise alone reaches ~0.35 (docs/scenes.md)
  int holdoff = -1;          // full-rate samples; -1: the energy window (the template span)
  double min_energy = 1e-4;  // on E = sum of y^2 over the window, in full-scale units^2
  int frac_bits = 8;         // sub-sample fraction bits of the arrival time (fixed point)
};

// Throws InputError naming the field (detector.threshold in [0, 1], ...).
void validate(const DetectorConfig& cfg);

struct Event {               // float form (fixed events convert to it for reports)
  int code = 0;              // 1-based j, as in the paper
  double arrival = 0;        // full-rate sample index of the correlation peak, with fraction
  double score = 0;          // rho^2 at the peak
  double margin = 0;         // rho^2(best) - rho^2(second) at the peak
};

struct EventFixed {
  int code = 0;              // 1-based j
  std::int64_t arrival = 0;  // peak sample index * 2^frac_bits + fraction (signed)
  std::uint64_t score = 0;   // unsigned score_bits fraction of rho^2
  std::uint64_t margin = 0;  // score(best) - score(second)
  Event to_float(int frac_bits, int score_bits) const;
  bool operator==(const EventFixed&) const = default;
};

class PeakDetectorFloat {
 public:
  PeakDetectorFloat(const DetectorConfig& cfg, const CorrelatorReference& ref);
  void reset() {
    prev_.clear();
    cand_.reset();
  }
  // Call after every bank.execute() that returned true.
  std::optional<Event> execute(const CorrelatorBankFloat& bank);
  // The same from a decimated output's values: Q_j per code, the full-rate sample index, E.
  std::optional<Event> execute(std::span<const double> q, std::int64_t n, double energy);
  // The same with the previous output's Q_j given (zeros before the first output) instead of
  // kept by the detector: its own record is neither read nor updated. A caller that knows the
  // gate is closed while idle() skips the call (ReceiverFloatBatch): nothing would change.
  std::optional<Event> execute(std::span<const double> q, std::span<const double> prev, std::int64_t n,
                               double energy);
  // Records q as the previous output's Q_j (after calls of the prev-given form above).
  void set_previous(std::span<const double> q) { prev_.assign(q.begin(), q.end()); }
  bool idle() const { return !cand_; }  // no candidate pending
  // The gate of an output whose best code has Q = top: rho^2 = top / E >= threshold, E >= min_energy.
  bool gate(double top, double energy) const {
    return (energy > 0 ? top / energy : 0.0) >= cfg_.threshold && energy >= cfg_.min_energy;
  }
  std::optional<Event> flush();  // end of stream: emit a pending candidate

 private:
  struct Candidate {
    std::int64_t n;
    int code;
    double q_prev, q, q_next, score, margin;
    bool has_next;
  };
  Event make_event(const Candidate& c) const;
  DetectorConfig cfg_;
  int holdoff_, decimation_;
  std::vector<double> prev_;
  std::optional<Candidate> cand_;
};

// The fixed-point detector's constants, derived without a detector object (what the hardware
// generator needs). Validates cfg (InputError naming the field).
//   threshold_q = min(2^score_bits - 1, round(threshold 2^score_bits))   on score
//   min_norm_q  = ceil(min_energy 2^(2 data_frac - energy_shift))        on norm = E >> energy_shift
//                 (InputError unless in [0, 9e18])
//   holdoff     = cfg.holdoff, or the layout's energy window when -1     full-rate samples
struct PeakDetectorFixedLayout {
  std::uint64_t threshold_q = 0, min_norm_q = 0;
  int holdoff = 0;
};
PeakDetectorFixedLayout resolve_detector_layout(const DetectorConfig& cfg, const CorrelatorFixedLayout& layout,
                                                const CorrelatorFixedConfig& corr);

class PeakDetectorFixed {
 public:
  PeakDetectorFixed(const DetectorConfig& cfg, const CorrelatorFixedLayout& layout,
                    const CorrelatorFixedConfig& corr);
  void reset() {
    prev_.clear();
    cand_.reset();
  }
  std::optional<EventFixed> execute(const CorrelatorBankFixed& bank);
  // The same from a decimated output's values: Q_j per code, the full-rate sample index and
  // norm = E >> energy_shift (what the bank overload reads from the bank).
  std::optional<EventFixed> execute(std::span<const std::uint64_t> q, std::int64_t n, std::uint64_t norm);
  // The same with the previous output's Q_j given (zeros before the first output) instead of
  // kept by the detector: its own record is neither read nor updated (set_previous after).
  std::optional<EventFixed> execute(std::span<const std::uint64_t> q, std::span<const std::uint64_t> prev,
                                    std::int64_t n, std::uint64_t norm);
  void set_previous(std::span<const std::uint64_t> q) { prev_.assign(q.begin(), q.end()); }
  std::optional<EventFixed> flush();

  std::uint64_t threshold_q() const { return thr_q_; }   // on score (score_bits fraction)
  std::uint64_t min_norm_q() const { return min_norm_; } // on norm = E >> energy_shift
  int holdoff() const { return holdoff_; }

 private:
  struct Candidate {
    std::int64_t n;
    int code;
    std::uint64_t q_prev, q, q_next, q_second, norm;
    bool has_next;
  };
  EventFixed make_event(const Candidate& c) const;
  DetectorConfig cfg_;
  int score_bits_, decimation_;
  // The gate of an output whose best code has Q = top: top >= threshold_q max(norm, 1) (rho^2
  // against the threshold, cross-multiplied) and norm >= min_norm_q.
  bool gate(std::uint64_t top, std::uint64_t norm) const {
    return static_cast<uint128_t>(top) >= static_cast<uint128_t>(thr_q_) * std::max<std::uint64_t>(norm, 1) &&
           norm >= min_norm_;
  }
  std::uint64_t thr_q_, min_norm_;
  int holdoff_;
  std::vector<std::uint64_t> prev_;
  std::optional<Candidate> cand_;
};

// The integer fraction rule (in units of 2^-frac_bits decimated samples), shared with the
// hardware generator's documentation and tests.
std::int64_t parabolic_fraction(std::uint64_t q_prev, std::uint64_t q, std::uint64_t q_next,
                                int frac_bits);

}  // namespace ranging
