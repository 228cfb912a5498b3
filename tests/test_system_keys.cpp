// The `system:` section of the receiver configuration (docs/configuration.md): parsed, validated
// with file:line, key and range, written back by the writer, and used by the generator (the
// system top's PERIOD_T, C_INIT, BAUD_DIV, TIME_W, OFF_W, C_FRAC and the receiver's TIME_W).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "model/base/error.hpp"
#include "model/config/receiver_config.hpp"
#include "model/dsp/codes.hpp"
#include "model/hw/hw_generator.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"

using namespace ranging;

namespace {

std::string error_of(const std::string& yaml) {
  try {
    parse_receiver_config(yaml, "cfg.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SystemKeys, ParsedAndWrittenBack) {
  const ReceiverConfig c = parse_receiver_config(
      "system:\n  speed_of_sound: 343\n  max_range_m: 2.5\n  baud: 1000000\n  calibration_distance_m: 0.2\n"
      "  time_w: 36\n  off_w: 24\n  c_frac: 12\n",
      "cfg.yaml");
  EXPECT_EQ(c.system.speed_of_sound, 343);
  EXPECT_EQ(c.system.max_range_m, 2.5);
  EXPECT_EQ(c.system.baud, 1e6);
  EXPECT_EQ(c.system.calibration_distance_m, 0.2);
  EXPECT_EQ(c.system.time_w, 36);
  EXPECT_EQ(c.system.off_w, 24);
  EXPECT_EQ(c.system.c_frac, 12);
  const std::string text = receiver_config_yaml(c);
  EXPECT_NE(text.find("system:\n  speed_of_sound: 343\n"), std::string::npos) << text;
  const ReceiverConfig back = parse_receiver_config(text, "back.yaml");
  EXPECT_EQ(receiver_config_yaml(back), text);
  EXPECT_EQ(back.system.time_w, 36);
  EXPECT_EQ(back.system.baud, 1e6);
}

TEST(SystemKeys, BadValuesNameFileLineKeyAndRange) {
  struct Case {
    std::string yaml, expect;
  };
  const Case cases[] = {
      {"system:\n  time_w: 64\n", "cfg.yaml:2: system.time_w: 64 is out of range; valid range is [32, 46]"},
      {"system:\n  off_w: 8\n", "cfg.yaml:2: system.off_w"},
      {"name: x\nsystem:\n  c_frac: 30\n", "cfg.yaml:3: system.c_frac"},  // 1..31 - frac_bits (8): 23
      {"system:\n  speed_of_sound: 20\n", "cfg.yaml:2: system.speed_of_sound"},
      {"system:\n  max_range_m: 0\n", "cfg.yaml:2: system.max_range_m"},
      {"system:\n  calibration_distance_m: 11\n", "cfg.yaml:2: system.calibration_distance_m"},
      {"system:\n  bogus: 1\n", "cfg.yaml:2: system.bogus: unknown key"},
      {"system:\n  time_w: 40.5\n", "cfg.yaml:2: system.time_w"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of(c.yaml);
    EXPECT_NE(e.find(c.expect), std::string::npos) << c.yaml << " -> " << e;
  }
  EXPECT_NE(error_of("detector:\n  frac_bits: 16\nsystem:\n  c_frac: 16\n").find("valid range is [1, 15]"),
            std::string::npos);
}

std::string line_with(const std::string& text, const std::string& prefix) {
  const auto at = text.find(prefix);
  if (at == std::string::npos) return "";
  return text.substr(at, text.find('\n', at) - at);
}

TEST(SystemKeys, UsedByTheGenerator) {
  ReceiverConfig c;
  c.system.speed_of_sound = 343;
  c.system.max_range_m = 2.5;  // fs L / (eta c) = 5e6 * 2.5 / (9 * 343) = 4049.2: above 1.5 T_d
  c.system.baud = 1e6;
  c.system.time_w = 36;
  c.system.off_w = 24;
  c.system.c_frac = 12;
  const auto files = generate_hardware_files(design_receiver(c), "test");
  const auto j = nlohmann::json::parse(files.at("system.json"));
  const int eta = code_family(c.family).eta();
  EXPECT_EQ(j["period_t_samples"].get<int>(), static_cast<int>(std::ceil(5e6 * 2.5 / (eta * 343.0))));
  EXPECT_EQ(j["baud_div"].get<int>(), 30);  // 30 MHz / 1 Mbaud
  EXPECT_EQ(j["c_register"].get<std::int64_t>(), std::llround(343.0 / 5e6 * 1e6 * 4096));
  EXPECT_EQ(j["c_frac"].get<int>(), 12);
  const std::string& vc = files.at("rtl/ranging_system.vc");
  EXPECT_EQ(line_with(vc, "-GTIME_W="), "-GTIME_W=32'd36");
  EXPECT_EQ(line_with(vc, "-GOFF_W="), "-GOFF_W=32'd24");
  EXPECT_EQ(line_with(vc, "-GC_FRAC="), "-GC_FRAC=32'd12");
  EXPECT_EQ(line_with(vc, "-GBAUD_DIV="), "-GBAUD_DIV=32'd30");
  // OFFSETS packs eta offsets of off_w bits each.
  EXPECT_EQ(line_with(vc, "-GOFFSETS=").substr(0, 13), "-GOFFSETS=" + std::to_string(eta * 24));
  EXPECT_EQ(line_with(files.at("rtl/correlator_bank.vc"), "-GTIME_W="), "-GTIME_W=36");
  EXPECT_EQ(line_with(files.at("rtl/peak_detector.vc"), "-GTIME_W="), "-GTIME_W=36");
  EXPECT_NE(files.at("rtl/ranging_system_top.v").find(".PERIOD_T(32'd" + std::to_string(j["period_t_samples"].get<int>()) + ")"),
            std::string::npos);
}

// Checks made only when the system is designed are located in the file too.
TEST(SystemKeys, GenerateLocatesSystemDesignErrors) {
  const ranging::testing_support::ScratchDir scratch("system_keys", ::testing::TempDir());
  const std::string dir = scratch.str();
  // holdoff 5000 samples > the burst period of 1 m (1634 samples)
  std::ofstream(dir + "/c.yaml") << "detector:\n  holdoff: 5000\nsystem:\n  max_range_m: 1\n";
  const auto r = ranging::testing_support::run_tool("generate --config " + dir + "/c.yaml --out " + dir + "/gen");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find(dir + "/c.yaml:4: system.max_range_m: the burst period 1634 samples is shorter than"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/gen"));
  // The UART divider clock_hz / baud is the system's: simulate accepts the receiver, generate
  // refuses the system with the key's line.
  std::ofstream(dir + "/b.yaml") << "name: b\nsystem:\n  baud: 1000001\n";
  const auto g = ranging::testing_support::run_tool("generate --config " + dir + "/b.yaml --out " + dir + "/gen");
  EXPECT_EQ(g.status, 2);
  EXPECT_TRUE(g.out.empty()) << g.out;
  EXPECT_NE(g.err.find(dir + "/b.yaml:3: system.baud"), std::string::npos) << g.err;
  EXPECT_FALSE(std::filesystem::exists(dir + "/gen"));
}

}  // namespace
