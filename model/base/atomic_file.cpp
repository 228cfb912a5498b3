#include "model/base/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>

#include "model/base/error.hpp"

namespace ranging {
namespace {

// Temporaries in flight, for the signal handler: fixed storage, no allocation in the handler.
constexpr int kSlots = 32;
constexpr std::size_t kPathMax = 4096;
char g_paths[kSlots][kPathMax];
std::atomic<bool> g_used[kSlots];

int register_temporary(const std::string& path) {
  if (path.size() >= kPathMax) return -1;
  for (int i = 0; i < kSlots; ++i) {
    bool expected = false;
    if (g_used[i].load() || !g_used[i].compare_exchange_strong(expected, true)) continue;
    // Claimed: the handler may read the slot from now on, so write the path before publishing
    // a non-empty string (the first byte last).
    g_paths[i][0] = '\0';
    std::memcpy(g_paths[i] + 1, path.c_str() + 1, path.size());  // includes the terminator
    std::atomic_signal_fence(std::memory_order_seq_cst);
    g_paths[i][0] = path[0];
    return i;
  }
  return -1;
}

void unregister_temporary(int slot) {
  if (slot < 0) return;
  g_paths[slot][0] = '\0';
  std::atomic_signal_fence(std::memory_order_seq_cst);
  g_used[slot].store(false);
}

extern "C" void cleanup_and_die(int sig) {
  for (int i = 0; i < kSlots; ++i) {
    if (g_used[i].load() && g_paths[i][0] != '\0') ::unlink(g_paths[i]);
  }
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

std::string reason(int err) { return std::strerror(err); }

[[noreturn]] void fail(const std::string& path, const std::string& what, int err) {
  throw InputError(path + ": cannot write: " + what + (err ? ": " + reason(err) : std::string()));
}

// Writes all of content to fd; returns 0 or the errno of the failure.
int write_all(int fd, const std::string& content) {
  const char* p = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  return 0;
}

std::string parent_of(const std::string& path) {
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return dir.empty() ? "." : dir;
}

}  // namespace

void write_file_atomic(const std::string& path, const std::string& content) {
  if (path.empty()) throw InputError("cannot write: empty output file name");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    if (S_ISDIR(st.st_mode)) fail(path, "it is a folder, expected a file", 0);
    if (!S_ISREG(st.st_mode)) {  // a device or FIFO: write in place
      const int fd = ::open(path.c_str(), O_WRONLY | O_TRUNC | O_CLOEXEC);
      if (fd < 0) fail(path, "cannot open", errno);
      int err = write_all(fd, content);
      if (::close(fd) != 0 && err == 0) err = errno;
      if (err) fail(path, "write failed", err);
      return;
    }
  }
  const std::filesystem::path p(path);
  const std::string dir = parent_of(path);
  std::random_device rd;
  std::string tmp;
  int fd = -1;
  for (int attempt = 0; attempt < 16 && fd < 0; ++attempt) {
    char suffix[16];
    std::snprintf(suffix, sizeof suffix, "%08x", static_cast<unsigned>(rd()));
    tmp = dir + "/." + p.filename().string() + ".tmp-" + suffix;
    fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) fail(path, "cannot create a file in '" + dir + "'", errno);
  }
  if (fd < 0) fail(path, "cannot create a unique temporary name in '" + dir + "'", EEXIST);
  const int slot = register_temporary(tmp);
  int err = write_all(fd, content);
  if (err == 0 && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err == 0 && ::rename(tmp.c_str(), path.c_str()) != 0) err = errno;
  if (err) {
    ::unlink(tmp.c_str());
    unregister_temporary(slot);
    fail(path, "write failed", err);
  }
  unregister_temporary(slot);
}

void check_output_file(const std::string& path, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (path.empty()) throw InputError(what + ": empty file name");
  if (fs::is_directory(path, ec)) throw InputError(what + ": '" + path + "' is a folder; expected a file name");
  const std::string dir = parent_of(path);
  if (!fs::exists(dir, ec)) throw InputError(what + ": '" + path + "': folder '" + dir + "' does not exist");
  if (!fs::is_directory(dir, ec)) throw InputError(what + ": '" + path + "': '" + dir + "' is not a folder");
  if (::access(dir.c_str(), W_OK) != 0) {
    throw InputError(what + ": '" + path + "': folder '" + dir + "' is not writable: " + reason(errno));
  }
}

std::vector<std::string> check_output_dir(const std::string& dir, const std::string& what) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (dir.empty()) throw InputError(what + ": empty folder name");
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) {
    throw InputError(what + ": '" + dir + "' exists and is not a folder; expected a folder");
  }
  std::vector<std::string> created;
  for (fs::path p = fs::path(dir).lexically_normal(); !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
    created.insert(created.begin(), p.string());
    if (p == p.parent_path()) break;
  }
  fs::create_directories(dir, ec);
  if (ec) throw InputError(what + ": cannot create the folder '" + dir + "': " + ec.message());
  // Probe: a file can be created there (read-only file systems, permissions).
  std::random_device rd;
  const std::string probe = dir + "/.ranging-probe-" + std::to_string(rd());
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) {
    const int err = errno;
    for (auto it = created.rbegin(); it != created.rend(); ++it) fs::remove(*it, ec);
    throw InputError(what + ": folder '" + dir + "' is not writable: " + reason(err));
  }
  ::close(fd);
  ::unlink(probe.c_str());
  return created;
}

OutputDir::~OutputDir() {
  std::error_code ec;
  for (auto it = created_.rbegin(); it != created_.rend(); ++it) std::filesystem::remove(*it, ec);  // only if empty
}

void install_output_cleanup_on_signals() {
  struct sigaction sa {};
  sa.sa_handler = cleanup_and_die;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) ::sigaction(sig, &sa, nullptr);
}

}  // namespace ranging
