#pragma once
// A fresh directory for a test's scratch files, removed with everything in it when the object goes
// out of scope: also when an ASSERT_ fails and returns early, so no run leaves files behind in the
// temp directory. For data shared by several tests keep one in a fixture (a static one for
// SetUpTestSuite, reset in TearDownTestSuite) or a function-local static (removed at exit).
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <string>
#include <system_error>

namespace ranging::testing_support {

class ScratchDir {
 public:
  // <base>/<prefix>_<pid>_<n>: the pid keeps concurrent test processes apart, n the directories
  // of one process. Gtest tests pass ::testing::TempDir() as base; the default serves code
  // without gtest (the fuzz entry).
  explicit ScratchDir(const std::string& prefix,
                      const std::filesystem::path& base = std::filesystem::temp_directory_path()) {
    static std::atomic<unsigned> counter{0};
    path_ = base / (prefix + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    std::filesystem::remove_all(path_);  // a leftover of a killed process that had the same pid
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ec;  // never throws from a destructor; a failed removal only leaves the tree
    std::filesystem::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::string str() const { return path_.string(); }
  // The path of `name` inside the directory, as a string (nothing is created).
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace ranging::testing_support
