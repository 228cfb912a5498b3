// `ranging generate` writes a self-contained IP folder: a configuration that is not committed
// (other word lengths, another family, a name FuseSoC must sanitize) lints with Verilator -Wall,
// compiles with Icarus and elaborates in yosys from its own files.f alone, the system filelist
// lints, the FuseSoC CAPI2 core names only files that exist, and --rtl takes the sources from
// another folder.
#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "tests/process.hpp"

namespace fs = std::filesystem;
using ranging::testing_support::run_command;
using ranging::testing_support::run_tool;

namespace {

std::string read(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Not a committed configuration: wider filter and bank words, narrower scores, Gold2.
constexpr const char* kConfig =
    "name: narrow-18\nfamily: Gold2\n"
    "bandpass_fixed:\n  coef_bits: 18\n  coef_frac: 16\n  data_bits: 18\n  data_frac: 16\n"
    "correlator_fixed:\n  chip_bits: 22\n  corr_bits: 18\n  score_bits: 14\n";

class IpFolder : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = fs::temp_directory_path() / ("ranging_ip_" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    std::ofstream(root_ / "narrow.yaml") << kConfig;
    const auto r = run_tool("generate --config " + (root_ / "narrow.yaml").string() + " --out " + (root_ / "ip").string());
    ASSERT_EQ(r.status, 0) << r.err;
  }
  static void TearDownTestSuite() { fs::remove_all(root_); }
  static fs::path ip() { return root_ / "ip"; }
  // Runs a command inside the IP folder (filelists are relative to it).
  static ranging::testing_support::ProcessResult in_ip(const std::string& cmd) {
    return run_command("cd '" + ip().string() + "' && " + cmd);
  }
  static fs::path root_;
};
fs::path IpFolder::root_;

}  // namespace

TEST_F(IpFolder, HoldsEverySourceItsFilelistsName) {
  for (const char* f : {"files.f", "system.f", "README.md", "receiver_narrow_18.core", "receiver.gtkw",
                        "manifest.json", "hls/receiver_config.hpp", "hls/receiver_hls.hpp"}) {
    EXPECT_TRUE(fs::exists(ip() / f)) << f;
  }
  for (const char* list : {"files.f", "system.f"}) {
    std::istringstream ls(read(ip() / list));
    int n = 0;
    for (std::string line; std::getline(ls, line); ++n) {
      EXPECT_TRUE(fs::exists(ip() / line)) << list << ": " << line;
      EXPECT_EQ(line.rfind('/', 0), std::string::npos) << list << ": paths are relative to the folder: " << line;
    }
    EXPECT_GE(n, 4) << list;
  }
  // The configuration's own widths reached the top (DATA_W 18 instead of the default 16).
  EXPECT_NE(read(ip() / "rtl/receiver_top.v").find(".DATA_W(32'd18)"), std::string::npos);
  EXPECT_EQ(read(ip() / "rtl/correlator_bank.v"), read(fs::path(RANGING_SOURCE_DIR) / "rtl/correlator_bank.v"));
}

TEST_F(IpFolder, FilelistLintsWithVerilatorWall) {
  for (const char* list : {"files.f", "system.f"}) {
    const auto r = in_ip(std::string("verilator --lint-only -Wall -f ") + list);
    EXPECT_EQ(r.status, 0) << list << "\n" << r.out << r.err;
    EXPECT_EQ(r.out + r.err, "") << list;
  }
}

TEST_F(IpFolder, FilelistCompilesWithIcarus) {
  const auto r = in_ip("iverilog -g2012 -c files.f -s receiver_top -o receiver.vvp");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(fs::exists(ip() / "receiver.vvp"));
  fs::remove(ip() / "receiver.vvp");
}

TEST_F(IpFolder, FilelistElaboratesInYosys) {
  const auto r = in_ip("yosys -q -p \"read_verilog $(tr '\\n' ' ' < files.f); hierarchy -check -top receiver_top\"");
  EXPECT_EQ(r.status, 0) << r.out << r.err;
}

TEST_F(IpFolder, FuseSocCoreIsCapi2AndNamesExistingFiles) {
  const std::string text = read(ip() / "receiver_narrow_18.core");
  ASSERT_EQ(text.rfind("CAPI=2:\n", 0), 0u) << "a CAPI2 core starts with CAPI=2:";
  const YAML::Node core = YAML::Load(text);
  // VLNV: vendor:library:name:version, name without characters FuseSoC refuses.
  const auto name = core["name"].as<std::string>();
  EXPECT_EQ(std::count(name.begin(), name.end(), ':'), 3) << name;
  EXPECT_EQ(name.rfind("ranging:ip:receiver_narrow_18:", 0), 0u) << name;
  ASSERT_TRUE(core["filesets"].IsMap());
  std::set<std::string> filesets, listed;
  for (const auto& fsn : core["filesets"]) {
    filesets.insert(fsn.first.as<std::string>());
    ASSERT_TRUE(fsn.second["file_type"]) << fsn.first.as<std::string>();
    ASSERT_TRUE(fsn.second["files"].IsSequence());
    for (const auto& f : fsn.second["files"]) {
      const std::string path = f.IsMap() ? f.begin()->first.as<std::string>() : f.as<std::string>();
      EXPECT_TRUE(fs::exists(ip() / path)) << path;
      listed.insert(path);
    }
  }
  // Every source of files.f is in the core.
  std::istringstream ls(read(ip() / "files.f"));
  for (std::string line; std::getline(ls, line);) EXPECT_TRUE(listed.count(line)) << line;
  ASSERT_TRUE(core["targets"]["default"]);
  ASSERT_TRUE(core["targets"]["lint"]);
  for (const auto& t : core["targets"]) {
    const auto tname = t.first.as<std::string>();
    ASSERT_TRUE(t.second["toplevel"]) << tname;
    ASSERT_TRUE(t.second["filesets"].IsSequence()) << tname;
    for (const auto& s : t.second["filesets"]) EXPECT_TRUE(filesets.count(s.as<std::string>())) << tname << ": " << s;
  }
  EXPECT_EQ(core["targets"]["default"]["toplevel"].as<std::string>(), "receiver_top");
  EXPECT_EQ(core["targets"]["lint"]["tools"]["verilator"]["mode"].as<std::string>(), "lint-only");
}

TEST_F(IpFolder, RtlOptionTakesTheSourcesFromAnotherFolderAndAMissingOneIsRefused) {
  const fs::path mine = root_ / "myrtl";
  fs::create_directories(mine);
  for (const auto& e : fs::directory_iterator(fs::path(RANGING_SOURCE_DIR) / "rtl")) fs::copy(e.path(), mine / e.path().filename());
  std::ofstream(mine / "peak_detector.v", std::ios::app) << "// my change\n";
  const fs::path cfg = root_ / "narrow.yaml";
  auto r = run_tool("generate --config " + cfg.string() + " --rtl " + mine.string() + " --out " + (root_ / "ip2").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(read(root_ / "ip2/rtl/peak_detector.v").find("// my change"), std::string::npos);
  fs::remove(mine / "tof_distance.v");
  r = run_tool("generate --config " + cfg.string() + " --rtl " + mine.string() + " --out " + (root_ / "ip3").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--rtl"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("tof_distance.v"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_FALSE(fs::exists(root_ / "ip3"));
}
