// SceneSimulator::set_jobs (issue 13, "several cores"): the streams of a run processed by N
// threads give the very measurements, false alarms, overflow counts, capture callbacks and
// progress ticks of one thread, in the same order; `ranging simulate --jobs N` writes the same
// files as --jobs 1.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <vector>

#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"

using namespace ranging;

namespace {

// Noise, a receiver input that saturates at the short distances, two families, single and periodic mode.
std::string scene_yaml(const std::string& precision, bool periodic) {
  std::ostringstream y;
  y << "medium:\n  temperature_c: 20\ntransducers: {}\ngeometry:\n  distances_m: [0.1, 0.4, 0.9]\n"
       "  repeats: 2\nexcitation:\n  family: [M1, Gold4]\n";
  if (periodic) y << "  schedule:\n    mode: periodic\n    period_s: 0.0006\n    bursts: 4\n";
  // No ADC stage: the receiver's input scale is receiver.full_scale_v, low enough that the fixed
  // receiver's input saturates at the short distances (its overflow counts are compared).
  y << "noise:\n  noise_v: 0.05\n  seed: 5\nreceiver:\n  full_scale_v: 0.3\n  precision: " << precision << "\n";
  return y.str();
}

struct RunResult {
  std::vector<Measurement> rows;
  std::vector<std::size_t> false_alarms;
  std::vector<std::uint64_t> overflows;
  std::vector<std::string> captures;  // family, distance, repeat, code, samples, checksum, in callback order
  std::size_t ticks = 0;
};

// observed: a fixed-stream observer is set, so every stream runs alone through ReceiverFixed
// (otherwise the fixed precision receives 8 streams at once through ReceiverFixedBatch).
RunResult run_all(const std::string& yaml, int jobs, std::size_t* observed = nullptr) {
  SceneSimulator sim(parse_scene(yaml, "s.yaml"));
  sim.set_jobs(jobs);
  if (observed) {
    sim.set_fixed_observer([observed](const ReceiverDesign&, const std::vector<std::int64_t>&,
                                      const std::vector<EventFixed>&) { ++*observed; });
  }
  RunResult r;
  for (const auto& f : sim.scene().excitation.families) {
    std::size_t fa = 0;
    std::uint64_t ovf = 0;
    auto rows = sim.run(
        f, [&] { ++r.ticks; },
        [&](const CaptureStream& c) {
          double sum = 0;
          for (double v : *c.volts) sum += v * v;
          std::ostringstream os;
          os.precision(17);
          os << c.family << " " << c.distance_m << " " << c.repeat << " " << c.code << " " << c.volts->size() << " "
             << sum;
          r.captures.push_back(os.str());
        },
        &fa, &ovf);
    r.rows.insert(r.rows.end(), rows.begin(), rows.end());
    r.false_alarms.push_back(fa);
    r.overflows.push_back(ovf);
  }
  return r;
}

void expect_same(const RunResult& a, const RunResult& b) {
  ASSERT_EQ(a.rows.size(), b.rows.size());
  for (std::size_t i = 0; i < a.rows.size(); ++i) {
    const Measurement &x = a.rows[i], &y = b.rows[i];
    SCOPED_TRACE("row " + std::to_string(i));
    EXPECT_EQ(x.family, y.family);
    EXPECT_EQ(x.true_distance_m, y.true_distance_m);
    EXPECT_EQ(x.repeat, y.repeat);
    EXPECT_EQ(x.burst, y.burst);
    EXPECT_EQ(x.code_sent, y.code_sent);
    EXPECT_EQ(x.detected, y.detected);
    EXPECT_EQ(x.det.code, y.det.code);
    EXPECT_EQ(x.det.tof_s, y.det.tof_s);  // bit for bit
    EXPECT_EQ(x.det.score, y.det.score);
    EXPECT_EQ(x.det.rho, y.det.rho);
    EXPECT_EQ(x.det.energy, y.det.energy);
    EXPECT_EQ(x.det.td_s, y.det.td_s);
    EXPECT_EQ(x.error_m, y.error_m);
    EXPECT_EQ(std::isnan(x.u), std::isnan(y.u));
    if (!std::isnan(x.u)) {
      EXPECT_EQ(x.u, y.u);
    }
    EXPECT_EQ(x.pearson_error, y.pearson_error);
  }
  EXPECT_EQ(a.false_alarms, b.false_alarms);
  EXPECT_EQ(a.overflows, b.overflows);
  EXPECT_EQ(a.captures, b.captures);
  EXPECT_EQ(a.ticks, b.ticks);
}

}  // namespace

TEST(ParallelStreams, FixedSingleModeIsIdenticalWithOneAndThreeThreads) {
  const std::string y = scene_yaml("fixed", false);
  const RunResult one = run_all(y, 1);
  // 3 distances x 2 repeats x (eta of M1 + eta of Gold4) single bursts, a stream each.
  ASSERT_EQ(one.ticks, one.rows.size());
  ASSERT_GT(one.rows.size(), 20u);
  std::uint64_t ovf = 0;
  for (auto v : one.overflows) ovf += v;
  EXPECT_GT(ovf, 0u) << "the receiver input at 0.3 V full scale should saturate at 0.1 m: overflow counts are compared";
  expect_same(one, run_all(y, 3));
}

// Groups of streams (ReceiverFixedBatch / ReceiverFloatBatch) against one stream at a time
// (ReceiverFixed / ReceiverFloat, forced by a fixed-stream observer): the same measurements,
// overflow counts and captures, both precisions, single and periodic.
TEST(ParallelStreams, GroupsOfStreamsMatchTheReceiverOneStreamAtATime) {
  for (const char* precision : {"fixed", "float"}) {
    for (bool periodic : {false, true}) {
      SCOPED_TRACE(std::string(precision) + (periodic ? " periodic" : " single"));
      const std::string y = scene_yaml(precision, periodic);
      std::size_t observed = 0;
      const RunResult alone = run_all(y, 1, &observed);
      if (std::string(precision) == "fixed") {
        EXPECT_GE(observed, alone.ticks) << "every stream (and each calibration) went through the observed receiver";
      }
      ASSERT_GT(alone.ticks, 8u) << "more streams than one group";
      expect_same(alone, run_all(y, 1));
      expect_same(alone, run_all(y, 2));
    }
  }
}

TEST(ParallelStreams, FloatPeriodicIsIdenticalWithOneAndTwoThreads) {
  const std::string y = scene_yaml("float", true);
  const RunResult one = run_all(y, 1);
  ASSERT_EQ(one.ticks, 12u);  // 3 distances x 2 repeats, per family one train
  expect_same(one, run_all(y, 2));
  expect_same(one, run_all(y, 64));  // more threads than streams
}

namespace {
std::string stream_id(const CaptureStream& c) {
  return std::to_string(c.distance_m) + "/" + std::to_string(c.repeat) + "/" + std::to_string(c.code);
}
}  // namespace

// A capture callback that throws at the k-th stream: with any number of threads the streams
// before it are emitted (their callbacks and ticks, in stream order), the error comes out of
// run(), and no later stream is emitted, as with one thread. k = 0, one inside the first group of
// 8, and one in a later group.
TEST(ParallelStreams, AFailingCaptureStopsTheRunAfterTheStreamsBeforeIt) {
  // the streams as one thread emits them without a failure: 3 distances x 2 repeats x 9 codes
  std::vector<std::string> all;
  SceneSimulator ref(parse_scene(scene_yaml("float", false), "s.yaml"));
  (void)ref.run("Gold4", nullptr, [&](const CaptureStream& c) { all.push_back(stream_id(c)); });
  ASSERT_EQ(all.size(), 54u);
  for (std::size_t k : {std::size_t{0}, std::size_t{5}, std::size_t{17}}) {
    for (int jobs : {1, 2, 3}) {
      SCOPED_TRACE("k " + std::to_string(k) + ", jobs " + std::to_string(jobs));
      SceneSimulator sim(parse_scene(scene_yaml("float", false), "s.yaml"));
      sim.set_jobs(jobs);
      std::vector<std::string> seen;  // the callbacks' streams, in call order
      std::size_t calls = 0, ticks = 0;
      try {
        (void)sim.run(
            "Gold4", [&] { ++ticks; },
            [&](const CaptureStream& c) {
              if (calls++ == k) throw std::runtime_error("disk full");  // once: a later call is recorded
              seen.push_back(stream_id(c));
            });
        ADD_FAILURE() << "run() returned";
      } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "disk full");
      }
      EXPECT_EQ(calls, k + 1) << "no stream after the failing one is emitted";
      EXPECT_EQ(ticks, k);
      EXPECT_EQ(seen, std::vector<std::string>(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(k)));
    }
  }
}

TEST(ParallelStreams, SimulateWritesTheSameFilesWithJobs) {
  namespace fs = std::filesystem;
  const testing_support::ScratchDir scratch("ranging_parallel");
  const fs::path dir = scratch.path();
  {
    std::ofstream(dir / "s.yaml") << scene_yaml("fixed", false);
  }
  auto files = [&](const std::string& name, int jobs) {
    const auto r = testing_support::run_tool("simulate \"" + (dir / "s.yaml").string() + "\" --out \"" +
                                             (dir / name).string() + "\" --quiet --jobs " + std::to_string(jobs));
    EXPECT_EQ(r.status, 0) << r.err;
    std::ifstream in(dir / name / "measurements.csv");
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  const std::string a = files("j1", 1), b = files("j2", 2);
  EXPECT_GT(a.size(), 1000u);
  EXPECT_EQ(a, b);
  const auto bad = testing_support::run_tool("simulate \"" + (dir / "s.yaml").string() + "\" --out \"" +
                                             (dir / "bad").string() + "\" --jobs 0");
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(bad.out.empty());
  EXPECT_NE(bad.err.find("--jobs"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad"));
}
