// `ranging sweep` (model/study/sweep.hpp): shards merged equal the serial run, --jobs does not
// change the output, a re-run keeps the points done, point results do not depend on the order
// of the axes or values, bad specs are refused naming file:line and key, and a GNU parallel run
// over shards merges to the serial result.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>
#include <vector>

#include "model/config/overrides.hpp"
#include "model/sim/scene.hpp"
#include "model/study/sweep.hpp"

#include "tests/process.hpp"

using nlohmann::json;
using ranging::testing_support::run_command;
using ranging::testing_support::run_tool;
namespace fs = std::filesystem;

namespace {

const std::string kSource = RANGING_SOURCE_DIR;

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

class Sweep : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("ranging_sweep_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    std::ofstream(dir_ / "scene.yaml") << "name: tiny\ntransducers: {}\ngeometry:\n  distances_m: [0.3, 0.8]\n"
                                          "excitation:\n  family: Gold4\n  codes: [1, 5, 9]\n"
                                          "noise:\n  noise_v: 0.01\n  seed: 4\n";
  }
  void TearDown() override { fs::remove_all(dir_); }

  // A spec in dir_ (config and scene relative to it).
  fs::path spec(const std::string& name, const std::string& axes, const std::string& extra = "mode: grid\n") {
    const fs::path p = dir_ / (name + ".yaml");
    std::ofstream(p) << "name: tiny\nconfig: " << kSource << "/configs/default.yaml\nscene: scene.yaml\n"
                     << extra << "axes:\n"
                     << axes;
    return p;
  }
  static std::string grid_axes() {
    return "  - key: correlator_fixed.chip_bits\n    values: [14, 22]\n"
           "  - key: bandpass_fixed.coef_bits\n    range: {from: 10, to: 16, step: 6}\n";
  }
  fs::path run(const fs::path& spec_file, const std::string& out, const std::string& opts = "") {
    const auto r = run_tool("sweep " + spec_file.string() + " --out " + (dir_ / out).string() +
                            " --no-synth --no-plot --quiet " + opts);
    EXPECT_EQ(r.status, 0) << r.err;
    return dir_ / out;
  }
  // sweep.json without the measured speed (the only field that may differ between runs).
  static json result(const fs::path& d) {
    json j = json::parse(slurp(d / "sweep.json"));
    for (auto& p : j["points"]) p.erase("speed");
    return j;
  }
  fs::path dir_;
};

}  // namespace

TEST_F(Sweep, ShardsMergedAndParallelJobsEqualTheSerialRun) {
  const fs::path s = spec("grid", grid_axes());
  const fs::path serial = run(s, "serial");
  const json ref = result(serial);
  ASSERT_EQ(ref["points"].size(), 5u);  // the base and 2 x 2
  std::size_t ok = 0, refused = 0;
  for (const auto& p : ref["points"]) (p["status"] == "ok" ? ok : refused)++;
  EXPECT_GT(ok, 0u);
  EXPECT_GT(refused, 0u) << "coef_bits 10 with the default's 14 fraction bits does not fit: a recorded refusal";
  for (const auto& p : ref["points"]) {
    if (p["status"] == "refused") {
      EXPECT_NE(p["error"].get<std::string>().find("does not fit"), std::string::npos);
    }
  }

  std::string dirs;
  std::size_t in_shards = 0;
  for (int i = 0; i < 3; ++i) {
    const fs::path d = run(s, "shard" + std::to_string(i), "--shard " + std::to_string(i) + "/3");
    in_shards += result(d)["points"].size();
    dirs += " " + d.string();
  }
  EXPECT_EQ(in_shards, ref["points"].size());
  const auto m = run_tool("sweep merge --no-plot --out " + (dir_ / "merged").string() + dirs);
  ASSERT_EQ(m.status, 0) << m.err;
  EXPECT_EQ(result(dir_ / "merged"), ref);
  EXPECT_EQ(slurp(dir_ / "merged/points.csv"), slurp(serial / "points.csv"));

  const fs::path par = run(s, "jobs2", "--jobs 2");
  EXPECT_EQ(result(par), ref);
  EXPECT_EQ(slurp(par / "points.csv"), slurp(serial / "points.csv"));

  // Overlapping shards and shards of another spec are refused.
  const auto overlap = run_tool("sweep merge --no-plot --out " + (dir_ / "bad").string() + dirs + " " +
                                (dir_ / "shard0").string());
  EXPECT_EQ(overlap.status, 2);
  EXPECT_NE(overlap.err.find("overlap"), std::string::npos) << overlap.err;
  const fs::path other = run(spec("other", "  - key: correlator_fixed.chip_bits\n    values: [18]\n"), "other");
  const auto mixed = run_tool("sweep merge --no-plot --out " + (dir_ / "bad").string() + " " + (dir_ / "shard0").string() +
                              " " + other.string());
  EXPECT_EQ(mixed.status, 2);
  EXPECT_NE(mixed.err.find("different specs"), std::string::npos) << mixed.err;
  EXPECT_FALSE(fs::exists(dir_ / "bad"));
}

// A scene whose sample rate does not divide a point's clock: the scene alone would move the
// receiver's clock (a warning), but a sweep point keeps the clock it asks for, so that point is
// a recorded refusal naming the clock; a clock that is a multiple is evaluated at that clock.
TEST_F(Sweep, APointWhoseClockIsNotAMultipleOfTheSampleRateIsRefused) {
  std::ofstream(dir_ / "scene.yaml") << "name: tiny4\nsample_rate: 4000000\ntransducers: {}\n"
                                        "geometry:\n  distances_m: [0.3]\nexcitation:\n  family: Gold4\n  codes: [1, 5]\n";
  const fs::path s = spec("clk", "  - key: hardware.clock_hz\n    values: [30000000, 40000000]\n");
  const json j = result(run(s, "out"));
  std::size_t refused = 0, evaluated = 0;
  for (const auto& p : j["points"]) {
    const bool asks_30 = !p["params"].contains("hardware.clock_hz") || p["params"]["hardware.clock_hz"] == "30000000";
    if (asks_30) {
      ++refused;
      EXPECT_EQ(p["status"], "refused") << p.dump();
      EXPECT_NE(p.value("error", "").find("hardware.clock_hz: 30000000 is not a multiple of the scene's sample_rate"),
                std::string::npos)
          << p.dump();
    } else {
      ++evaluated;
      EXPECT_EQ(p["status"], "ok") << p.dump();
      EXPECT_EQ(p["cost"]["clocks_per_sample_available"], 10) << p.dump();
    }
  }
  EXPECT_EQ(refused, 2u);  // the base and the 30 MHz point
  EXPECT_EQ(evaluated, 1u);
}

TEST_F(Sweep, AReRunKeepsThePointsDoneAndRunsTheRest) {
  const fs::path s = spec("grid", grid_axes());
  const fs::path d = run(s, "out");
  const json ref = result(d);
  // Mark one finished point and remove another: the re-run keeps the first (not recomputed)
  // and computes the second again, to the same result.
  const std::string kept = ref["points"][1]["id"], lost = ref["points"][2]["id"];
  json k = json::parse(slurp(d / "points" / (kept + ".json")));
  k["marker"] = "kept";
  std::ofstream(d / "points" / (kept + ".json")) << k.dump();
  fs::remove(d / "points" / (lost + ".json"));
  run(s, "out");
  json again = result(d);
  EXPECT_EQ(again["points"][1]["marker"], "kept");
  again["points"][1].erase("marker");
  EXPECT_EQ(again, ref);
  EXPECT_TRUE(fs::exists(d / "points" / (lost + ".json")));
  // Another spec in the same DIR is refused.
  const auto r = run_tool("sweep " + spec("other", "  - key: correlator_fixed.chip_bits\n    values: [18]\n").string() +
                          " --out " + d.string() + " --no-synth --no-plot --quiet");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("another sweep"), std::string::npos) << r.err;
}

TEST_F(Sweep, PointResultsDoNotDependOnOrder) {
  const json a = result(run(spec("a", grid_axes()), "a"));
  const json b = result(run(spec("b", "  - key: bandpass_fixed.coef_bits\n    values: [16, 10]\n"
                                      "  - key: correlator_fixed.chip_bits\n    values: [22, 14]\n"),
                            "b"));
  auto by_params = [](const json& doc) {
    std::map<std::map<std::string, std::string>, json> m;
    for (const auto& p : doc["points"]) {
      json q = p;
      q.erase("params");
      m[p["params"].get<std::map<std::string, std::string>>()] = q;
    }
    return m;
  };
  const auto ma = by_params(a), mb = by_params(b);
  ASSERT_EQ(ma.size(), mb.size());
  for (const auto& [params, point] : ma) {
    ASSERT_TRUE(mb.count(params));
    EXPECT_EQ(point, mb.at(params));
  }
  // ... and the base point equals a plain `simulate` of the scene in the fixed model.
  const auto sim = run_tool("simulate " + (dir_ / "scene.yaml").string() + " --precision fixed --json --out " +
                            (dir_ / "sim").string() + " --set receiver.config=" + kSource + "/configs/default.yaml");
  ASSERT_EQ(sim.status, 0) << sim.err;
  const json summary = json::parse(sim.out);
  const json& base = a["points"][0];
  ASSERT_TRUE(base["default"].get<bool>());
  EXPECT_EQ(base["accuracy"]["measurements"], summary["measurements"]);
  EXPECT_DOUBLE_EQ(base["accuracy"]["distance_rmse_m"].get<double>(),
                   summary["families"][0]["distance_rmse_m"].get<double>());
}

TEST_F(Sweep, BadSpecsExitTwoNamingFileLineAndKeyAndWriteNothing) {
  struct Case {
    std::string axes, extra, what;
    int line;
  };
  const std::vector<Case> cases = {
      {"  - key: correlator_fixed.chp_bits\n    values: [14]\n", "mode: grid\n", "unknown key", 7},
      {"  - key: correlator_fixed.chip_bits\n    values: [14, 99]\n", "mode: grid\n", "valid range is", 7},
      {"  - key: correlator_fixed.chip_bits\n    values: []\n", "mode: grid\n", "empty axis", 7},
      {"  - key: correlator_fixed.chip_bits\n    values: [14]\n  - key: correlator_fixed.chip_bits\n    values: [18]\n",
       "mode: grid\n", "duplicate axis", 8},
      {"  - key: scene.noise.noise_v\n    values: [-1]\n", "mode: grid\n", "valid range is", 7},
      {"  - key: correlator_fixed.chip_bits\n    values: [14]\n", "mode: grid\nbogus: 1\n", "bogus: unknown key", 5},
      {"  - key: correlator_fixed.chip_bits\n    values: [14]\n", "mode: random\n", "random needs points", 4},
  };
  for (const auto& c : cases) {
    const fs::path s = spec("bad", c.axes, c.extra);
    const auto r = run_tool("sweep " + s.string() + " --out " + (dir_ / "out").string() + " --no-synth --no-plot");
    SCOPED_TRACE(c.axes + c.extra);
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_NE(r.err.find(s.string() + ":" + std::to_string(c.line) + ":"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(c.what), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out"));
  }
  const auto shard = run_tool("sweep " + spec("ok", grid_axes()).string() + " --out " + (dir_ / "out").string() +
                              " --shard 3/3 --no-synth");
  EXPECT_EQ(shard.status, 2);
  EXPECT_NE(shard.err.find("--shard"), std::string::npos) << shard.err;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
  for (const char* targets : {"ice40,vivado", "ecp5,ecp5", ""}) {
    const auto t = run_tool("sweep " + spec("ok", grid_axes()).string() + " --out " + (dir_ / "out").string() +
                            " --synth-targets '" + targets + "' --no-plot");
    SCOPED_TRACE(targets);
    EXPECT_EQ(t.status, 2);
    EXPECT_TRUE(t.out.empty()) << t.out;
    EXPECT_NE(t.err.find("option --synth-targets"), std::string::npos) << t.err;
    EXPECT_FALSE(fs::exists(dir_ / "out"));
  }
}

// A referenced file whose name the file system refuses (longer than NAME_MAX) is a bad input, not a crash
// (found by fuzz_sweep_spec: std::filesystem::exists threw filesystem_error and the tool terminated).
TEST_F(Sweep, ANameTooLongForTheFileSystemExitsTwoNamingTheKey) {
  const fs::path s = dir_ / "long.yaml";
  std::ofstream(s) << "name: tiny\nconfig: " << std::string(5000, 'c') << ".yaml\nscene: scene.yaml\n"
                   << "mode: grid\naxes:\n  - key: correlator_fixed.chip_bits\n    values: [14]\n";
  const auto r = run_tool("sweep " + s.string() + " --out " + (dir_ / "out").string() + " --no-synth --no-plot");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find(s.string() + ":2: config"), std::string::npos) << r.err.substr(0, 300);
  EXPECT_NE(r.err.find("does not exist (File name too long)"), std::string::npos) << r.err.substr(0, 300);
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

// The recipe of docs/design-space.md: GNU parallel runs the shards, `sweep merge` joins them.
TEST_F(Sweep, GnuParallelShardsMergeToTheSerialRun) {
  const fs::path s = spec("grid", grid_axes());
  const json ref = result(run(s, "serial"));
  const std::string cmd = "parallel --halt now,fail=1 -j 2 '" + std::string(RANGING_TOOL) + "' sweep " + s.string() +
                          " --out " + (dir_ / "p").string() + "{} --shard {}/3 --no-synth --no-plot --quiet ::: 0 1 2";
  const auto r = run_command(cmd);
  ASSERT_EQ(r.status, 0) << cmd << "\n" << r.err;
  const auto m = run_tool("sweep merge --no-plot --out " + (dir_ / "merged").string() + " " + (dir_ / "p0").string() + " " +
                          (dir_ / "p1").string() + " " + (dir_ / "p2").string());
  ASSERT_EQ(m.status, 0) << m.err;
  EXPECT_EQ(result(dir_ / "merged"), ref);
}

// The float-reference cache (model/study/sweep.hpp): points that differ only in what the float
// model does not read (word lengths, detector.frac_bits, the clock, system keys) share one float
// run; a key the float model reads is a different entry. The points' results are the same with
// and without the cache, on one thread and on two.
TEST_F(Sweep, FloatReferenceCacheSharesOnlyWhatTheFloatModelIgnores) {
  namespace st = ranging::study;
  const std::string cfg = kSource + "/configs/default.yaml";
  auto scene_with = [&](const ranging::Overrides& ov) {
    ranging::Overrides all;
    for (const auto& [k, v] : ov) all.push_back({k.rfind("scene.", 0) == 0 ? k.substr(6) : "receiver.config." + k, v});
    std::ofstream(dir_ / "s2.yaml") << slurp(dir_ / "scene.yaml") << "receiver:\n  config: " << cfg << "\n";
    return ranging::load_scene((dir_ / "s2.yaml").string(), all);
  };
  const std::string base = st::float_reference_key(scene_with({}));
  for (const auto& [k, v] : std::vector<std::pair<std::string, std::string>>{
           {"bandpass_fixed.coef_bits", "18"}, {"correlator_fixed.chip_bits", "18"}, {"detector.frac_bits", "6"},
           {"hardware.clock_hz", "60000000"}, {"system.time_w", "32"}, {"name", "other"}}) {
    EXPECT_EQ(st::float_reference_key(scene_with({{k, v}})), base) << k << " is ignored by the float model";
  }
  for (const auto& [k, v] : std::vector<std::pair<std::string, std::string>>{
           {"detector.threshold", "0.45"}, {"correlator.decimation", "10"}, {"correlator.template_floor", "0.2"},
           {"filter.type", "cheby1"}, {"scene.noise.seed", "5"}, {"scene.geometry.distances_m", "[0.3, 0.9]"}}) {
    EXPECT_NE(st::float_reference_key(scene_with({{k, v}})), base) << k << " is read by the float model";
  }

  const fs::path s = spec("cache", "  - key: correlator_fixed.chip_bits\n    values: [16, 22]\n"
                                   "  - key: detector.threshold\n    values: [0.5, 0.45]\n");
  const st::SweepSpec sp = st::load_sweep_spec(s.string());
  const auto points = st::sweep_points(sp);
  ASSERT_EQ(points.size(), 5u);  // the base and the 2 x 2 grid
  auto strip = [](json j) {
    j.erase("speed");
    return j;
  };
  st::PointOptions plain;
  plain.synth = false;
  std::vector<json> want;
  for (const auto& p : points) want.push_back(strip(st::evaluate_point(sp, p, plain)));
  for (int threads : {1, 2}) {
    SCOPED_TRACE(threads);
    st::PointOptions cached = plain;
    cached.float_cache = std::make_shared<st::FloatReferenceCache>();
    std::vector<json> got(points.size());
    std::vector<std::thread> pool;
    for (int t = 0; t < threads; ++t) {
      pool.emplace_back([&, t] {
        for (std::size_t i = static_cast<std::size_t>(t); i < points.size(); i += static_cast<std::size_t>(threads)) {
          got[i] = st::evaluate_point(sp, points[i], cached);
        }
      });
    }
    for (auto& th : pool) th.join();
    std::size_t shared = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      ASSERT_EQ(got[i]["status"], "ok") << got[i].dump();
      shared += got[i]["speed"]["float_reference"] == "shared";
      EXPECT_EQ(strip(got[i]), want[i]) << points[i].id;
    }
    // two thresholds (0.5 is the base's): two float runs, three points share them
    EXPECT_EQ(cached.float_cache->misses(), 2u);
    EXPECT_EQ(cached.float_cache->hits(), 3u);
    EXPECT_EQ(shared, 3u);
  }
}
