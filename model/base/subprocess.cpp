#include "model/base/subprocess.hpp"

#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <mutex>

namespace ranging {

namespace {

constexpr int kForwarded[] = {SIGINT, SIGTERM, SIGHUP};
constexpr int kSlots = 64;  // commands running at once (sweep --jobs); more are not forwarded to

std::atomic<pid_t> g_groups[kSlots];  // process groups of the running commands (0: free)
std::atomic<int> g_received{0};       // the first signal received while any ran

// sig to the process group, then SIGTERM: a non-interactive shell starts its background jobs
// (cmd &) with SIGINT ignored. Async-signal-safe.
void forward_to(pid_t group, int sig) {
  ::kill(-group, sig);
  if (sig != SIGTERM) ::kill(-group, SIGTERM);
}

extern "C" void forward_signal(int sig) {
  int none = 0;
  g_received.compare_exchange_strong(none, sig);
  for (auto& g : g_groups) {
    const pid_t p = g.load();
    if (p > 0) forward_to(p, sig);
  }
}

// The forwarding handlers are installed by the first running command and the previous
// dispositions restored by the last one.
std::mutex g_mutex;
int g_running = 0;
struct sigaction g_old[3];
bool g_forwarding[3];

void enter() {
  std::lock_guard<std::mutex> lock(g_mutex);
  if (g_running++ > 0) return;
  g_received.store(0);
  struct sigaction fwd {};
  fwd.sa_handler = forward_signal;
  sigemptyset(&fwd.sa_mask);
  for (int i = 0; i < 3; ++i) {
    ::sigaction(kForwarded[i], nullptr, &g_old[i]);
    // Ignored here (nohup, a background job): left ignored, and ignored by the command too.
    g_forwarding[i] = g_old[i].sa_handler != SIG_IGN;
    if (g_forwarding[i]) ::sigaction(kForwarded[i], &fwd, nullptr);
  }
}

int leave() {  // the signal to raise now (0: none)
  std::lock_guard<std::mutex> lock(g_mutex);
  if (--g_running > 0) return 0;
  for (int i = 0; i < 3; ++i) {
    if (g_forwarding[i]) ::sigaction(kForwarded[i], &g_old[i], nullptr);
  }
  return g_received.exchange(0);
}

}  // namespace

int run_shell(const std::string& cmd) {
  enter();
  // The signals stay blocked in this thread until the child's group is published, so one that
  // comes between fork and then is forwarded rather than lost.
  sigset_t block, prev;
  sigemptyset(&block);
  for (int s : kForwarded) sigaddset(&block, s);
  ::pthread_sigmask(SIG_BLOCK, &block, &prev);
  int status = -1;
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::setpgid(0, 0);
    // exec resets handled signals to their defaults and keeps ignored ones ignored.
    ::pthread_sigmask(SIG_SETMASK, &prev, nullptr);
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  int slot = -1;
  if (pid > 0) {
    ::setpgid(pid, pid);  // the child does it too: whichever runs first
    for (int i = 0; i < kSlots && slot < 0; ++i) {
      pid_t free = 0;
      if (g_groups[i].compare_exchange_strong(free, pid)) slot = i;
    }
    // A signal that came before the slot was published: forward it now.
    if (const int sig = g_received.load()) forward_to(pid, sig);
  }
  ::pthread_sigmask(SIG_SETMASK, &prev, nullptr);
  if (pid > 0) {
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
  }
  if (slot >= 0) g_groups[slot].store(0);
  if (const int sig = leave()) ::raise(sig);  // with the handler from before: it decides
  return status;
}

}  // namespace ranging
