// `--set KEY=VALUE` overrides (model/config/overrides.hpp): applied to the YAML document before
// the strict parser, so they are validated exactly like the file, and their errors name them.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "model/base/error.hpp"
#include "model/config/overrides.hpp"
#include "model/config/receiver_config.hpp"
#include "model/sim/scene.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"

using namespace ranging;
using testing_support::run_tool;
namespace fs = std::filesystem;

namespace {

const std::string kSource = RANGING_SOURCE_DIR;
const std::string kDefault = kSource + "/configs/default.yaml";

std::string config_error(const std::vector<std::string>& sets) {
  try {
    load_receiver_config(kDefault, parse_overrides(sets));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST(Overrides, SetValuesReachTheConfiguration) {
  const ReceiverConfig base = load_receiver_config(kDefault);
  const ReceiverConfig c = load_receiver_config(
      kDefault, parse_overrides({"correlator_fixed.chip_bits=18", "filter.type=ellip", "filter.order=3",
                                 "correlator.decimation=10", "detector.holdoff=auto"}));
  EXPECT_NE(base.correlator.chip_bits, 18);
  EXPECT_EQ(c.correlator.chip_bits, 18);
  EXPECT_EQ(c.filter_type, FilterType::Elliptic);
  EXPECT_EQ(c.filter_order, 3);
  EXPECT_EQ(c.decimation, 10);
  EXPECT_EQ(c.detector.holdoff, -1);
  // Everything not overridden is the file's.
  EXPECT_EQ(c.bandpass.coef_bits, base.bandpass.coef_bits);
  EXPECT_EQ(c.correlator.lo_bits, base.correlator.lo_bits);
}

TEST(Overrides, TheLastOfEqualKeysWins) {
  const ReceiverConfig c =
      load_receiver_config(kDefault, parse_overrides({"correlator_fixed.chip_bits=18", "correlator_fixed.chip_bits=17"}));
  EXPECT_EQ(c.correlator.chip_bits, 17);
}

TEST(Overrides, ErrorsNameTheOverrideAndTheValidRange) {
  // Out of range in the parser's or in validate()'s check: both name --set, the key, the range.
  for (const std::string& bad : {std::string("correlator_fixed.chip_bits=99"), std::string("correlator.decimation=0")}) {
    const std::string e = config_error({bad});
    EXPECT_NE(e.find("--set " + bad), std::string::npos) << e;
    EXPECT_NE(e.find("valid range is"), std::string::npos) << e;
  }
  const std::string unknown = config_error({"correlator_fixed.chp_bits=3"});
  EXPECT_NE(unknown.find("--set correlator_fixed.chp_bits=3"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("unknown key"), std::string::npos) << unknown;
  const std::string section = config_error({"nosuch.key=1"});
  EXPECT_NE(section.find("--set nosuch.key=1: nosuch: unknown key"), std::string::npos) << section;
  const std::string type = config_error({"filter.type=foo"});
  EXPECT_NE(type.find("valid: butter, cheby1, ellip"), std::string::npos) << type;
  EXPECT_NE(config_error({"filter.order=abc"}).find("'abc' is not an integer"), std::string::npos);
  EXPECT_NE(config_error({"filter.type.x=1"}).find("'filter.type' is not a mapping"), std::string::npos);
  // A file's own error keeps its file:line, not --set.
  try {
    parse_receiver_config("filter:\n  order: 99\n", "cfg.yaml", parse_overrides({"correlator_fixed.chip_bits=18"}));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("cfg.yaml", 0), 0u) << e.what();
  }
  for (const char* malformed : {"chip_bits", "=3", "a.b=", "a..b=1"}) {
    EXPECT_THROW(parse_override(malformed), InputError) << malformed;
  }
}

TEST(Overrides, ScenesTakeTheirOwnAndTheirConfigurationsKeys) {
  const std::string yaml = "geometry:\n  distances_m: [0.5]\nnoise:\n  seed: 3\n";
  const Scene s = parse_scene(yaml, "s.yaml", ".",
                              parse_overrides({"noise.noise_v=0.01", "geometry.distances_m=[0.1, 0.2]",
                                               "receiver.config.correlator_fixed.chip_bits=18"}));
  ASSERT_TRUE(s.noise.noise_v);
  EXPECT_DOUBLE_EQ(*s.noise.noise_v, 0.01);
  EXPECT_EQ(s.geometry.distances_m, (std::vector<double>{0.1, 0.2}));
  EXPECT_EQ(s.noise.seed, 3u);
  EXPECT_EQ(s.receiver.config.correlator.chip_bits, 18);
  // Through a scene that references a configuration file.
  const Scene r = parse_scene("geometry:\n  distances_m: [0.5]\nreceiver:\n  config: configs/large.yaml\n", "s.yaml",
                              kSource, parse_overrides({"receiver.config.detector.min_energy=0.125"}));
  EXPECT_EQ(r.receiver.config.detector.min_energy, 0.125);
  EXPECT_EQ(r.receiver.config.name, load_receiver_config(kSource + "/configs/large.yaml").name);
  try {
    parse_scene(yaml, "s.yaml", ".", parse_overrides({"receiver.config.correlator_fixed.chip_bits=99"}));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--set receiver.config.correlator_fixed.chip_bits=99"), std::string::npos)
        << e.what();
  }
  try {
    parse_scene(yaml, "s.yaml", ".", parse_overrides({"noise.noise_v=-1"}));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--set noise.noise_v=-1: noise.noise_v"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("valid range is [0, 1000]"), std::string::npos) << e.what();
  }
}

// The effective scene and configuration are written next to the results, and re-running them
// reproduces the results exactly.
TEST(Overrides, SimulateWritesTheEffectiveSceneAndItRepeatsTheRun) {
  const testing_support::ScratchDir scratch("ranging_overrides");
  const fs::path a = scratch.path() / "a", b = scratch.path() / "b";
  const auto r1 = run_tool("simulate " + kSource + "/scenes/minimal.yaml --quiet --out " + a.string() +
                           " --set noise.noise_v=0.01 --set receiver.precision=fixed"
                           " --set receiver.config.correlator_fixed.chip_bits=18");
  ASSERT_EQ(r1.status, 0) << r1.err;
  ASSERT_TRUE(fs::exists(a / "scene.yaml"));
  ASSERT_TRUE(fs::exists(a / "config.yaml"));
  EXPECT_EQ(load_receiver_config((a / "config.yaml").string()).correlator.chip_bits, 18);
  const auto r2 = run_tool("simulate " + (a / "scene.yaml").string() + " --quiet --out " + b.string());
  ASSERT_EQ(r2.status, 0) << r2.err;
  EXPECT_EQ(slurp(a / "measurements.csv"), slurp(b / "measurements.csv"));
  // The overrides changed the run (noise and precision): the plain scene gives other numbers.
  const fs::path c = scratch.path() / "c";
  ASSERT_EQ(run_tool("simulate " + kSource + "/scenes/minimal.yaml --quiet --out " + c.string()).status, 0);
  EXPECT_NE(slurp(a / "measurements.csv"), slurp(c / "measurements.csv"));
}

TEST(Overrides, BadSetExitsTwoNamingItAndWritesNothing) {
  const testing_support::ScratchDir scratch("ranging_overrides");
  const fs::path out = scratch.path() / "bad";
  for (const std::string& cmd :
       {"simulate " + kSource + "/scenes/minimal.yaml --out " + out.string() + " --set noise.noise_v=abc",
        "simulate " + kSource + "/scenes/minimal.yaml --out " + out.string() + " --set noise.nosie_v=1",
        "generate --config " + kDefault + " --out " + out.string() + " --set correlator_fixed.chip_bits=99",
        std::string("demo --set correlator_fixed.chip_bits=1 --quiet")}) {
    const auto r = run_tool(cmd);
    EXPECT_EQ(r.status, 2) << cmd;
    EXPECT_TRUE(r.out.empty()) << cmd << ": " << r.out;
    EXPECT_NE(r.err.find("--set"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out)) << cmd;
  }
}

TEST(Overrides, GenerateWritesTheEffectiveConfiguration) {
  const testing_support::ScratchDir scratch("ranging_overrides");
  const fs::path out = scratch.path() / "gen";
  const auto r = run_tool("generate --config " + kDefault + " --out " + out.string() + " --set filter.type=ellip --set filter.order=3");
  ASSERT_EQ(r.status, 0) << r.err;
  const ReceiverConfig c = load_receiver_config((out / "config.yaml").string());
  EXPECT_EQ(c.filter_type, FilterType::Elliptic);
  EXPECT_EQ(c.filter_order, 3);
}
