// `ranging sweep` with synthesis (label soak: yosys synth_ice40 takes ~20 s of CPU per RTL):
// points of equal generated RTL are synthesized once (DIR/cache), the resources are real
// numbers, and another RTL gets its own synthesis.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/process.hpp"
#include "tests/scratch.hpp"

using nlohmann::json;
using ranging::testing_support::run_tool;
namespace fs = std::filesystem;

TEST(SweepSynth, EqualRtlIsSynthesizedOnceAndResourcesAreReported) {
  const ranging::testing_support::ScratchDir scratch("ranging_sweep_synth");
  const fs::path dir = scratch.path();
  std::ofstream(dir / "scene.yaml") << "transducers: {}\ngeometry:\n  distances_m: [0.5]\nexcitation:\n  family: Gold4\n"
                                       "  codes: [2]\nnoise:\n  noise_v: 0.01\n";
  std::ofstream(dir / "spec.yaml") << "name: synth\nconfig: " << RANGING_SOURCE_DIR
                                   << "/configs/default.yaml\nscene: scene.yaml\nmode: one-at-a-time\naxes:\n"
                                      "  - key: scene.noise.noise_v\n    values: [0.002, 0.02]\n"
                                      "  - key: correlator_fixed.corr_bits\n    values: [14]\n";
  const auto r = run_tool("sweep " + (dir / "spec.yaml").string() + " --out " + (dir / "out").string() + " --no-plot --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const json doc = json::parse(std::ifstream(dir / "out/sweep.json"));
  ASSERT_EQ(doc["points"].size(), 4u);
  std::size_t cached = 0;
  for (const auto& e : fs::directory_iterator(dir / "out/cache")) cached += e.path().extension() == ".json";
  EXPECT_EQ(cached, 2u) << "the base and the two noise points share one RTL; corr_bits 14 is another";
  const json& base = doc["points"][0]["cost"]["ice40"];
  ASSERT_TRUE(base.contains("lut4")) << base.dump();
  EXPECT_GT(base["lut4"].get<int>(), 1000);
  EXPECT_GT(base["mac16"].get<int>(), 0);
  for (int i = 1; i < 3; ++i) EXPECT_EQ(doc["points"][i]["cost"]["ice40"], base);
  EXPECT_NE(doc["points"][3]["cost"]["ice40"]["rtl_hash"], base["rtl_hash"]);
  EXPECT_EQ(doc["cost_for_front"], "lut4");
}

TEST(SweepSynth, EcpAndXilinxEstimatesBesideTheIce40s) {
  const ranging::testing_support::ScratchDir scratch("ranging_sweep_targets");
  const fs::path dir = scratch.path();
  std::ofstream(dir / "scene.yaml") << "transducers: {}\ngeometry:\n  distances_m: [0.5]\nexcitation:\n  family: Gold4\n"
                                       "  codes: [2]\nnoise:\n  noise_v: 0.01\n";
  std::ofstream(dir / "spec.yaml") << "name: targets\nconfig: " << RANGING_SOURCE_DIR
                                   << "/configs/default.yaml\nscene: scene.yaml\nmode: grid\naxes:\n"
                                      "  - key: scene.noise.noise_v\n    values: [0.02]\n";
  const auto r = run_tool("sweep " + (dir / "spec.yaml").string() + " --out " + (dir / "out").string() +
                          " --synth-targets ice40,ecp5,xilinx --jobs 2 --no-plot --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const json doc = json::parse(std::ifstream(dir / "out/sweep.json"));
  const json& c = doc["points"][0]["cost"];
  EXPECT_GT(c["ecp5"]["lut4"].get<int>(), 1000) << c.dump();
  EXPECT_GT(c["ecp5"]["mult18"].get<int>(), 0);
  EXPECT_GT(c["xilinx"]["lut"].get<int>(), 1000);
  EXPECT_GT(c["xilinx"]["dsp48"].get<int>(), 0);
  EXPECT_EQ(doc["points"][1]["cost"]["xilinx"], c["xilinx"]) << "same RTL: one synthesis per target";
  std::ifstream csv(dir / "out/points.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find("ecp5_mult18"), std::string::npos) << header;
  EXPECT_NE(header.find("xilinx_dsp48"), std::string::npos) << header;
}
