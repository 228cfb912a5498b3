// `ranging bitstream` (tool/cmd_bitstream.cpp), the fast paths: help, bad input, and --program
// with no programmer or no board (refused before anything is built: exit 2, nothing on stdout),
// and the programming path itself with a stand-in iceprog. The real place-and-route run is
// tests/test_bitstream_soak.cpp (label soak; CI's bitstream_targets places and routes the default).
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/process.hpp"
#include "tests/scratch.hpp"

namespace {

namespace fs = std::filesystem;
using ranging::testing_support::run_command;
using ranging::testing_support::run_tool;

const std::string kDefault = std::string(RANGING_SOURCE_DIR) + "/configs/default.yaml";

void write_script(const std::string& path, const std::string& body) {
  std::ofstream(path) << "#!/bin/sh\n" << body;
  ::chmod(path.c_str(), 0755);
}

std::string tool() { return std::string("\"") + RANGING_TOOL + "\""; }

TEST(BitstreamCli, HelpNamesTheOptions) {
  const auto r = run_tool("bitstream --help");
  EXPECT_EQ(r.status, 0);
  for (const char* o : {"--config", "--board", "--seeds", "--jobs", "--out", "--program", "--check"}) {
    EXPECT_NE(r.out.find(o), std::string::npos) << o;
  }
}

TEST(BitstreamCli, BadOptionsAreRefused) {
  struct Case {
    std::string args, expect;
  };
  const Case cases[] = {
      {"--config " + kDefault + " --seeds 0", "option --seeds: 0 is out of range; valid range is [1, 99]"},
      {"--config " + kDefault + " --jobs x", "option --jobs: 'x' is not an integer"},
      {"--config " + kDefault + " --board ulx3s", "option --board: 'ulx3s' is not supported; valid: icebreaker"},
      {"--seeds 2", "option --config is required"},
      {"--config " + kDefault + " --bin x.bin", "option --bin: only with --program"},
      {"--config " + kDefault + " --set system.time_w=20", "system.time_w"},
  };
  for (const auto& c : cases) {
    const auto r = run_tool("bitstream " + c.args);
    EXPECT_EQ(r.status, 2) << c.args;
    EXPECT_TRUE(r.out.empty()) << c.args << ": " << r.out;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << ": " << r.err;
  }
  const ranging::testing_support::ScratchDir scratch("bitstream_bad", ::testing::TempDir());
  const std::string dir = scratch.str();
  std::ofstream(dir + "/c.yaml") << "name: x\nsystem:\n  baud: 7\n";
  const auto r = run_tool("bitstream --config " + dir + "/c.yaml --out " + dir + "/out");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(dir + "/c.yaml:3: system.baud"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

// No iceprog and no openFPGALoader on PATH: refused at once, nothing built.
TEST(BitstreamCli, ProgramWithoutAProgrammerFailsBeforeBuilding) {
  const ranging::testing_support::ScratchDir scratch("bitstream_noprog", ::testing::TempDir());
  const std::string dir = scratch.str();
  const auto r = run_command("PATH=" + dir + " " + tool() + " bitstream --config " + kDefault + " --program --out " +
                             dir + "/out");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("option --program: no programmer found: install iceprog (Debian package fpga-icestorm) or "
                       "openFPGALoader"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

// iceprog installed, no board attached (its probe fails as the real one does without a board).
TEST(BitstreamCli, ProgramWithoutABoardFailsBeforeBuilding) {
  const ranging::testing_support::ScratchDir scratch("bitstream_noboard", ::testing::TempDir());
  const std::string dir = scratch.str();
  write_script(dir + "/iceprog", "echo \"Can't find iCE FTDI USB device (vendor_id 0x0403, device_id 0x6010 or 0x6014).\"\n"
                                 "echo ABORT.\nexit 2\n");
  const auto r = run_command("PATH=" + dir + ":/usr/bin:/bin " + tool() + " bitstream --config " + kDefault +
                             " --program --out " + dir + "/out");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("option --program: no iCEBreaker board answers (`iceprog -t`: ABORT.)"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
}

// --program --bin FILE: probe, then write the given bitstream; nothing is built.
TEST(BitstreamCli, ProgramsAnExistingBitstream) {
  const ranging::testing_support::ScratchDir scratch("bitstream_prog", ::testing::TempDir());
  const std::string dir = scratch.str();
  write_script(dir + "/iceprog", "echo \"$@\" >> " + dir + "/calls\n");
  std::ofstream(dir + "/my.bin") << "not really a bitstream";
  auto r = run_command("PATH=" + dir + ":/usr/bin:/bin " + tool() + " bitstream --program --bin " + dir + "/my.bin");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("programmed " + dir + "/my.bin with iceprog"), std::string::npos) << r.out;
  std::ifstream calls(dir + "/calls");
  std::stringstream ss;
  ss << calls.rdbuf();
  EXPECT_EQ(ss.str(), "-t\n" + dir + "/my.bin\n");
  // The programmer failing is reported, exit 2.
  write_script(dir + "/iceprog", "[ \"$1\" = -t ] && exit 0\necho 'flash write failed'\nexit 1\n");
  r = run_command("PATH=" + dir + ":/usr/bin:/bin " + tool() + " bitstream --program --bin " + dir + "/my.bin");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("failed: flash write failed"), std::string::npos) << r.err;
  r = run_command("PATH=" + dir + ":/usr/bin:/bin " + tool() + " bitstream --program --bin " + dir + "/none.bin");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("option --bin: no file"), std::string::npos) << r.err;
}

}  // namespace
