// rtl/tof_distance.v against ranging::TofDistanceModel (model/hw/hw_system.hpp), bit for bit:
// every measurement {code, flags, ToF, distance, score, margin} on directed corners and random
// events. The parameters are the generated system's (tb/tof_distance.cmake).
#include <gtest/gtest.h>

#include <cstdint>
#include <iostream>
#include <optional>
#include <random>
#include <string>

#include "Vtof_distance.h"
#include "model/config/receiver_config.hpp"
#include "model/hw/hw_system.hpp"
#include "model/dsp/receiver.hpp"
#include "tb/verilator_harness.hpp"

namespace {

using namespace ranging;
using ranging::tb::Harness;

const SystemDesign& sys() {
  static const SystemDesign s =
      system_design(design_receiver(load_receiver_config(std::string(RANGING_SOURCE_DIR) + "/configs/default.yaml")));
  return s;
}

class TofBench {
 public:
  TofBench() : h_("tb_tof_distance"), model_(sys()) {
    auto& t = h_.top();
    t.rst = 1;
    t.burst_valid = 0;
    t.c_wr = 0;
    t.s_valid = 0;
    t.m_ready = 1;
    for (int i = 0; i < 3; ++i) h_.tick();
    t.rst = 0;
    h_.tick();
    model_.reset();
  }
  void burst(int code, std::int64_t start) {
    auto& t = h_.top();
    t.burst_valid = 1;
    t.burst_code = static_cast<std::uint8_t>(code);
    t.burst_time = static_cast<std::uint64_t>(start);
    h_.tick();
    t.burst_valid = 0;
    model_.burst(code, start);
  }
  void speed(std::uint32_t c) {
    auto& t = h_.top();
    t.c_wr = 1;
    t.c_value = c;
    h_.tick();
    t.c_wr = 0;
    model_.set_speed(c);
  }
  // One event through the module: offered until s_ready, then m_ready held low for ready_delay
  // clocks after m_valid; the RTL's measurement, or nullopt if the module did not take the event
  // or did not answer within `limit` clocks (each).
  std::optional<Measurement32> measure(int code, std::int64_t arrival, std::uint32_t score, std::uint32_t margin,
                                       int ready_delay, std::uint64_t limit) {
    auto& t = h_.top();
    const int arr_w = sys().time_w + sys().frac_w + 1;
    t.s_code = static_cast<std::uint8_t>(code);
    ranging::tb::set_port(t.s_arrival, arrival, arr_w);
    t.s_score = static_cast<std::uint16_t>(score);
    t.s_margin = static_cast<std::uint16_t>(margin);
    t.s_valid = 1;
    t.m_ready = 0;
    for (std::uint64_t clocks = 0;; ++clocks) {
      h_.settle();
      const bool take = t.s_ready;
      h_.tick();
      if (take) break;
      if (clocks >= limit) return std::nullopt;
    }
    t.s_valid = 0;
    for (std::uint64_t clocks = 0;; ++clocks) {
      h_.settle();
      if (t.m_valid) break;
      h_.tick();
      if (clocks >= limit) return std::nullopt;
    }
    for (int i = 0; i < ready_delay; ++i) h_.tick();  // held while m_valid && !m_ready
    h_.settle();
    Measurement32 m;
    m.code = t.m_code;
    m.flags = t.m_flags;
    m.tof = t.m_tof;
    m.distance = t.m_distance;
    m.score = t.m_score;
    m.margin = t.m_margin;
    t.m_ready = 1;
    h_.tick();
    t.m_ready = 0;
    return m;
  }
  // One event through the module; returns false with a message on a mismatch.
  ::testing::AssertionResult event(int code, std::int64_t arrival, std::uint32_t score, std::uint32_t margin,
                                   int ready_delay) {
    const auto got = measure(code, arrival, score, margin, ready_delay, 100000);
    if (!got) return ::testing::AssertionFailure() << "the module did not take the event or answer";
    const Measurement32 e = model_.execute(code, arrival, score, margin);
    const int got_code = got->code, got_flags = static_cast<int>(got->flags);
    const std::uint32_t got_tof = got->tof, got_dist = got->distance;
    const std::uint32_t got_score = static_cast<std::uint32_t>(got->score);
    const std::uint32_t got_margin = static_cast<std::uint32_t>(got->margin);
    ++events_;
    flags_seen_ |= 1u << got_flags;
    if (got_code != e.code || static_cast<unsigned>(got_flags) != e.flags || got_tof != e.tof ||
        got_dist != e.distance || got_score != e.score || got_margin != e.margin) {
      return ::testing::AssertionFailure()
             << "code " << code << " arrival " << arrival << ": rtl {" << got_code << ", flags " << got_flags
             << ", tof " << got_tof << ", dist " << got_dist << ", " << got_score << ", " << got_margin
             << "} model {" << e.code << ", flags " << e.flags << ", tof " << e.tof << ", dist " << e.distance
             << ", " << e.score << ", " << e.margin << "}";
    }
    return ::testing::AssertionSuccess();
  }
  int events() const { return events_; }
  unsigned flags_seen() const { return flags_seen_; }

 private:
  Harness<Vtof_distance> h_;
  TofDistanceModel model_;
  int events_ = 0;
  unsigned flags_seen_ = 0;  // bit f: flags value f occurred
};

TEST(TofDistanceRtl, DirectedCornersAndRandomEventsEqualTheModel) {
  const SystemDesign& s = sys();
  const std::int64_t one = std::int64_t{1} << s.frac_w, T = s.period_t;
  auto off = [&](int code) { return s.offsets[static_cast<std::size_t>(code - 1)]; };
  TofBench b;
  // No burst sent yet: flag 0, ToF and distance 0.
  ASSERT_TRUE(b.event(3, 500 * one + off(3), 100, 7, 0));
  // The first bursts of the schedule (codes 1, 2, ...), then arrivals of codes sent and not yet sent.
  std::int64_t now = 1000;
  int next_code = 1;
  auto send = [&]() {
    b.burst(next_code, now);
    next_code = next_code == s.codes ? 1 : next_code + 1;
    now += T;
  };
  send();
  send();
  ASSERT_TRUE(b.event(1, (1000 + 800) * one + off(1) + 37, 1, 2, 3));   // code 1's burst
  ASSERT_TRUE(b.event(2, (1000 + T + 5) * one + off(2), 1, 2, 0));     // code 2's burst
  ASSERT_TRUE(b.event(5, (1000 + T + 5) * one + off(5), 1, 2, 0));     // code 5 before the first burst
  ASSERT_TRUE(b.event(2, (1000 + 2) * one + off(2), 9, 9, 1));         // arrival before code 2 was sent
  for (int i = 0; i < 3 * s.codes; ++i) send();
  // Arrivals several cycles after a code's last burst step back whole cycles; ToF saturation.
  ASSERT_TRUE(b.event(4, now * one + off(4) + 12345, 3, 4, 0));
  ASSERT_TRUE(b.event(4, (now + (std::int64_t{1} << 25)) * one + off(4), 3, 4, 0));
  // Speed register: full scale saturates the distance; back to the configured speed.
  b.speed(0xffffffffu);
  ASSERT_TRUE(b.event(6, (now - 2 * T + 70000) * one + off(6), 5, 6, 2));
  b.speed(s.c_init);
  // Random events around the schedule.
  std::mt19937_64 rng(2025);
  for (int round = 0; round < 400; ++round) {
    if (rng() % 3 == 0) send();
    if (rng() % 50 == 0) b.speed(static_cast<std::uint32_t>(rng()));
    if (rng() % 50 == 1) b.speed(s.c_init);
    const int code = 1 + static_cast<int>(rng() % static_cast<std::uint64_t>(s.codes));
    const std::int64_t flight = static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(4 * T)) - T;
    const std::int64_t frac = static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(2 * one)) - one;
    const std::int64_t arrival = (now - 2 * T + flight) * one + off(code) + frac;
    ASSERT_TRUE(b.event(code, arrival, static_cast<std::uint32_t>(rng() & 0xffff),
                        static_cast<std::uint32_t>(rng() & 0xffff), static_cast<int>(rng() % 4)))
        << "round " << round;
  }
  std::cout << b.events() << " measurements equal to TofDistanceModel; flags seen mask " << b.flags_seen() << "\n";
  // Every flag combination the module can produce was exercised: none, no burst, saturated.
  EXPECT_TRUE(b.flags_seen() & 1u);
  EXPECT_TRUE(b.flags_seen() & 2u);
  EXPECT_TRUE(b.flags_seen() & 4u);
}

// The sample counters (tx_scheduler's burst time, the bank's index) are TIME_W bits and wrap
// after 2^TIME_W samples (61.1 h at 5 MS/s with 40 bits), while the model's int64 time does not.
// This test drives the module as the wrapped counters would across the wrap: a burst every
// PERIOD_T, its time modulo 2^TIME_W, and its echo `flight` samples later, the arrival (receiver
// latency included) modulo 2^TIME_W. Every measurement must be the true time of flight, equal
// TofDistanceModel's on the same wrapped inputs, and come within 20 000 clocks. (Before the wrap
// rule, the echo of the last burst before the wrap made the module step back ~7.5e7 cycles:
// 1.5e8 clocks, 5 s at 30 MHz, a stall that backed the receiver up into an ADC overrun.)
TEST(TofDistanceRtl, AcrossTheSampleCounterWrapEveryMeasurementIsRight) {
  const SystemDesign& s = sys();
  const std::int64_t one = std::int64_t{1} << s.frac_w, T = s.period_t;
  const std::int64_t wrap = std::int64_t{1} << s.time_w;
  auto off = [&](int code) { return s.offsets[static_cast<std::size_t>(code - 1)]; };
  TofBench b;
  TofDistanceModel model(s);
  int code = 1, right = 0;
  std::int64_t t = wrap - 4 * s.codes * T;  // true (unwrapped) time of the next burst
  for (int i = 0; i < 8 * s.codes; ++i, t += T) {
    b.burst(code, t % wrap);
    model.burst(code, t % wrap);
    const std::int64_t flight = 700 + 37 * (i % 11);  // samples
    const std::int64_t arrival = ((t + flight) * one + off(code)) % (wrap * one);
    const auto m = b.measure(code, arrival, 1, 1, 0, 20000);
    ASSERT_TRUE(m) << "burst " << i << " (time " << t << "): no answer within 20000 clocks";
    const Measurement32 e = model.execute(code, arrival, 1, 1);
    EXPECT_EQ(m->flags, e.flags) << "burst " << i;
    EXPECT_EQ(m->tof, e.tof) << "burst " << i;
    EXPECT_EQ(m->distance, e.distance) << "burst " << i;
    EXPECT_EQ(m->flags, 0u) << "burst " << i << " (time " << t << ", wrapped " << t % wrap << ")";
    EXPECT_EQ(m->tof, static_cast<std::uint32_t>(flight * one)) << "burst " << i << " (time " << t << ")";
    right += m->flags == 0 && m->tof == static_cast<std::uint32_t>(flight * one);
    code = code == s.codes ? 1 : code + 1;
  }
  std::cout << right << " of " << 8 * s.codes << " measurements right across the wrap at 2^" << s.time_w << "\n";
}

}  // namespace
