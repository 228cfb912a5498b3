// `ranging wordlength` (model/study/wordlength.hpp): the width found meets the tolerance, one bit
// less does not, the written configuration carries it, and a bad spec is refused.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>

#include "model/config/receiver_config.hpp"
#include "model/study/sweep.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"

using nlohmann::json;
using ranging::testing_support::run_tool;
namespace fs = std::filesystem;

TEST(WordLength, TheMinimumPassesOneBitLessFailsAndTheConfigurationCarriesIt) {
  const ranging::testing_support::ScratchDir scratch("ranging_wordlength");
  const fs::path dir = scratch.path();
  std::ofstream(dir / "scene.yaml") << "transducers: {}\ngeometry:\n  distances_m: [0.3, 0.8]\nexcitation:\n"
                                       "  family: Gold4\n  codes: [1, 5, 9]\nnoise:\n  noise_v: 0.01\n  seed: 2\n";
  std::ofstream(dir / "spec.yaml") << "name: wl\nconfig: " << RANGING_SOURCE_DIR << "/configs/default.yaml\n"
                                   << "scene: scene.yaml\ntolerance: {rmse_factor: 1.5, decode_errors: 0}\n"
                                      "nodes: [correlator_fixed.chip_bits]\n";
  const auto r = run_tool("wordlength " + (dir / "spec.yaml").string() + " --out " + (dir / "out").string() + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  const json doc = json::parse(std::ifstream(dir / "out/wordlength.json"));
  const int base = doc["nodes"][0]["base"], min = doc["nodes"][0]["joint"];
  EXPECT_LT(min, base) << "the default's chip_bits has slack at 1.5x its RMSE";
  const double limit = doc["tolerance"]["rmse_limit_m"];
  EXPECT_LE(doc["joint"]["accuracy"]["distance_rmse_m"].get<double>(), limit);
  EXPECT_EQ(doc["joint"]["accuracy"]["decode_errors"], 0);
  EXPECT_EQ(ranging::load_receiver_config((dir / "out/config.yaml").string()).correlator.chip_bits, min);

  // One bit less misses the tolerance (or is refused).
  ranging::study::SweepSpec s;
  s.config_path = std::string(RANGING_SOURCE_DIR) + "/configs/default.yaml";
  s.scene_path = (dir / "scene.yaml").string();
  const ranging::study::Params less{{"correlator_fixed.chip_bits", std::to_string(min - 1)}};
  ranging::study::PointOptions opt;
  opt.synth = false;
  const json p = ranging::study::evaluate_point(s, {ranging::study::point_id(less), less}, opt);
  const bool fails = p["status"] != "ok" || p["accuracy"]["distance_rmse_m"].is_null() ||
                     p["accuracy"]["distance_rmse_m"].get<double>() > limit || p["accuracy"]["decode_errors"] != 0;
  EXPECT_TRUE(fails) << p.dump();

  std::ofstream(dir / "bad.yaml") << "name: wl\nconfig: " << RANGING_SOURCE_DIR << "/configs/default.yaml\n"
                                  << "scene: scene.yaml\nnodes: [correlator_fixed.chip_bitz]\n";
  const auto bad = run_tool("wordlength " + (dir / "bad.yaml").string() + " --out " + (dir / "bad").string());
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(bad.out.empty());
  EXPECT_NE(bad.err.find((dir / "bad.yaml").string() + ":4: nodes"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(dir / "bad"));
}

// --jobs N searches the nodes on N threads: the result is the one thread's (only the points'
// measured speed differs), and the evaluations are counted once each.
TEST(WordLength, SeveralThreadsGiveTheSameResult) {
  const ranging::testing_support::ScratchDir scratch("ranging_wordlength_jobs");
  const fs::path dir = scratch.path();
  std::ofstream(dir / "scene.yaml") << "transducers: {}\ngeometry:\n  distances_m: [0.3, 0.8]\nexcitation:\n"
                                       "  family: Gold4\n  codes: [2, 7]\nnoise:\n  noise_v: 0.01\n  seed: 3\n";
  std::ofstream(dir / "spec.yaml") << "name: wl\nconfig: " << RANGING_SOURCE_DIR << "/configs/default.yaml\n"
                                   << "scene: scene.yaml\ntolerance: {rmse_factor: 1.5, decode_errors: 0}\n"
                                      "nodes: [correlator_fixed.chip_bits, correlator_fixed.tap_bits, "
                                      "correlator_fixed.weight_bits]\n";
  auto strip = [](json j) {
    std::function<void(json&)> drop = [&](json& o) {
      if (o.is_object()) {
        o.erase("speed");
        for (auto& [k, v] : o.items()) drop(v);
      } else if (o.is_array()) {
        for (auto& v : o) drop(v);
      }
    };
    drop(j);
    return j;
  };
  json first;
  for (int jobs : {1, 3}) {
    SCOPED_TRACE(jobs);
    const std::string out = (dir / ("out" + std::to_string(jobs))).string();
    const auto r = run_tool("wordlength " + (dir / "spec.yaml").string() + " --out " + out + " --quiet --jobs " +
                            std::to_string(jobs));
    ASSERT_EQ(r.status, 0) << r.err;
    const json doc = strip(json::parse(std::ifstream(out + "/wordlength.json")));
    int per_node = 0;
    for (const auto& n : doc["nodes"]) per_node += n["evaluations"].get<int>();
    EXPECT_EQ(doc["evaluations"].get<int>(), 1 + per_node + 1 + doc["widenings"].get<int>());
    if (first.is_null()) {
      first = doc;
    } else {
      EXPECT_EQ(doc, first);
    }
  }
}
