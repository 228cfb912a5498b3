// Decoding against the send schedule: a burst that arrives before its code was first sent has
// no time of flight. A capture cut one whole code cycle into a periodic train starts with the
// echoes of the previous cycle's last codes; the decoder used to measure them from t = 0 and
// printed distances of 87, 225 and 362 mm for a 500 mm link. They are now reported with their
// arrival, tof_s and distance_m null, and counted; every other burst keeps its distance.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "model/base/error.hpp"
#include "model/sim/capture.hpp"
#include "model/sim/capture_calibration.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"

namespace {

using ranging::Capture;
using ranging::Detection;
using ranging::testing_support::run_tool;
using ranging::testing_support::ScratchDir;

constexpr double kPeriod = 0.0004;  // s between bursts, codes 1..9 in turn (Gold4)
constexpr int kEta = 9;

// A simulated periodic Gold4 train at 0.5 m, cut `cycles` whole code cycles (9 bursts) in, so
// its t = 0 is again a send of code 1. Returns the cut capture's path (16-bit WAV).
std::string cut_train(const ScratchDir& dir, int cycles) {
  std::ofstream(dir.file("train.yaml"))
      << "name: train\nmedium: {temperature_c: 20}\ntransducers: {}\ngeometry: {distances_m: [0.5]}\n"
         "excitation: {family: Gold4, schedule: {mode: periodic, period_s: 0.0004, bursts: 27}}\n"
         "noise: {noise_v: 0.002, seed: 1}\n";
  const auto sim = run_tool("simulate " + dir.file("train.yaml") + " --out " + dir.file("out") +
                            " --write-captures --quiet");
  EXPECT_EQ(sim.status, 0) << sim.err;
  const Capture c = ranging::read_capture(dir.file("out/captures/Gold4_500mm_r1.wav"));
  Capture cut = c;
  const auto skip = static_cast<std::size_t>(std::lround(cycles * kEta * kPeriod * c.sample_rate));
  cut.samples.assign(c.samples.begin() + static_cast<long>(skip), c.samples.end());
  const std::string path = dir.file("cut.wav");
  ranging::write_file_atomic(path, ranging::capture_wav(cut, ranging::WavFormat::Float32));
  return path;
}

TEST(DecodeSchedule, BurstsArrivingBeforeTheirCodesFirstSendHaveNoDistance) {
  const ScratchDir dir("decode_schedule", ::testing::TempDir());
  const std::string wav = cut_train(dir, 1);
  const auto r = run_tool("decode " + wav + " --family Gold4 --period 0.0004 --speed-of-sound 343.987 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  std::size_t nulls = 0, early_found = 0, measured = 0;
  for (const char* list : {"detections", "below_gate"}) {
    for (const auto& d : j.at(list)) {
      const int code = d.at("code").get<int>();
      const double first_send = (code - 1) * kPeriod;
      if (d.at("tof_s").is_null()) {
        ++nulls;
        EXPECT_TRUE(d.at("distance_m").is_null()) << d;
        ASSERT_TRUE(d.contains("arrival_s")) << d;
        EXPECT_LT(d.at("arrival_s").get<double>(), first_send) << d;
        if (std::string(list) == "detections") ++early_found;
        continue;
      }
      if (std::string(list) != "detections") continue;
      // measured from a send of its own code: arrival - tof is k * period with k = code - 1 (mod 9)
      const double tof = d.at("tof_s").get<double>();
      EXPECT_GT(tof, 0.0) << d;
      EXPECT_NEAR(d.at("distance_m").get<double>(), 0.5, 0.005) << d;
      ++measured;
    }
  }
  EXPECT_EQ(j.at("arrivals_before_first_send").get<std::size_t>(), nulls);
  // the previous cycle's codes 7, 8 and 9 arrive at about 0.25, 0.65 and 1.05 ms
  EXPECT_GE(early_found, 3u) << r.out;
  EXPECT_GE(measured, 15u) << r.out;

  // The text output gives them no distance and says why.
  const auto t = run_tool("decode " + wav + " --family Gold4 --period 0.0004 --speed-of-sound 343.987");
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_NE(t.out.find("before code 7 was first sent: no ToF"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("burst(s) arrived before their code was first sent"), std::string::npos) << t.out;
  EXPECT_EQ(t.out.find("   87."), std::string::npos) << t.out;  // the old distance of code 7's echo, mm
}

// More workers than the machine has threads (--jobs 256): the same output as one, and nothing
// from the thread library on stderr (an arena wider than TBB's threads printed "TBB Warning").
TEST(DecodeSchedule, ManyMoreJobsThanCoresGiveTheSameOutputQuietly) {
  const ScratchDir dir("decode_jobs", ::testing::TempDir());
  const std::string wav = cut_train(dir, 1);
  const std::string args = "decode " + wav + " --family Gold4 --period 0.0004 --speed-of-sound 343.987 --json";
  const auto one = run_tool(args + " --jobs 1");
  const auto many = run_tool(args + " --jobs 256");
  ASSERT_EQ(one.status, 0) << one.err;
  ASSERT_EQ(many.status, 0) << many.err;
  EXPECT_EQ(many.out, one.out);
  EXPECT_EQ(many.err.find("TBB"), std::string::npos) << many.err;
  EXPECT_EQ(many.err, one.err);
}

// Latency calibration takes its ToF from detections with a send before them only.
TEST(DecodeSchedule, CalibrationLeavesOutDetectionsWithoutASendBeforeThem) {
  Detection early, ok;
  early.code = ok.code = 2;
  early.tof_from_send = false;
  early.tof_s = 0.0002;  // a time from t = 0, not a flight
  early.score = 0.99;    // the stronger one: it would win if it were taken
  ok.tof_s = 0.0015;
  ok.score = 0.5;
  const auto cal = ranging::calibrate_latency({early, ok}, 0.5, 340.0, "option --calibrate");
  ASSERT_EQ(cal.per_code_s.size(), 1u);
  EXPECT_DOUBLE_EQ(cal.per_code_s.at(2), 0.0015 - 0.5 / 340.0);
  try {
    (void)ranging::calibrate_latency({early}, 0.5, 340.0, "option --calibrate");
    FAIL() << "a calibration with no usable detection was accepted";
  } catch (const ranging::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("before its code was first sent"), std::string::npos) << e.what();
  }
}

}  // namespace
