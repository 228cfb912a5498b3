// Host side of a crossing (model/hw/rotor_host.hpp): the burst index of a frame from the host's
// reception time and the code, and h from frames built from the exact moving geometry
// (reception_time of model/sim/moving_channel.hpp, independent of the estimators' algebra).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "model/hw/rotor_host.hpp"

using namespace ranging;

namespace {

HostTiming timing() {
  HostTiming t;
  t.fs = 5e6;
  t.period_t = 1634;
  t.codes = 9;
  t.latency_s = 250e-6;
  return t;
}

TEST(RotorHost, BurstIndexFromCodeAndHostTime) {
  const auto t = timing();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-1.4e-3, 1.4e-3);  // < eta T / 2 = 1.47 ms
  for (long k : {0L, 1L, 8L, 9L, 10L, 1000L, 123457L}) {
    UartFrame f;
    f.code = static_cast<int>(k % 9) + 1;
    f.tof_q8 = 3000 * 256 + 17;
    const double t_emit = static_cast<double>(k) * t.period_t / t.fs;
    const double t_host = t_emit + f.tof_q8 / 256.0 / t.fs + t.latency_s + jitter(rng);
    EXPECT_EQ(frame_burst_index(f, t_host, t), k);
  }
  UartFrame bad;
  bad.code = 10;
  EXPECT_EQ(frame_burst_index(bad, 1.0, t), -1);
  bad.code = 0;
  EXPECT_EQ(frame_burst_index(bad, 1.0, t), -1);
}

TEST(RotorHost, HFromExactFrames) {
  const auto t = timing();
  RotorParams p;
  p.rpm = 45;
  const double c = 340, burst_s = 700 / t.fs, h = 0.3;
  const double tc = 0.0123;  // crossing time in the system's time base
  MovingLink link;
  link.tx = rotor_tx(p, h);
  link.rx = rotor_rx(p, tc);
  link.c = c;
  std::vector<UartFrame> frames;
  std::vector<double> t_host;
  const double T = t.period_t / t.fs;
  for (long k = std::lround(tc / T) - 3; k <= std::lround(tc / T) + 3; ++k) {
    const double te = static_cast<double>(k) * T + burst_s / 2;  // the estimators' emission: the burst centre
    const double tof = reception_time(link, te, te + h / c) - te;
    UartFrame f;
    f.code = static_cast<int>(k % t.codes) + 1;
    f.tof_q8 = static_cast<std::uint32_t>(std::lround(tof * t.fs * 256));
    f.distance_um = static_cast<std::uint32_t>(std::lround(c * tof * 1e6));
    f.score = 60000;
    frames.push_back(f);
    t_host.push_back(static_cast<double>(k) * T + tof + t.latency_s);
  }
  // a flagged frame and a low-score frame are not used
  UartFrame flagged = frames.front();
  flagged.flags = 1;
  frames.push_back(flagged);
  t_host.push_back(t_host.front());
  UartFrame weak = frames.back();
  weak.flags = 0;
  weak.score = 1000;
  weak.tof_q8 /= 2;
  frames.push_back(weak);
  t_host.push_back(t_host.front());
  const auto e = estimate_crossing_from_frames(p, frames, t_host, t, c, burst_s, 1.0);
  EXPECT_EQ(e.samples.size(), 7u);
  EXPECT_NEAR(e.h_motion_m, h, 2e-6);
  // the paper's straight-line picture is biased by the motion during the flight
  EXPECT_TRUE(std::isfinite(e.h_paper_m));
}

}  // namespace
