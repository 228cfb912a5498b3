// `ranging generate`: parameters come only from the model; bad configurations are refused
// with the key named and nothing written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "model/config/receiver_config.hpp"
#include "model/sim/demo.hpp"
#include "model/base/error.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"
#include "model/hw/hw_generator.hpp"
#include "model/hw/hw_params.hpp"

using namespace ranging;
namespace fs = std::filesystem;

namespace {

using ToolRun = testing_support::ProcessResult;
using testing_support::run_tool;

// Every test's files in one directory, removed at exit.
const fs::path& scratch_dir() {
  static const testing_support::ScratchDir d("ranging_gen");
  return d.path();
}

fs::path temp_dir(const std::string& name) {
  const fs::path p = scratch_dir() / ("gen_" + name);
  fs::remove_all(p);
  return p;
}

fs::path write_config(const std::string& name, const std::string& text) {
  const fs::path p = scratch_dir() / ("cfg_" + name + ".yaml");
  std::ofstream(p) << text;
  return p;
}

}  // namespace

TEST(Generate, VerilogPackedPlacesElementIAtBitsIW) {
  EXPECT_EQ(verilog_packed({1, 2, 3}, 4), "12'h321");
  EXPECT_EQ(verilog_packed({-1, 0}, 4), "8'h0f");
  EXPECT_EQ(verilog_packed({-2}, 3), "3'h6");
  EXPECT_EQ(verilog_packed({1, 0, 1, 1}, 1), "4'hd");
}

TEST(Generate, ParametersComeFromTheModel) {
  const ReceiverDesign d = design_receiver(load_receiver_config(std::string(RANGING_SOURCE_DIR) + "/configs/default.yaml"));
  const auto mods = hardware_parameters(d);
  ASSERT_EQ(mods.size(), 3u);
  const BandpassFixed bp(d.filter, d.config.bandpass);
  const auto& sos = mods[0];
  EXPECT_EQ(sos.module, "bandpass_sos");
  EXPECT_EQ(sos.value("SECTIONS"), static_cast<std::int64_t>(bp.coefficients().size()));
  EXPECT_EQ(sos.at("COEFS").elements[3], bp.coefficients()[0][3]);  // section 1 a1
  const auto& bank = mods[1];
  EXPECT_EQ(bank.value("TAPS"), d.layout.taps);
  EXPECT_EQ(bank.at("WEIGHTS").elements, d.layout.weights);
  EXPECT_EQ(bank.at("TAP_VALUES").elements, d.layout.taps_q);
  EXPECT_EQ(bank.value("CHIP_SHIFT"), d.layout.chip_shift);
  const auto& det = mods[2];
  const PeakDetectorFixed pd(d.config.detector, d.layout, d.config.correlator);
  EXPECT_EQ(det.value("HOLDOFF"), pd.holdoff());
  EXPECT_EQ(det.at("THRESHOLD").elements[0], static_cast<std::int64_t>(pd.threshold_q()));
}

TEST(Generate, WritesEveryFileAndTheTopInstantiatesEveryModule) {
  const fs::path out = temp_dir("ok");
  const ToolRun r = run_tool("generate --config " + std::string(RANGING_SOURCE_DIR) +
                             "/configs/default.yaml --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* f : {"rtl/receiver_top.v", "rtl/bandpass_sos.vc", "rtl/correlator_bank.vc",
                        "rtl/peak_detector.vc", "hls/receiver_config.hpp", "receiver.gtkw", "manifest.json"}) {
    EXPECT_TRUE(fs::exists(out / f)) << f;
  }
  std::ifstream top(out / "rtl/receiver_top.v");
  std::stringstream ss;
  ss << top.rdbuf();
  for (const char* inst : {"bandpass_sos #(", "correlator_bank #(", "peak_detector #(", "Do not edit by hand"}) {
    EXPECT_NE(ss.str().find(inst), std::string::npos) << inst;
  }
  fs::remove_all(out);
}

TEST(Generate, ImpossibleConfigurationsAreRefusedAndNothingIsWritten) {
  struct Case {
    const char* yaml;
    const char* key;
  } cases[] = {
      {"bandpass_fixed:\n  acc_bits: 24\n", "acc_bits"},
      {"bandpass_fixed:\n  coef_bits: 8\n  coef_frac: 7\n", "section"},  // a1 ~ -1.9 does not fit Q1.7
      {"family: mseq-7\n", "family"},                                     // 127 chips: beyond the hardware
      {"correlator_fixed:\n  mix_bits: 40\n", "mix_bits"},
      {"correlator:\n  decimation: 7\n", "decimation"},
  };
  for (const auto& c : cases) {
    const fs::path cfg = write_config("bad", c.yaml);
    const fs::path out = temp_dir("bad");
    const ToolRun r = run_tool("generate --config " + cfg.string() + " --out " + out.string());
    EXPECT_EQ(r.status, 2) << c.yaml;
    EXPECT_NE(r.err.find(c.key), std::string::npos) << c.yaml << " -> " << r.err;
    EXPECT_FALSE(fs::exists(out)) << "nothing may be written for " << c.yaml;
    for (const auto& e : fs::directory_iterator(out.parent_path())) {
      EXPECT_EQ(e.path().filename().string().rfind(".tmp-" + out.filename().string(), 0), std::string::npos)
          << "temporary folder left behind: " << e.path();
    }
    fs::remove(cfg);
  }
}

TEST(Generate, AFailedRunLeavesAPreviousOutputUntouched) {
  const fs::path out = temp_dir("keep");
  fs::create_directories(out);
  std::ofstream(out / "marker") << "old";
  const fs::path cfg = write_config("bad2", "bandpass_fixed:\n  acc_bits: 24\n");
  const ToolRun r = run_tool("generate --config " + cfg.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(fs::exists(out / "marker"));
  fs::remove_all(out);
  fs::remove(cfg);
}

// The committed generated/<config>/ is exactly what the generator writes for configs/<config>.yaml:
// generated files are never edited by hand.
class CommittedGenerated : public ::testing::TestWithParam<const char*> {};

TEST_P(CommittedGenerated, IsUpToDate) {
  const std::string name = GetParam();
  const fs::path out = temp_dir("committed_" + name);
  const fs::path committed = fs::path(RANGING_SOURCE_DIR) / "generated" / name;
  const ToolRun r = run_tool("generate --config " + std::string(RANGING_SOURCE_DIR) + "/configs/" + name +
                             ".yaml --out " + out.string() + " --origin configs/" + name + ".yaml --no-sources");
  ASSERT_EQ(r.status, 0) << r.err;
  auto files = [](const fs::path& root) {
    std::map<std::string, std::string> m;
    for (const auto& e : fs::recursive_directory_iterator(root)) {
      if (!e.is_regular_file()) continue;
      std::ifstream f(e.path(), std::ios::binary);
      std::stringstream ss;
      ss << f.rdbuf();
      m[fs::relative(e.path(), root).string()] = ss.str();
    }
    return m;
  };
  const auto fresh = files(out), old = files(committed);
  const std::string where = "generated/" + name + "/";
  for (const auto& [file, text] : fresh) {
    ASSERT_TRUE(old.count(file)) << where << file << " is missing: regenerate";
    EXPECT_EQ(old.at(file), text) << where << file
                                  << " differs from the generator's output: regenerate, never edit by hand";
  }
  for (const auto& [file, text] : old) {
    EXPECT_TRUE(fresh.count(file)) << where << file << " is not generated any more";
  }
  fs::remove_all(out);
}

INSTANTIATE_TEST_SUITE_P(Configs, CommittedGenerated, ::testing::Values("default", "large"));

// The large configuration (full rate, long received template) decodes every code too.
TEST(Generate, LargeConfigurationDecodes) {
  DemoParams p;
  p.receiver = load_receiver_config(std::string(RANGING_SOURCE_DIR) + "/configs/large.yaml");
  p.distances_m = {0.2, 0.9};
  const auto rows = run_demo(p);
  ASSERT_EQ(rows.size(), 18u);
  for (const auto& r : rows) {
    EXPECT_EQ(r.fix.decoded, r.code);
    EXPECT_EQ(r.flt.decoded, r.code);
    EXPECT_LT(std::abs(r.fix.error_m), 1e-3);
  }
  const auto mods = hardware_parameters(design_receiver(p.receiver));
  EXPECT_EQ(mods[1].value("DECIM"), 1);
  EXPECT_GT(mods[1].value("TAPS"), 400);
}
