#pragma once
// Streaming detection on the correlator bank: turns P_j[n] (every code, every sample) into
// events {code j, arrival sample with a sub-sample fraction, score, margin}.
//
// Per sample n (identical in float and fixed point; the hardware implements the fixed one):
//   best   = argmax_j P_j[n]  (lowest j on ties);  second = max_{j != best} P_j[n]
//   gate   = rho^2_best[n] >= threshold  and  E[n] >= min_energy
//   if the candidate was set at n-1: record P_code[n] of its code as P_next
//   if gate and (no candidate or P_best[n] > P_candidate): candidate := (n, best, P[n-1], P[n], ...)
//   else if a candidate exists, its P_next is known and n - n_candidate >= holdoff: emit it
// The fraction is the vertex of the parabola through P[n-1], P[n], P[n+1] of the winning code:
//   delta = (P_next - P_prev) / (2 (2 P - P_prev - P_next)),  clamped to [-1/2, 1/2].
// Event latency: holdoff samples after the peak. Two bursts closer than holdoff merge into the
// stronger one, so holdoff <= the transmit period (the paper's T >= 1.5 T_d).
//
// Fixed point: the gate is the exact integer test P * rho_scale >= thr_q * max(norm, 1) (no
// divider per sample); score and margin are computed only at an event (one division each):
// score = min(2^score_bits - 1, floor(P * rho_scale / max(norm, 1))), margin = score(best) -
// score(second). The fraction is floor-toward-zero of (P_next - P_prev) 2^frac_bits / (2 den).
#include <cstdint>
#include <optional>
#include <vector>

#include "model/correlator_bank.hpp"

namespace ranging {

struct DetectorConfig {
  double threshold = 0.25;  // on rho^2 (0..1): 0.25 means a Pearson-like rho >= 0.5
  int holdoff = -1;         // samples; -1: one code length, L * Nc
  double min_energy = 1e-4; // on E = sum of y^2 over the code window, in full-scale units^2
  int frac_bits = 8;        // sub-sample fraction bits of the arrival time (fixed point)
};

struct Event {                // float form (fixed events convert to it for reports)
  int code = 0;               // 1-based j, as in the paper
  double arrival = 0;         // sample index of the correlation peak, with fraction
  double score = 0;           // rho^2 at the peak
  double margin = 0;          // rho^2(best) - rho^2(second) at the peak
};

struct EventFixed {
  int code = 0;               // 1-based j
  std::int64_t arrival = 0;   // peak sample index * 2^frac_bits + fraction (signed)
  std::uint64_t score = 0;    // unsigned score_bits fraction of rho^2
  std::uint64_t margin = 0;   // score(best) - score(second)
  Event to_float(int frac_bits, int score_bits) const;
  bool operator==(const EventFixed&) const = default;
};

class PeakDetectorFloat {
 public:
  PeakDetectorFloat(const DetectorConfig& cfg, int code_window_samples);
  void reset();
  // Call after bank.execute() for every sample; returns an event when one is complete.
  std::optional<Event> execute(const CorrelatorBankFloat& bank);
  std::optional<Event> flush();  // end of stream: emit a pending candidate

 private:
  struct Candidate { std::int64_t n; int code; double p_prev, p, p_next, score, margin; bool has_next; };
  Event make_event(const Candidate& c) const;
  DetectorConfig cfg_;
  int holdoff_;
  std::int64_t n_ = 0;
  std::vector<double> prev_;
  std::optional<Candidate> cand_;
};

class PeakDetectorFixed {
 public:
  PeakDetectorFixed(const DetectorConfig& cfg, const CorrelatorFixedLayout& layout,
                    const CorrelatorFixedConfig& corr);
  void reset();
  std::optional<EventFixed> execute(const CorrelatorBankFixed& bank);
  std::optional<EventFixed> flush();

  std::uint64_t threshold_q() const { return thr_q_; }   // on score (score_bits fraction)
  std::uint64_t min_norm_q() const { return min_norm_; } // on norm = E >> energy_shift
  int holdoff() const { return holdoff_; }

 private:
  struct Candidate {
    std::int64_t n; int code;
    std::int64_t p_prev, p, p_next, p_second;
    std::uint64_t norm;
    bool has_next;
  };
  EventFixed make_event(const Candidate& c) const;
  DetectorConfig cfg_;
  int score_bits_;
  std::int64_t rho_scale_;
  std::uint64_t thr_q_, min_norm_;
  int holdoff_;
  std::int64_t n_ = 0;
  std::vector<std::int64_t> prev_;
  std::optional<Candidate> cand_;
};

// The integer fraction rule, shared with the hardware generator's documentation and tests.
std::int64_t parabolic_fraction(std::int64_t p_prev, std::int64_t p, std::int64_t p_next,
                                int frac_bits);

}  // namespace ranging
