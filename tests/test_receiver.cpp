// The receiver top (float and fixed), its YAML configuration and the demo, end to end.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <memory>

#include "model/config/receiver_config.hpp"
#include "model/sim/demo.hpp"
#include "model/base/error.hpp"
#include "tests/process.hpp"
#include "model/dsp/receiver.hpp"

using namespace ranging;

namespace {

using ToolRun = testing_support::ProcessResult;
using testing_support::run_tool;

std::string error_of(const std::string& yaml) {
  try {
    parse_receiver_config(yaml, "cfg.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// The acceptance: with the defaults every code of M1, M2 and Gold1-7 decodes correctly
// at 100 to 1000 mm, in both precisions.
class DemoFamily : public ::testing::TestWithParam<const char*> {};

TEST_P(DemoFamily, DecodesEveryCodeAt100To1000mmInBothPrecisions) {
  DemoParams p;
  p.receiver.family = GetParam();
  p.distances_m.clear();
  for (int mm = 100; mm <= 1000; mm += 100) p.distances_m.push_back(mm / 1000.0);
  const auto rows = run_demo(p);
  ASSERT_EQ(rows.size(), p.distances_m.size() * static_cast<std::size_t>(code_family(GetParam()).eta()));
  for (const auto& r : rows) {
    SCOPED_TRACE(std::string(GetParam()) + " code " + std::to_string(r.code) + " at " +
                 std::to_string(r.distance_m) + " m");
    ASSERT_TRUE(r.flt.detected);
    ASSERT_TRUE(r.fix.detected);
    EXPECT_EQ(r.flt.decoded, r.code);
    EXPECT_EQ(r.fix.decoded, r.code);
    EXPECT_EQ(r.pearson_decoded, r.code);
    // 1 mm is 14.7 samples of ToF: both receivers are far inside it.
    EXPECT_LT(std::abs(r.flt.error_m), 1e-3);
    EXPECT_LT(std::abs(r.fix.error_m), 1e-3);
    EXPECT_GT(r.u, 0.0);
    EXPECT_EQ(r.overflows, 0u) << "the default word lengths claim no saturation";
  }
}

INSTANTIATE_TEST_SUITE_P(Paper, DemoFamily,
                         ::testing::Values("M1", "M2", "Gold1", "Gold2", "Gold3", "Gold4", "Gold5",
                                           "Gold6", "Gold7"));

TEST(Receiver, FixedIsDeterministicAndResets) {
  ReceiverConfig cfg;
  cfg.family = "M1";
  const ReceiverDesign d = design_receiver(cfg);
  ReceiverFixed rx(d);
  std::vector<std::int64_t> x(3000);
  for (std::size_t n = 0; n < x.size(); ++n) x[n] = static_cast<std::int64_t>((n * 7919) % 2001) - 1000;
  auto run = [&] {
    std::vector<std::int64_t> out;
    for (auto v : x) {
      rx.execute_raw(v);
      out.push_back(rx.filtered());
      out.push_back(rx.bank().power()[2]);
    }
    return out;
  };
  const auto a = run();
  rx.reset();
  EXPECT_EQ(run(), a);
}

TEST(Receiver, InputQuantizerRoundsHalfUpAndSaturatesCounted) {
  OverflowCounter c;
  EXPECT_EQ(quantize_input(0.0, 12, &c), 0);
  EXPECT_EQ(quantize_input(1.0, 12, &c), 2047);  // saturates
  EXPECT_EQ(quantize_input(-1.0, 12, &c), -2048);
  EXPECT_EQ(c.saturations, 1u);
  EXPECT_EQ(quantize_input(0.5 / 2048, 12, &c), 1);     // half up
  EXPECT_EQ(quantize_input(-0.5 / 2048, 12, &c), 0);    // half up (toward +inf)
  EXPECT_EQ(quantize_input(-0.51 / 2048, 12, &c), -1);
  EXPECT_THROW(quantize_input(std::nan(""), 12, &c), InputError);
}

TEST(ReceiverConfig, YamlRoundTripsAndTheCommittedDefaultIsTheDefault) {
  ReceiverConfig cfg;
  cfg.family = "M2";
  cfg.bandpass.acc_bits = 44;
  cfg.correlator.corr_shift = 12;
  cfg.detector.threshold = 0.3;
  const std::string text = receiver_config_yaml(cfg);
  const ReceiverConfig back = parse_receiver_config(text, "roundtrip");
  EXPECT_EQ(receiver_config_yaml(back), text);
  // configs/default.yaml is the default configuration, written by the model.
  const ReceiverConfig def = load_receiver_config(std::string(RANGING_SOURCE_DIR) + "/configs/default.yaml");
  EXPECT_EQ(receiver_config_yaml(def), receiver_config_yaml(ReceiverConfig{}));
}

TEST(ReceiverConfig, BadFilesNameFileLineAndKey) {
  EXPECT_NE(error_of("family: Gold4\nbogus: 1\n").find("cfg.yaml:2: bogus: unknown key"), std::string::npos)
      << error_of("family: Gold4\nbogus: 1\n");
  EXPECT_NE(error_of("bandpass_fixed:\n  data_bits: sixteen\n").find("cfg.yaml:2: bandpass_fixed.data_bits"),
            std::string::npos);
  EXPECT_NE(error_of("bandpass_fixed:\n  rounding: nearest\n").find("valid: truncate, round-half-up, convergent"),
            std::string::npos);
  EXPECT_NE(error_of("detector:\n  threshold: 1.5\n").find("detector.threshold"), std::string::npos);
  EXPECT_NE(error_of("signal:\n  carrier_hz: 190000\n").find("integer"), std::string::npos);
  EXPECT_NE(error_of("family: Gold9\n").find("Gold9"), std::string::npos);
  EXPECT_NE(error_of("bandpass_fixed:\n  data_bits: 70\n").find("data_bits"), std::string::npos);
  EXPECT_NE(error_of("bandpass_fixed:\n  acc_bits: 20\n").find("acc_bits"), std::string::npos);
  EXPECT_NE(error_of("filter: [1, 2]\n").find("expected a mapping"), std::string::npos);
  EXPECT_NE(error_of("family: [\n").find("YAML syntax error"), std::string::npos);
  EXPECT_NE(error_of("").find("empty"), std::string::npos);
  EXPECT_NE(error_of("architecture: template\n").find("valid: baseband"), std::string::npos);
}

TEST(DemoCli, JsonContractAndBadInput) {
  const ToolRun ok = run_tool("demo --family M1 --distances 0.3 --json");
  ASSERT_EQ(ok.status, 0);
  const auto j = nlohmann::json::parse(ok.out);
  EXPECT_EQ(j["family"], "M1");
  ASSERT_EQ(j["rows"].size(), 7u);
  for (const auto& r : j["rows"]) {
    EXPECT_EQ(r["fixed"]["decoded"], r["code"]);
    EXPECT_NEAR(r["fixed"]["distance_m"].get<double>(), 0.3, 1e-3);
  }
  for (const char* bad : {"demo --family Nope", "demo --distances 0.1,abc", "demo --distances 50",
                          "demo --noise-rms -1", "demo --gain nan", "demo --bogus",
                          "demo --config /nonexistent.yaml"}) {
    const ToolRun r = run_tool(bad);
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_TRUE(r.out.empty()) << bad;
  }
}

TEST(ReceiverConfig, FitDecimationToChipPicksTheLargestDivisor) {
  ReceiverConfig cfg;  // 200 kHz, 5 MS/s: 25 samples per cycle
  cfg.decimation = 20;
  cfg.cycles_per_chip = 2;  // 50 samples per chip: 20 does not divide, 10 is the largest that does
  fit_decimation_to_chip(cfg);
  EXPECT_EQ(cfg.decimation, 10);
  EXPECT_NO_THROW(validate(cfg));
  cfg.cycles_per_chip = 4;  // 100: 10 divides, unchanged
  fit_decimation_to_chip(cfg);
  EXPECT_EQ(cfg.decimation, 10);
  cfg.cycles_per_chip = 1;  // 25: 5
  cfg.decimation = 20;
  fit_decimation_to_chip(cfg);
  EXPECT_EQ(cfg.decimation, 5);
  cfg.cycles_per_chip = 4;
  cfg.decimation = 30;  // 100: 25
  fit_decimation_to_chip(cfg);
  EXPECT_EQ(cfg.decimation, 25);
}

// The demo's rows (distance x code) on several threads: every field identical to one thread's,
// whatever the number of threads (each row has its own seed and slot); the tool's --jobs too.
TEST(Demo, SeveralThreadsGiveTheSameRows) {
  DemoParams p;
  p.distances_m = {0.1, 0.37, 0.8};
  p.noise_rms = 0.02;
  const auto one = run_demo(p);
  for (int jobs : {2, 5}) {
    p.jobs = jobs;
    std::size_t calls = 0;
    const auto many = run_demo(p, [&](std::size_t, std::size_t) { ++calls; });
    ASSERT_EQ(many.size(), one.size());
    EXPECT_EQ(calls, one.size() + 9);  // the 9 calibration bursts, then every row once
    for (std::size_t i = 0; i < one.size(); ++i) {
      const auto &a = one[i], &b = many[i];
      EXPECT_EQ(a.code, b.code);
      EXPECT_EQ(a.distance_m, b.distance_m);
      EXPECT_EQ(a.flt.tof_s, b.flt.tof_s);
      EXPECT_EQ(a.fix.tof_s, b.fix.tof_s);
      EXPECT_EQ(a.fix.score, b.fix.score);
      EXPECT_EQ(a.rho_max, b.rho_max);
      EXPECT_EQ(a.u, b.u);
      EXPECT_EQ(a.energy, b.energy);
      EXPECT_EQ(a.overflows, b.overflows);
    }
  }
  p.jobs = 0;
  EXPECT_THROW(run_demo(p), InputError);
  const auto r1 = run_tool("demo --json --distances 0.2,0.6");
  const auto r2 = run_tool("demo --json --distances 0.2,0.6 --jobs 2");
  ASSERT_EQ(r1.status, 0) << r1.err;
  ASSERT_EQ(r2.status, 0) << r2.err;
  EXPECT_EQ(r1.out, r2.out);
}
