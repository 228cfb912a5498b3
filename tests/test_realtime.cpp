// The real-time budget (model/hw/realtime.hpp, issue 17 section 7): the rule reproduces the
// figures the RTL headers state and tb_peak_detector measured at the default configuration
// (bank back end 117 <= 120 clocks per group, combiner 81, detector 101 < 120), refuses a clock below the
// bandpass's 6 clocks per sample, and marks configs/large.yaml (DECIM 1, 524 taps at 5 MS/s)
// "NOT REAL TIME" in manifest.json with the numbers, warning on stderr.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "model/config/receiver_config.hpp"
#include "model/hw/realtime.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"

namespace fs = std::filesystem;
using ranging::testing_support::run_tool;

namespace {

const std::string kSource = RANGING_SOURCE_DIR;

ranging::RealTimeBudget budget(const std::string& config, const ranging::Overrides& ov = {}) {
  const auto cfg = ranging::load_receiver_config(kSource + "/configs/" + config, ov);
  return ranging::realtime_budget(ranging::design_receiver(cfg));
}

}  // namespace

TEST(RealTime, DefaultMatchesTheRtlHeaders) {
  const auto r = budget("default.yaml");
  EXPECT_EQ(r.clocks_per_sample, 6);  // 30 MHz / 5 MS/s
  EXPECT_EQ(r.decimation, 20);
  EXPECT_EQ(r.group_clocks, 120);
  // rtl/correlator_bank.v: FIR 2*20*2 = 80 + 1, SQ 9*2, W 9*2: 117 <= 120.
  EXPECT_EQ(r.bank_back_end_clocks, 117);
  // rtl/correlator_bank.v: the combiner, (CHIPS + 2) CODES = 9 x 9 = 81 <= 120.
  EXPECT_EQ(r.combiner_clocks, 81);
  // rtl/peak_detector.v: <= 101 clocks per group (101 measured on the edge-case stream).
  EXPECT_EQ(r.detector_clocks, 101);
  EXPECT_TRUE(r.real_time) << r.summary();
  EXPECT_TRUE(r.limits.empty());
  EXPECT_DOUBLE_EQ(r.needed_clocks_per_sample(), 6.0);
  EXPECT_EQ(r.summary().rfind("real time: ", 0), 0u) << r.summary();
}

TEST(RealTime, SlowClockFailsTheBandpass) {
  const auto r = budget("default.yaml", {{"hardware.clock_hz", "20000000"}});  // 4 clocks per sample
  EXPECT_EQ(r.clocks_per_sample, 4);
  EXPECT_FALSE(r.real_time);
  ASSERT_FALSE(r.limits.empty());
  EXPECT_NE(r.limits[0].find("bandpass"), std::string::npos) << r.limits[0];
  EXPECT_NE(r.summary().find("NOT REAL TIME"), std::string::npos);
}

TEST(RealTime, HalfTheDecimationOverrunsTheBackEnd) {
  // DECIM 10 at 6 clocks per sample leaves 60 clocks per group: the detector's 101 and the
  // bank's back end (more taps per group) do not fit.
  const auto r = budget("default.yaml", {{"correlator.decimation", "10"}});
  EXPECT_EQ(r.group_clocks, 60);
  EXPECT_FALSE(r.real_time);
  EXPECT_GT(r.bank_back_end_clocks, 60);
  EXPECT_GT(r.detector_clocks, 60);
  EXPECT_GT(r.needed_clocks_per_sample(), 6.0);
}

// The combiner runs one round of CHIPS + 2 clocks per code for every output group, on its own
// engine: M3 (15 chips, 15 codes) needs 255 clocks per group. At DECIM 25 (150 clocks) the
// multiplier's back end (125) and the detector fit, and the rule used to say "real time" while
// the RTL fell behind one sample in six (ranging verify: 44074 of 44205 paced samples late).
TEST(RealTime, ALongFamilyOverrunsTheCombiner) {
  const auto r = budget("default.yaml", {{"family", "M3"}, {"correlator.decimation", "25"}});
  EXPECT_EQ(r.group_clocks, 150);
  EXPECT_LE(r.bank_back_end_clocks, 150);
  EXPECT_LE(r.detector_clocks, 150);
  EXPECT_EQ(r.combiner_clocks, (15 + 2) * 15);
  EXPECT_FALSE(r.real_time) << r.summary();
  ASSERT_EQ(r.limits.size(), 1u) << r.summary();
  EXPECT_NE(r.limits[0].find("combiner needs 255 > 150"), std::string::npos) << r.limits[0];
  EXPECT_DOUBLE_EQ(r.needed_clocks_per_sample(), 255.0 / 25);
  // DECIM 50 (300 clocks per group) gives it room
  EXPECT_TRUE(budget("default.yaml", {{"family", "M3"}, {"correlator.decimation", "50"}}).real_time);
}

TEST(RealTime, LargeConfigurationIsMarkedNotRealTime) {
  const ranging::testing_support::ScratchDir scratch("ranging_realtime");
  const fs::path out = scratch.path() / "out";  // made by generate
  const auto r = run_tool("generate --config " + kSource + "/configs/large.yaml --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("warning: NOT REAL TIME"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("correlator back end"), std::string::npos) << r.err;
  std::ifstream in(out / "manifest.json");
  ASSERT_TRUE(in.good());
  const auto j = nlohmann::json::parse(in);
  const auto& rt = j.at("real_time");
  EXPECT_FALSE(rt.at("real_time").get<bool>());
  EXPECT_EQ(rt.at("clocks_per_sample_available").get<int>(), 18);  // 90 MHz / 5 MS/s
  EXPECT_EQ(rt.at("group_clocks").get<int>(), 18);                 // DECIM 1
  // The back end's FIR alone is 2 TAPS limb products: hundreds of clocks per sample.
  EXPECT_GT(rt.at("bank_back_end_clocks_per_group").get<long long>(), 2 * 500);
  EXPECT_GT(rt.at("clocks_per_sample_needed").get<double>(), 18.0);
}

TEST(RealTime, DefaultManifestSaysRealTime) {
  std::ifstream in(kSource + "/generated/default/manifest.json");
  ASSERT_TRUE(in.good());
  const auto j = nlohmann::json::parse(in);
  EXPECT_TRUE(j.at("real_time").at("real_time").get<bool>());
}

// The sweep records the same verdict per point (cost.real_time, with the stage numbers) and the
// stability guard's verdict.
TEST(RealTime, SweepPointsCarryTheRuleAndTheStabilityVerdict) {
  const ranging::testing_support::ScratchDir scratch("ranging_realtime_sweep");
  const fs::path dir = scratch.path();
  std::ofstream(dir / "scene.yaml") << "name: tiny\ntransducers: {}\ngeometry:\n  distances_m: [0.3]\n"
                                       "excitation:\n  family: Gold4\n  codes: [1, 5]\n"
                                       "noise:\n  noise_v: 0.01\n  seed: 4\n";
  std::ofstream(dir / "spec.yaml") << "name: rt\nconfig: " << kSource << "/configs/default.yaml\nscene: scene.yaml\n"
                                   << "mode: grid\naxes:\n  - key: hardware.clock_hz\n    values: [20000000]\n";
  const auto r = run_tool("sweep " + (dir / "spec.yaml").string() + " --out " + (dir / "out").string() +
                          " --no-synth --no-plot --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream in(dir / "out" / "sweep.json");
  const auto j = nlohmann::json::parse(in);
  ASSERT_EQ(j.at("points").size(), 2u);
  for (const auto& p : j.at("points")) {
    ASSERT_EQ(p.at("status"), "ok") << p.dump();
    const bool base = p.at("default").get<bool>();
    const auto expect = base ? budget("default.yaml") : budget("default.yaml", {{"hardware.clock_hz", "20000000"}});
    const auto& c = p.at("cost");
    EXPECT_EQ(c.at("real_time").get<bool>(), expect.real_time);
    EXPECT_EQ(c.at("real_time").get<bool>(), base);
    EXPECT_EQ(c.at("bank_back_end_clocks_per_group").get<long long>(), expect.bank_back_end_clocks);
    EXPECT_EQ(c.at("combiner_clocks_per_group").get<long long>(), expect.combiner_clocks);
    EXPECT_EQ(c.at("detector_clocks_per_group").get<long long>(), expect.detector_clocks);
    EXPECT_EQ(c.at("clocks_per_sample_available").get<long long>(), base ? 6 : 4);
    EXPECT_EQ(c.at("real_time_summary").get<std::string>(), expect.summary());
    const auto& s = p.at("stability");
    EXPECT_TRUE(s.at("stable").get<bool>());
    EXPECT_TRUE(s.at("within_spec").get<bool>());
    EXPECT_LT(s.at("max_quantized_pole_radius").get<double>(), 1.0);
    EXPECT_GT(s.at("max_quantized_pole_radius").get<double>(), 0.5);
  }
}
