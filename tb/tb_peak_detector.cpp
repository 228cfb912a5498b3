// rtl/peak_detector.v against PeakDetectorFixed, bit for bit: the detector is driven with the
// model bank's outputs (Q_j, E, n) of streams of filtered Gold4 bursts at many distances, each
// output as a group of CODES beats (s_weighted = Q_j, s_last on j = CODES-1, E and n on every
// beat), with random s_valid gaps inside and between groups, random m_ready back-pressure and a
// reset in the middle of a stream (between groups);
// every event (code, arrival, score, margin) must equal the model's, none lost or duplicated
// (the model's flush() at the end of a stream is not part of the hardware and not compared).
// A paced run at the default configuration starts one group every DECIM x 6 clocks (the bank's
// rate), its beats on consecutive clocks, with m_ready = 1, and asserts the detector accepts
// every beat on its first clock and every group before the next is due (it never stalls the
// bank) while the events still match the model. Synthetic beats drive the divider and the
// cross-product comparison to their edges (score exactly at / just below the cap, fraction
// exactly +-1/2, zero and negative parabola denominators, equal rho^2, 48-bit operands); their
// expected events come from a step-by-step reference of PeakDetectorFixed::execute built on the
// model's correlation_score and parabolic_fraction, itself checked equal to the model on the
// coded streams. Also the Verilator lint (-Wall). RANGING_TRACE=1 writes $RANGING_TRACE_DIR/tb_peak_detector.fst.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <algorithm>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "model/config/receiver_config.hpp"
#include "model/dsp/bandpass_filter.hpp"
#include "model/sim/channel.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/receiver.hpp"
// Verilator's runtime headers are not warning-clean under -Wextra -Werror.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include "Vpeak_detector.h"
#include "tb/generated_params.hpp"
#include "tb/verilator_harness.hpp"
#pragma GCC diagnostic pop

namespace {

// "event N: <what> {...} rtl {...}": the first differing event, for a failure message.
std::string event_mismatch(std::size_t n, const char* what, const ranging::EventFixed& e,
                           const ranging::EventFixed& g) {
  std::ostringstream os;
  os << "event " << n << ": " << what << " {code " << e.code << ", arrival " << e.arrival << ", score " << e.score
     << ", margin " << e.margin << "} rtl {code " << g.code << ", arrival " << g.arrival << ", score " << g.score
     << ", margin " << g.margin << "}";
  return os.str();
}

using namespace ranging;

const ReceiverDesign& design() { return tb::configured_design(); }

// One bank output (a group): Q_j of every code, E, n. The detector receives it as CODES beats.
struct Beat {
  std::vector<std::uint64_t> q;
  std::uint64_t energy = 0, index = 0;
};

// Drive beat j of group g on the slave port (data only; s_valid is the caller's).
void drive_beat(Vpeak_detector& t, const Beat& g, std::size_t j) {
  t.s_weighted = g.q[j];
  t.s_last = j + 1 == g.q.size() ? 1 : 0;
  t.s_energy = g.energy;
  t.s_index = g.index;
}

// Filtered received bursts, one after the other (a new burst every `spacing` samples).
std::vector<std::int64_t> burst_stream(std::uint64_t seed, double noise, std::size_t bursts) {
  const auto& d = design();
  const ExcitationParams ex = receiver_excitation(d.config);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> dist_mm(100, 1000), gain(0.05, 0.8);
  BandpassFixed bp(d.filter, d.config.bandpass);
  OverflowCounter oc;
  std::vector<std::int64_t> y;
  for (std::size_t b = 0; b < bursts; ++b) {
    const auto exc = bpsk_excitation(d.family.codes.at(b % d.family.codes.size()), ex);
    ChannelParams ch;
    ch.distance_m = dist_mm(rng) / 1000.0;
    ch.gain = gain(rng);
    ch.noise_rms = noise;
    ch.seed = seed * 1000 + b;
    const std::size_t arrival = static_cast<std::size_t>(ch.distance_m / ch.speed_of_sound * d.config.fs);
    const auto rx = propagate(exc, ch, d.config.fs, arrival + 2600);
    const std::size_t start = arrival > 900 ? arrival - 900 : 0;
    for (std::size_t n = start; n < rx.size(); ++n) {
      y.push_back(bp.execute_raw(quantize_input(rx[n], d.config.bandpass.input_bits, &oc)));
    }
  }
  return y;
}

// The bank model's outputs for y, and the detector model's events on them (beats [0, split)
// with one detector, beats [split, end) with a freshly reset one).
void model(const std::vector<std::int64_t>& y, std::size_t split, std::vector<Beat>& beats,
           std::vector<EventFixed>& events, std::size_t& events_before_split) {
  const auto& d = design();
  CorrelatorBankFixed bank(d.reference, d.config.correlator);
  PeakDetectorFixed det(d.config.detector, bank.layout(), d.config.correlator);
  events_before_split = 0;
  for (std::int64_t v : y) {
    if (!bank.execute(v)) continue;
    if (beats.size() == split) {
      events_before_split = events.size();
      det.reset();
    }
    beats.push_back({bank.weighted_power(), bank.energy(), static_cast<std::uint64_t>(bank.sample_index())});
    if (auto e = det.execute(bank)) events.push_back(*e);
  }
  if (split >= beats.size()) events_before_split = events.size();
}

// The Verilated detector on the shared harness (tb/verilator_harness.hpp), plus an event reader.
class DetSim : public tb::StreamHarness<Vpeak_detector> {
 public:
  DetSim() : StreamHarness("tb_peak_detector") {}
  // The event on m_* (valid when m_valid): the arrival is 40 integer + frac_bits + sign bits.
  EventFixed read_event() const {
    const auto& t = top();
    EventFixed g;
    g.code = t.m_code;
    g.arrival = tb::sign_extend(t.m_arrival, 40 + design().config.detector.frac_bits + 1);
    g.score = t.m_score;
    g.margin = t.m_margin;
    return g;
  }
};

struct Totals {
  std::uint64_t inputs = 0, groups = 0, beats = 0, events = 0, mismatches = 0;
  std::string first;
};

void run_stream(DetSim& sim, const std::vector<std::int64_t>& y, double gap, double stall,
                std::mt19937_64& rng, const std::string& what, Totals& tot) {
  const auto& d = design();
  std::vector<Beat> beats;
  std::vector<EventFixed> events;
  std::size_t before = 0;
  std::uniform_real_distribution<double> u(0, 1);
  const std::size_t split = (y.size() / d.layout.decimation) / 2;
  model(y, split, beats, events, before);
  tot.inputs += y.size();
  sim.reset();
  std::size_t in = 0, jb = 0, got = 0;  // group, beat within the group
  bool presenting = false, did_reset = false;
  std::uint64_t cycles = 0;
  auto fail = [&](const std::string& msg) {
    ++tot.mismatches;
    if (tot.first.empty()) tot.first = what + ": " + msg;
  };
  bool holding = false;
  EventFixed held;
  while (in < beats.size() || got < events.size() || holding) {
    auto& t = sim.top();
    if (!did_reset && in == split && jb == 0) {
      // Drain what the first half produced, then reset in the middle of the stream.
      if (got == before && t.s_ready && !t.m_valid) {
        sim.reset();
        did_reset = true;
        presenting = false;
        continue;
      }
    } else if (!presenting && in < beats.size()) {
      presenting = u(rng) >= gap;
    }
    t.s_valid = presenting ? 1 : 0;
    if (in < beats.size()) drive_beat(t, beats[in], jb);
    t.m_ready = u(rng) >= stall ? 1 : 0;
    t.eval();
    if (t.m_valid) {
      const EventFixed g = sim.read_event();
      if (holding && !(g == held)) fail("event changed while m_valid && !m_ready");
      held = g;
      holding = !t.m_ready;
      if (t.m_ready) {
        if (got >= events.size()) {
          fail("extra event code " + std::to_string(g.code) + " arrival " + std::to_string(g.arrival));
        } else if (!(g == events[got])) {
          const auto& e = events[got];
          fail(event_mismatch(got, "model", e, g));
        }
        ++got;
        ++tot.events;
      }
    }
    if (t.s_valid && t.s_ready) {
      ++tot.beats;
      if (++jb == beats[in].q.size()) {
        jb = 0;
        ++in;
        ++tot.groups;
      }
      presenting = false;
    }
    sim.tick();
    if (++cycles > 600 * (beats.size() + 10)) {
      fail("timeout: " + std::to_string(got) + " of " + std::to_string(events.size()) + " events");
      break;
    }
  }
  // A few idle cycles: nothing else may come out.
  for (int i = 0; i < 400; ++i) {
    sim.top().m_ready = 1;
    sim.top().eval();
    if (sim.top().m_valid) fail("event after the model's last one");
    sim.tick();
  }
}

TEST(PeakDetectorRtl, EventsBitExactUnderGapsBackPressureAndReset) {
  DetSim sim;
  std::mt19937_64 rng(777);
  Totals tot;
  const double gaps[] = {0.0, 0.4, 0.1};
  const double stalls[] = {0.0, 0.5, 0.9};
  for (int s = 0; s < 3; ++s) {
    const auto y = burst_stream(100 + static_cast<std::uint64_t>(s), s == 1 ? 0.01 : 0.002, 27);
    run_stream(sim, y, gaps[s], stalls[s], rng, "stream " + std::to_string(s), tot);
  }
  std::printf("peak_detector: %llu input samples (model bank), %llu groups, %llu beats, %llu events compared, "
              "%llu mismatches\n",
              static_cast<unsigned long long>(tot.inputs), static_cast<unsigned long long>(tot.groups),
              static_cast<unsigned long long>(tot.beats),
              static_cast<unsigned long long>(tot.events), static_cast<unsigned long long>(tot.mismatches));
  EXPECT_EQ(tot.mismatches, 0u) << tot.first;
  EXPECT_GT(tot.events, 50u);
}

// PeakDetectorFixed::execute on raw beats (the model takes a bank object, whose state cannot be
// set to synthetic values): the same rules, with the model's score and fraction functions.
class RefDetector {
 public:
  RefDetector() {
    const auto& d = design();
    CorrelatorBankFixed bank(d.reference, d.config.correlator);
    PeakDetectorFixed det(d.config.detector, bank.layout(), d.config.correlator);
    thr_ = det.threshold_q();
    min_norm_ = det.min_norm_q();
    holdoff_ = det.holdoff();
    shift_ = d.layout.energy_shift;
    score_bits_ = d.config.correlator.score_bits;
    frac_bits_ = d.config.detector.frac_bits;
    decim_ = d.layout.decimation;
  }
  std::optional<EventFixed> execute(const Beat& b) {
    const auto& q = b.q;
    if (prev_.empty()) prev_.assign(q.size(), 0);
    int best = 0;
    for (int j = 1; j < static_cast<int>(q.size()); ++j)
      if (q[j] > q[best]) best = j;
    std::uint64_t second = 0;
    for (int j = 0; j < static_cast<int>(q.size()); ++j)
      if (j != best && q[j] > second) second = q[j];
    if (cand_ && !cand_->has_next) {
      cand_->qn = q[cand_->code];
      cand_->has_next = true;
    }
    const std::uint64_t norm = b.energy >> shift_, norm1 = std::max<std::uint64_t>(norm, 1);
    const bool gate = static_cast<uint128_t>(q[best]) >= static_cast<uint128_t>(thr_) * norm1 && norm >= min_norm_;
    const bool better = !cand_ || static_cast<uint128_t>(q[best]) * std::max<std::uint64_t>(cand_->norm, 1) >
                                      static_cast<uint128_t>(cand_->q) * norm1;
    std::optional<EventFixed> out;
    const auto n = static_cast<std::int64_t>(b.index);
    if (gate && better) {
      cand_ = Cand{n, best, prev_[best], q[best], 0, second, norm, false};
    } else if (cand_ && cand_->has_next && n - cand_->n >= holdoff_) {
      EventFixed e;
      e.code = cand_->code + 1;
      const std::int64_t frac = parabolic_fraction(cand_->qp, cand_->q, cand_->qn, frac_bits_);
      fractions.push_back(frac);
      den_not_positive.push_back(2 * static_cast<int128_t>(cand_->q) <=
                                 static_cast<int128_t>(cand_->qp) + cand_->qn);
      e.arrival = cand_->n * (std::int64_t{1} << frac_bits_) + decim_ * frac;
      e.score = correlation_score(cand_->q, cand_->norm, score_bits_);
      e.margin = e.score - correlation_score(cand_->q2, cand_->norm, score_bits_);
      out = e;
      cand_.reset();
    }
    prev_ = q;
    return out;
  }
  int holdoff() const { return holdoff_; }
  std::uint64_t threshold() const { return thr_; }
  std::uint64_t min_norm() const { return min_norm_; }
  std::vector<std::int64_t> fractions;  // of every event, and whether its denominator was <= 0
  std::vector<bool> den_not_positive;

 private:
  struct Cand {
    std::int64_t n;
    int code;
    std::uint64_t qp, q, qn, q2, norm;
    bool has_next;
  };
  std::uint64_t thr_ = 0, min_norm_ = 0;
  int holdoff_ = 0, shift_ = 0, score_bits_ = 0, frac_bits_ = 0, decim_ = 0;
  std::vector<std::uint64_t> prev_;
  std::optional<Cand> cand_;
};

struct PacedResult {
  std::uint64_t stalls = 0, late = 0, mismatches = 0, events = 0, max_busy = 0, max_busy_event = 0;
  std::string first;
};

// One group every `period` clocks (or back to back when 0), its CODES beats on consecutive
// clocks, m_ready = 1. A stall is a presented beat that is not accepted on its first clock; a
// group is late when its last beat is accepted when the next group is already due. Busy: clocks
// from a group's first beat to s_ready high again after its last beat (the group's whole time).
PacedResult run_paced(DetSim& sim, const std::vector<Beat>& beats, const std::vector<EventFixed>& expected,
                      std::uint64_t period) {
  PacedResult r;
  auto fail = [&](const std::string& m) {
    ++r.mismatches;
    if (r.first.empty()) r.first = m;
  };
  sim.reset();
  std::size_t in = 0, jb = 0, got = 0;
  std::uint64_t cycle = 0, due = 0, started_at = 0, busy_start_events = 0;
  bool busy = false, first_clock = true;
  while ((in < beats.size() || busy) && cycle < (beats.size() + 10) * (period + 400)) {
    auto& t = sim.top();
    const bool present = in < beats.size() && cycle >= due;
    t.s_valid = present ? 1 : 0;
    if (present) drive_beat(t, beats[in], jb);
    t.m_ready = 1;
    t.eval();
    if (t.m_valid) {
      const EventFixed g = sim.read_event();
      if (got >= expected.size()) {
        fail("extra event");
      } else if (!(g == expected[got])) {
        const auto& e = expected[got];
        fail(event_mismatch(got, "expected", e, g));
      }
      ++got;
    }
    if (busy && t.s_ready && jb == 0) {  // the event (if any) leaves on the clock s_ready rises
      const std::uint64_t b = cycle - started_at;
      r.max_busy = std::max(r.max_busy, b);
      if (got > busy_start_events) r.max_busy_event = std::max(r.max_busy_event, b);
      busy = false;
    }
    if (present) {
      if (first_clock && !t.s_ready) ++r.stalls;
      first_clock = false;
      if (t.s_ready) {
        first_clock = true;
        if (jb == 0) {
          started_at = cycle;
          busy_start_events = got;
        }
        if (++jb == beats[in].q.size()) {
          jb = 0;
          ++in;
          busy = true;
          if (period && cycle >= due + period) ++r.late;
          due = period ? due + period : cycle + 1;
        }
      }
    }
    sim.tick();
    ++cycle;
  }
  for (int i = 0; i < 400; ++i) {  // drain: the last group's event, nothing else
    sim.top().s_valid = 0;
    sim.top().m_ready = 1;
    sim.top().eval();
    if (sim.top().m_valid) {
      if (got >= expected.size()) fail("extra event after the last group");
      ++got;
    }
    sim.tick();
  }
  if (got != expected.size()) fail(std::to_string(got) + " of " + std::to_string(expected.size()) + " events");
  r.events = got;
  return r;
}

TEST(PeakDetectorRtl, PacedAtTheBankRateNeverStallsAndStaysBitExact) {
  const auto& d = design();
  const std::uint64_t period = static_cast<std::uint64_t>(d.layout.decimation) * 6;  // 5 MS/s at 30 MHz
  std::vector<Beat> beats;
  std::vector<EventFixed> events;
  std::size_t before = 0;
  const auto y = burst_stream(300, 0.003, 36);
  model(y, SIZE_MAX, beats, events, before);
  // The step-by-step reference used for the synthetic cases equals the model here.
  RefDetector ref;
  std::vector<EventFixed> ref_events;
  for (const auto& b : beats)
    if (auto e = ref.execute(b)) ref_events.push_back(*e);
  EXPECT_EQ(ref_events, events);
  DetSim sim;
  const auto r = run_paced(sim, beats, events, period);
  std::printf("peak_detector paced: %zu groups of %zu beats, one group every %llu clocks, %llu events, "
              "%llu stalled beats, %llu late groups; max clocks per group %llu, per group with an event %llu\n",
              beats.size(), beats.front().q.size(), static_cast<unsigned long long>(period),
              static_cast<unsigned long long>(r.events), static_cast<unsigned long long>(r.stalls),
              static_cast<unsigned long long>(r.late), static_cast<unsigned long long>(r.max_busy),
              static_cast<unsigned long long>(r.max_busy_event));
  EXPECT_EQ(r.mismatches, 0u) << r.first;
  EXPECT_EQ(r.stalls, 0u);
  EXPECT_EQ(r.late, 0u);
  EXPECT_GT(r.events, 30u);
  EXPECT_GT(r.max_busy_event, 0u);
  EXPECT_LE(r.max_busy_event, period);
}

TEST(PeakDetectorRtl, DividerAndCrossProductEdgeCases) {
  const auto& d = design();
  const int codes = static_cast<int>(d.family.codes.size());
  const int ww = d.layout.weighted_bits, shift = d.layout.energy_shift;
  const int sb = d.config.correlator.score_bits, fb = d.config.detector.frac_bits;
  const std::uint64_t qmax = (ww >= 64) ? ~std::uint64_t{0} : (std::uint64_t{1} << ww) - 1;
  const int norm_bits = d.layout.energy_bits - shift;
  const std::uint64_t nmax = (std::uint64_t{1} << std::min(norm_bits, 40)) - 1;
  const std::uint64_t cap = (std::uint64_t{1} << sb) - 1;
  const std::int64_t half = std::int64_t{1} << (fb - 1);
  RefDetector ref;
  ASSERT_GE(nmax, ref.min_norm());
  std::mt19937_64 rng(4242);
  std::vector<Beat> beats;
  std::uint64_t n = 5000;
  const std::uint64_t step = static_cast<std::uint64_t>(d.layout.decimation);
  auto beat = [&](int code, std::uint64_t qc, int code2, std::uint64_t q2, std::uint64_t norm) {
    Beat b;
    b.q.assign(static_cast<std::size_t>(codes), 0);
    for (auto& v : b.q) v = rng() % 1000;
    b.q[static_cast<std::size_t>(code2)] = q2;
    b.q[static_cast<std::size_t>(code)] = qc;
    b.energy = (norm << shift) | (rng() & ((std::uint64_t{1} << shift) - 1));
    b.index = n;
    n += step;
    beats.push_back(b);
  };
  // A peak (qp, q, qn) of code c with norm nb, second code q2, then quiet beats past the holdoff.
  // gated_tail: the quiet beats pass the gate (rho^2 ~ 0.6) but not the candidate's rho^2 test, so
  // the event leaves on a beat that ran both MAC programs (the longest beat).
  auto peak = [&](std::uint64_t qp, std::uint64_t q, std::uint64_t qn, std::uint64_t q2, std::uint64_t nb,
                  std::uint64_t nc, bool gated_tail = false) {
    const int c = static_cast<int>(rng() % static_cast<std::uint64_t>(codes));
    const int c2 = (c + 1 + static_cast<int>(rng() % static_cast<std::uint64_t>(codes - 1))) % codes;
    beat(c, qp, c2, 0, nmax);
    beat(c, q, c2, q2, nb);
    beat(c, qn, c2, 0, nc);
    const std::uint64_t tail = gated_tail ? (ref.threshold() * 5 / 4) * ref.min_norm() : 0;
    for (int i = 0; i < ref.holdoff() / static_cast<int>(step) + 3; ++i) beat(c, 0, c2, tail, ref.min_norm());
  };
  const std::uint64_t norms[] = {ref.min_norm(), 12345, nmax};
  for (std::uint64_t nb : norms) {
    // score: exactly at the cap, at 2^S (capped), just below; second score at the same edges
    const std::uint64_t qs[] = {nb * cap + nb - 1, nb * (cap + 1), nb * cap - 1, nb * (cap + 1) - 1};
    for (std::uint64_t q : qs) {
      if (q > qmax) continue;
      peak(q / 2, q, q / 3, q - 1, nb, nmax, true);
      peak(q / 2, q, q / 3, nb * cap - 1, nb, nmax);
      peak(q / 2, q, q / 3, nb * (cap + 1) - 1 <= q ? nb * (cap + 1) - 1 : q / 2, nb, nmax);
    }
  }
  const std::uint64_t big = qmax - 7;
  // fraction: +1/2 exactly (qn = q), -1/2 (qp = q), zero / negative denominators, 48-bit operands
  peak(big / 3, big, big, big / 5, norms[2], nmax);
  peak(big, big, big / 3, big / 5, norms[2], nmax);
  peak(big, big, big, big / 5, norms[2], nmax);
  peak(big, big - 1000, big, 5, norms[2], nmax);
  peak(1000, 1000000, 1000, 5, 30, nmax);
  // fraction just inside +-1/2: (qn - qp) 2^F = (half - 1/2 ...) x 2 den
  for (int i = 0; i < 40; ++i) {
    const std::uint64_t q = (qmax >> 2) + rng() % (qmax >> 2);
    const std::uint64_t qp = q - 1 - rng() % (q >> 1);
    const std::uint64_t qn = q - 1 - rng() % 3;
    peak(qp, q, qn, rng() % q, 1 + rng() % nmax, nmax);
    peak(qn, q, qp, rng() % q, 1 + rng() % nmax, nmax);
  }
  // equal rho^2 (strict >: the earlier candidate stays) and one just better, on wide operands
  for (int i = 0; i < 10; ++i) {
    const std::uint64_t nb = 1000 + rng() % (nmax / 4);
    const std::uint64_t q = std::min<std::uint64_t>(qmax / 4, nb * (cap / 2 + rng() % (cap / 2)));
    peak(q / 2, q, 2 * q, q / 2, nb, 2 * nb);
    peak(q / 2, q, 2 * q + 1, q / 2, nb, 2 * nb);
    peak(q / 2, q, 2 * q - 1, q / 2, nb, 2 * nb);
  }
  // random wide values
  for (int i = 0; i < 150; ++i) {
    const std::uint64_t q = rng() & qmax;
    peak(rng() % (q + 1), q, rng() % (q + 1), rng() % (q + 1), 1 + rng() % nmax, 1 + rng() % nmax);
  }
  std::vector<EventFixed> expected;
  for (const auto& b : beats)
    if (auto e = ref.execute(b)) expected.push_back(*e);
  int at_cap = 0, below_cap = 0, plus_half = 0, minus_half = 0, den_le0 = 0, inner = 0;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    at_cap += expected[i].score == cap;
    below_cap += expected[i].score == cap - 1;
    const std::int64_t f = ref.fractions[i];
    plus_half += f == half;
    minus_half += f == -half;
    den_le0 += ref.den_not_positive[i] ? 1 : 0;
    inner += (f == half - 1 || f == 1 - half) ? 1 : 0;
  }
  DetSim sim;
  const auto r = run_paced(sim, beats, expected, 0);
  std::printf("peak_detector edge cases, back to back: max clocks per group %llu, per group with an event %llu\n",
              static_cast<unsigned long long>(r.max_busy), static_cast<unsigned long long>(r.max_busy_event));
  EXPECT_LE(r.max_busy_event, static_cast<std::uint64_t>(d.layout.decimation) * 6);
  std::printf("peak_detector edge cases: %zu groups, %zu events (score: %d at the cap, %d at cap - 1; fraction: "
              "%d at +1/2, %d at -1/2, %d at +-(1/2 - 1 lsb), %d with denominator <= 0), %llu mismatches\n",
              beats.size(), expected.size(), at_cap, below_cap, plus_half, minus_half, inner, den_le0,
              static_cast<unsigned long long>(r.mismatches));
  EXPECT_EQ(r.mismatches, 0u) << r.first;
  EXPECT_GT(at_cap, 5);
  EXPECT_GT(below_cap, 3);
  EXPECT_GT(plus_half, 0);
  EXPECT_GT(minus_half, 0);
  EXPECT_GT(den_le0, 1);
  EXPECT_GT(inner, 0);
  EXPECT_GT(expected.size(), 200u);
}

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(PeakDetectorRtl, VerilatorLintIsClean) {
  const std::string vc = std::string(RANGING_GENERATED_DIR) + "/rtl/peak_detector.vc";
  const std::string rtl = std::string(RANGING_SOURCE_DIR) + "/rtl/peak_detector.v";
  const std::string log = std::string(RANGING_TRACE_DIR) + "/tb_peak_detector_lint.log";
  const int rc = std::system(("verilator --lint-only -Wall -f " + vc + " " + rtl + " > " + log + " 2>&1").c_str());
  const std::string out = slurp(log);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_EQ(out.find("%Warning"), std::string::npos) << out;
  EXPECT_EQ(out.find("%Error"), std::string::npos) << out;
}

}  // namespace
