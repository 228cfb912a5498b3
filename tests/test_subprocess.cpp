// run_shell (model/base/subprocess.hpp): std::system's exit status, and an interruption that
// reaches the whole command: SIGTERM or SIGINT to the caller stops the command's children too
// (std::system leaves them running) and then the caller dies of the signal.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "model/base/atomic_file.hpp"
#include "model/base/subprocess.hpp"

namespace fs = std::filesystem;

namespace {

// Alive and not a zombie.
bool running(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string s;
  if (!std::getline(stat, s)) return false;
  const auto close = s.rfind(')');
  return close != std::string::npos && close + 2 < s.size() && s[close + 2] != 'Z';
}

// A child process runs `sleep 60` (its pid in pidfile) through run_shell, or std::system;
// the test sends sig to that child once the sleep has started.
struct Outcome {
  int status = 0;          // the child's wait status
  bool sleep_survived = false;
};

Outcome interrupt_child(bool use_run_shell, int sig) {
  const fs::path pidfile = fs::temp_directory_path() / ("ranging_subprocess_" + std::to_string(::getpid()) + "_" +
                                                        std::to_string(sig) + (use_run_shell ? "_r" : "_s"));
  fs::remove(pidfile);
  const std::string cmd = "sleep 60 & echo $! > " + pidfile.string() + "; wait";
  const pid_t child = ::fork();
  if (child == 0) {
    ranging::install_output_cleanup_on_signals();
    const int st = use_run_shell ? ranging::run_shell(cmd) : std::system(cmd.c_str());
    ::_exit(WIFEXITED(st) ? WEXITSTATUS(st) : 100);
  }
  pid_t sleeper = 0;
  for (int i = 0; i < 500 && sleeper == 0; ++i) {
    std::ifstream f(pidfile);
    if (!(f >> sleeper)) sleeper = 0;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  Outcome o;
  EXPECT_GT(sleeper, 0) << "the command did not start";
  ::kill(child, sig);
  // std::system ignores SIGINT in the caller: give it a moment, then end the test's sleep.
  const auto t0 = std::chrono::steady_clock::now();
  while (std::chrono::steady_clock::now() - t0 < std::chrono::seconds(2)) {
    if (::waitpid(child, &o.status, WNOHANG) == child) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  // The signalled sleep may need a moment to be scheduled and exit on a loaded machine: it
  // survived if it still runs 3 s later.
  const auto t1 = std::chrono::steady_clock::now();
  while (sleeper > 0 && running(sleeper) && std::chrono::steady_clock::now() - t1 < std::chrono::seconds(3)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  o.sleep_survived = sleeper > 0 && running(sleeper);
  if (sleeper > 0) ::kill(sleeper, SIGKILL);
  if (::waitpid(child, &o.status, WNOHANG) == 0) {  // still running (std::system with SIGINT)
    ::waitpid(child, &o.status, 0);
  }
  fs::remove(pidfile);
  return o;
}

}  // namespace

TEST(RunShell, ReturnsTheWaitStatusLikeSystem) {
  EXPECT_EQ(ranging::run_shell("true"), 0);
  const int st = ranging::run_shell("exit 3");
  ASSERT_TRUE(WIFEXITED(st));
  EXPECT_EQ(WEXITSTATUS(st), 3);
  EXPECT_EQ(ranging::run_shell("exit 3"), std::system("exit 3"));
  const int missing = ranging::run_shell("/nonexistent/command 2>/dev/null");
  ASSERT_TRUE(WIFEXITED(missing));
  EXPECT_EQ(WEXITSTATUS(missing), 127);
}

TEST(RunShell, ASignalStopsTheCommandsChildrenAndThenTheCaller) {
  for (int sig : {SIGTERM, SIGINT}) {
    SCOPED_TRACE(sig == SIGTERM ? "SIGTERM" : "SIGINT");
    const Outcome o = interrupt_child(true, sig);
    EXPECT_TRUE(WIFSIGNALED(o.status)) << "the caller must die of the signal";
    if (WIFSIGNALED(o.status)) {
      EXPECT_EQ(WTERMSIG(o.status), sig);
    }
    EXPECT_FALSE(o.sleep_survived) << "the command's child outlived the interruption";
  }
}

// What run_shell is for: with std::system a SIGTERM kills the caller alone and the command's
// child keeps running.
TEST(RunShell, StdSystemLeavesTheChildRunning) {
  const Outcome o = interrupt_child(false, SIGTERM);
  EXPECT_TRUE(WIFSIGNALED(o.status));
  EXPECT_TRUE(o.sleep_survived);
}
