// Interruption (issue 18, section 5): SIGINT or SIGTERM during `ranging simulate`, `ranging
// sweep`, `ranging evaluate` or `ranging bitstream` leaves the previous outputs intact and no
// partial or temporary file, stops the external commands the tool started (yosys, nextpnr:
// model/base/subprocess.hpp), and a re-run succeeds. The tool dies of the signal (its handler unlinks the temporaries of
// model/base/atomic_file.hpp and re-raises), so the exit is "killed by SIGINT/SIGTERM".
#include <gtest/gtest.h>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <functional>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/process.hpp"
#include "tests/scratch.hpp"

namespace fs = std::filesystem;

namespace {

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::map<std::string, std::string> files_in(const fs::path& dir) {
  std::map<std::string, std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (e.is_regular_file()) out[fs::relative(e.path(), dir).string()] = slurp(e.path());
  }
  return out;
}

// Starts the tool, sends sig after delay, returns the wait status.
int run_and_signal(const std::vector<std::string>& args, int sig, std::chrono::milliseconds delay) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv;
    std::string tool = RANGING_TOOL;
    argv.push_back(tool.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int devnull = ::open("/dev/null", O_WRONLY);
    ::dup2(devnull, 1);
    ::dup2(devnull, 2);
    ::execv(tool.c_str(), argv.data());
    ::_exit(127);
  }
  std::this_thread::sleep_for(delay);
  ::kill(pid, sig);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return status;
}

// As run_and_signal, but the signal is sent as soon as ready() holds (polled every 20 ms, at most
// `limit`): the interruption falls mid-run whatever the machine's speed.
int run_and_signal_when(const std::vector<std::string>& args, int sig, const std::function<bool()>& ready,
                        std::chrono::milliseconds limit) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    std::vector<char*> argv;
    std::string tool = RANGING_TOOL;
    argv.push_back(tool.data());
    std::vector<std::string> copy = args;
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int devnull = ::open("/dev/null", O_WRONLY);
    ::dup2(devnull, 1);
    ::dup2(devnull, 2);
    ::execv(tool.c_str(), argv.data());
    ::_exit(127);
  }
  const auto t0 = std::chrono::steady_clock::now();
  int status = 0;
  while (!ready() && std::chrono::steady_clock::now() - t0 < limit) {
    if (::waitpid(pid, &status, WNOHANG) == pid) return status;  // ended on its own
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(pid, sig);
  ::waitpid(pid, &status, 0);
  return status;
}

class Interrupt : public ::testing::TestWithParam<int> {};

TEST_P(Interrupt, SimulateLeavesPreviousOutputsAndNoTemporaries) {
  const int sig = GetParam();
  const ranging::testing_support::ScratchDir scratch("ranging_int_" + std::to_string(sig));
  const fs::path dir = scratch.path();
  // A short run fills the output folder; a long one into the same folder is interrupted.
  std::ofstream(dir / "short.yaml") << "name: s\ngeometry:\n  distances_m: [0.5]\n";
  std::ofstream(dir / "long.yaml") << "name: s\ngeometry:\n  distances_m: [0.2, 0.4, 0.6, 0.8, 1.0]\n"
                                      "  repeats: 400\nnoise:\n  snr_db: 30\n";
  const std::string out = (dir / "out").string();
  const auto first = ranging::testing_support::run_tool("simulate --quiet " + (dir / "short.yaml").string() + " --out " + out);
  ASSERT_EQ(first.status, 0) << first.err;
  const auto before = files_in(out);
  ASSERT_EQ(before.count("measurements.csv"), 1u);
  ASSERT_EQ(before.count("summary.json"), 1u);

  const auto t0 = std::chrono::steady_clock::now();
  const int status = run_and_signal({"simulate", "--quiet", (dir / "long.yaml").string(), "--out", out}, sig,
                                    std::chrono::milliseconds(700));
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(WIFSIGNALED(status)) << "the run ended before the signal (" << s << " s): make long.yaml longer";
  EXPECT_EQ(WTERMSIG(status), sig);
  EXPECT_EQ(files_in(out), before) << "the interrupted run changed or added files";

  // A re-run works and replaces the outputs whole.
  const auto again = ranging::testing_support::run_tool("simulate --quiet " + (dir / "short.yaml").string() + " --out " + out);
  EXPECT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(files_in(out), before);
}

// A sweep interrupted part-way leaves only whole files (every point file parses, no temporary,
// no half-written sweep.json), and a re-run into the same folder resumes: the points done
// before are kept, the rest are evaluated, and the outputs are complete.
TEST(InterruptSweep, SigtermLeavesWholePointFilesAndResumes) {
  const int sig = SIGTERM;
  const ranging::testing_support::ScratchDir scratch("ranging_int_sweep_" + std::to_string(sig));
  const fs::path dir = scratch.path();
  const std::string src = RANGING_SOURCE_DIR;
  // Ten distances per point (about a second each here), five points; the signal comes as soon
  // as the first point file is there.
  std::ofstream(dir / "scene.yaml") << "name: int-scene\ngeometry:\n  distances_m: [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, "
                                       "0.8, 0.9, 1.0]\nexcitation:\n  family: Gold4\nnoise:\n  noise_v: 0.01\n  seed: 1\n";
  std::ofstream(dir / "spec.yaml") << "name: int\nconfig: " << src << "/configs/default.yaml\nscene: "
                                   << (dir / "scene.yaml").string() << "\nmode: grid\naxes:\n"
                                      "  - key: correlator_fixed.chip_bits\n    range: {from: 14, to: 20, step: 2}\n";
  const std::string out = (dir / "out").string();
  auto first_point = [&] {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(fs::path(out) / "points", ec)) {
      if (e.path().extension() == ".json") return true;
    }
    return false;
  };
  const int status = run_and_signal_when({"sweep", (dir / "spec.yaml").string(), "--no-synth", "--quiet", "--out", out},
                                         sig, first_point, std::chrono::milliseconds(60000));
  ASSERT_TRUE(WIFSIGNALED(status)) << "the sweep ended before the signal: make the spec longer";
  EXPECT_EQ(WTERMSIG(status), sig);
  std::size_t kept = 0;
  for (const auto& [name, text] : files_in(out)) {
    EXPECT_EQ(name.find(".tmp-"), std::string::npos) << "temporary left: " << name;
    EXPECT_NE(name, "sweep.json") << "the interrupted sweep wrote its final document";
    if (name.rfind("points/", 0) == 0) {
      EXPECT_TRUE(nlohmann::json::accept(text)) << name << " is not whole JSON";
      ++kept;
    }
  }
  const auto again = ranging::testing_support::run_tool("sweep " + (dir / "spec.yaml").string() + " --no-synth --out " + out);
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_NE(again.err.find(std::to_string(kept) + " done before"), std::string::npos) << again.err;
  const auto doc = nlohmann::json::parse(slurp(fs::path(out) / "sweep.json"));
  ASSERT_TRUE(doc.contains("points"));
  EXPECT_EQ(doc["points"].size(), 5u);  // 4 values of the axis and the base point
}

// The paper's evaluation, interrupted: the outputs of the run before are untouched.
TEST(InterruptEvaluate, SigtermLeavesThePreviousResults) {
  const ranging::testing_support::ScratchDir scratch("ranging_int_eval");
  const fs::path dir = scratch.path();
  const std::string paper = slurp(fs::path(RANGING_SOURCE_DIR) / "scenes/paper-section4.yaml");
  ASSERT_FALSE(paper.empty());
  auto with = [&](const std::vector<std::pair<std::string, std::string>>& lines) {
    std::string s = paper;
    for (const auto& [key, line] : lines) {
      const auto at = s.find(key);
      EXPECT_NE(at, std::string::npos) << key;
      if (at != std::string::npos) s.replace(at, s.find('\n', at) - at, line);
    }
    return s;
  };
  // The same scene name: the long run would write the very files the short one wrote.
  std::ofstream(dir / "short.yaml") << with({{"name: ", "name: ev"}, {"  family: [", "  family: [M1, Gold4]"},
                                             {"  distances_m: [", "  distances_m: [0.1]"}, {"  repeats: ", "  repeats: 1"}});
  std::ofstream(dir / "long.yaml") << with({{"name: ", "name: ev"}});
  const std::string out = (dir / "out").string();
  const auto first = ranging::testing_support::run_tool("evaluate " + (dir / "short.yaml").string() +
                                                        " --no-plots --quiet --out " + out);
  ASSERT_EQ(first.status, 0) << first.err;
  const auto before = files_in(out);
  ASSERT_EQ(before.count("ev-summary.json"), 1u);
  const int status = run_and_signal({"evaluate", (dir / "long.yaml").string(), "--no-plots", "--quiet", "--out", out},
                                    SIGTERM, std::chrono::milliseconds(1500));
  ASSERT_TRUE(WIFSIGNALED(status)) << "the evaluation ended before the signal: make long.yaml longer";
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_EQ(files_in(out), before) << "the interrupted evaluation changed or added files";
  const auto again = ranging::testing_support::run_tool("evaluate " + (dir / "short.yaml").string() +
                                                        " --no-plots --quiet --out " + out);
  EXPECT_EQ(again.status, 0) << again.err;
  EXPECT_EQ(files_in(out).size(), before.size());
}

// The FPGA flow interrupted during synthesis: the tool dies of the signal, yosys (started by
// scripts/build_bitstream.sh, two processes down) stops with it, and no summary is left.
TEST(InterruptBitstream, SigtermStopsTheFlowsCommands) {
  if (std::system("command -v yosys >/dev/null") != 0) GTEST_FAIL() << "yosys not installed";
  const ranging::testing_support::ScratchDir scratch("ranging_int_bitstream");
  const fs::path dir = scratch.path();
  const std::string out = (dir / "out").string();
  const fs::path log = fs::path(out) / "yosys_ice40.log";
  const int status = run_and_signal_when(
      {"bitstream", "--config", std::string(RANGING_SOURCE_DIR) + "/configs/default.yaml", "--out", out}, SIGTERM,
      [&] { return fs::exists(log); }, std::chrono::milliseconds(60000));
  ASSERT_TRUE(fs::exists(log)) << "the flow did not reach synthesis";
  ASSERT_TRUE(WIFSIGNALED(status)) << "the flow ended before the signal";
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  // Nothing that names the work folder is left running (yosys -l OUT/..., the script).
  std::string left;
  for (int i = 0; i < 150; ++i) {  // up to 15 s: yosys may take a while to die on a loaded machine
    left.clear();
    for (const auto& e : fs::directory_iterator("/proc")) {
      const std::string pid = e.path().filename().string();
      if (pid.find_first_not_of("0123456789") != std::string::npos) continue;
      std::string cmdline = slurp(e.path() / "cmdline"), stat = slurp(e.path() / "stat");
      const auto close = stat.rfind(')');
      if (close != std::string::npos && close + 2 < stat.size() && stat[close + 2] == 'Z') continue;
      if (cmdline.find(out) != std::string::npos) left += pid + " ";
    }
    if (left.empty()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_EQ(left, "") << "processes of the interrupted flow still run";
  EXPECT_FALSE(fs::exists(fs::path(out) / "results" / "bitstream.json")) << "a summary of an interrupted flow";
}

INSTANTIATE_TEST_SUITE_P(Signals, Interrupt, ::testing::Values(SIGINT, SIGTERM),
                         [](const ::testing::TestParamInfo<int>& i) { return i.param == SIGINT ? "SIGINT" : "SIGTERM"; });

}  // namespace
