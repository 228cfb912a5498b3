#pragma once
// Runs a command as a process for the CLI tests, capturing its exit status, stdout and stderr.
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace ranging::testing_support {

struct ProcessResult {
  int status = -1;  // exit status, -1 if the process did not exit normally
  std::string out, err;
};

inline ProcessResult run_command(const std::string& cmd) {
  static int counter = 0;
  const auto err_path = std::filesystem::temp_directory_path() /
                        ("ranging_test_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) + ".err");
  ProcessResult r;
  FILE* pipe = ::popen((cmd + " 2>\"" + err_path.string() + "\"").c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
  const int st = ::pclose(pipe);
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  std::ifstream ef(err_path);
  std::stringstream ss;
  ss << ef.rdbuf();
  r.err = ss.str();
  std::filesystem::remove(err_path);
  return r;
}

// The built `ranging` tool with arguments.
inline ProcessResult run_tool(const std::string& args) {
  return run_command(std::string("\"") + RANGING_TOOL + "\" " + args);
}

}  // namespace ranging::testing_support
