// Decoding captures from transducers unlike the model (issue 14, section 4): an independent
// scipy channel (tests/oracle/foreign_channel.py: TX Q 7, RX Q 9, ISO-like absorption, SNR
// 14-26 dB, c = 347 m/s, Tektronix-like CSV and 16-bit WAV without metadata) writes every code
// of M1 and Gold4; `decode --calibrate` with its calibration train at 0.2 m must name every
// code right and put every distance within 2 mm. Also the exit status: 0 found, 1 nothing.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/process.hpp"
#include "tests/scratch.hpp"

namespace fs = std::filesystem;
using ranging::testing_support::run_command;
using ranging::testing_support::run_tool;

namespace {

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return nlohmann::json::parse(ss.str());
}

class ForeignCaptures : public ::testing::TestWithParam<const char*> {};

}  // namespace

TEST_P(ForeignCaptures, EveryCodeRightAndEveryDistanceWithin2mm) {
  const std::string family = GetParam();
  const ranging::testing_support::ScratchDir scratch("foreign_" + family, ::testing::TempDir());
  const std::string dir = scratch.file("captures");  // made by foreign_channel.py
  const std::string cmd = std::string(RANGING_PYTHON) + " " + RANGING_SOURCE_DIR + "/tests/oracle/foreign_channel.py " +
                          dir + " " + family + " 14";
  const auto gen = run_command(cmd);
  ASSERT_EQ(gen.status, 0) << cmd << "\n" << gen.err;  // no scipy is a failure, not a skip
  const auto truth = read_json(dir + "/truth.json");
  const double c = truth["c"].get<double>();
  ASSERT_NE(c, 340.0);
  const std::string cal = truth["calibration"]["stem"].get<std::string>();
  const double dcal = truth["calibration"]["distance_m"].get<double>();
  int checked = 0;
  for (const auto& t : truth["captures"]) {
    const int code = t["code"].get<int>();
    const double d = t["distance_m"].get<double>();
    for (const char* ext : {".csv", ".wav"}) {
      SCOPED_TRACE(t["stem"].get<std::string>() + ext + " snr " + std::to_string(t["snr_db"].get<double>()));
      char args[512];
      std::snprintf(args, sizeof args, "decode %s%s --family %s --speed-of-sound %.6g --calibrate %s%s --distance %.6g --json",
                    t["stem"].get<std::string>().c_str(), ext, family.c_str(), c, cal.c_str(), ext, dcal);
      const auto r = run_tool(args);
      ASSERT_EQ(r.status, 0) << r.err << r.out;
      const auto j = nlohmann::json::parse(r.out);
      ASSERT_TRUE(j["found"].get<bool>());
      auto best = j["detections"][0];
      for (const auto& x : j["detections"]) {
        if (x["receiver_rho2"].get<double>() > best["receiver_rho2"].get<double>()) best = x;
      }
      EXPECT_EQ(best["code"], code);
      EXPECT_EQ(best["pearson_code"], code);
      EXPECT_NEAR(best["distance_m"].get<double>(), d, 2e-3);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 2 * static_cast<int>(truth["captures"].size()));
}

INSTANTIATE_TEST_SUITE_P(Families, ForeignCaptures, ::testing::Values("M1", "Gold4"));

TEST(DecodeExitStatus, NothingFoundIsOneAndBelowGateBurstsAreListed) {
  const ranging::testing_support::ScratchDir scratch("exit", ::testing::TempDir());
  const std::string dir = scratch.str();
  // Silence: nothing at all -> exit 1, "no burst detected".
  {
    std::ofstream out(dir + "/quiet.csv");
    out << "TIME,CH1\n";
    for (int n = 0; n < 6000; ++n) out << n * 2e-7 << "," << 1e-4 * std::sin(n * 0.7) << "\n";
  }
  const auto q = run_tool("decode " + dir + "/quiet.csv --family M1");
  EXPECT_EQ(q.status, 1) << q.out << q.err;
  EXPECT_NE(q.out.find("no burst"), std::string::npos) << q.out;
  // A real burst with an impossible gate: listed below the gate with its rho, exit 1.
  const std::string gen = std::string(RANGING_PYTHON) + " " + RANGING_SOURCE_DIR + "/tests/oracle/foreign_channel.py " +
                          dir + "/f M1 3";
  ASSERT_EQ(run_command(gen).status, 0);
  const auto g = run_tool("decode " + dir + "/f/M1_j1.csv --family M1 --min-rho 1 --json");
  EXPECT_EQ(g.status, 1) << g.err;
  const auto j = nlohmann::json::parse(g.out);
  EXPECT_FALSE(j["found"].get<bool>());
  EXPECT_TRUE(j["detections"].empty());
  ASSERT_FALSE(j["below_gate"].empty());
  EXPECT_LT(j["below_gate"][0]["rho"].get<double>(), 1.0);
  const auto t = run_tool("decode " + dir + "/f/M1_j1.csv --family M1 --min-rho 1");
  EXPECT_EQ(t.status, 1);
  EXPECT_NE(t.out.find("below the gate"), std::string::npos) << t.out;
}
