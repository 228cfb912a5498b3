#pragma once
// External commands (yosys, nextpnr, the FPGA flow script, Verilator builds, plot scripts) run
// so that an interruption reaches them.
//
// run_shell(cmd) is std::system(cmd) with two differences:
//   - the command runs in its own process group (sh -c CMD, setpgid), and while it runs SIGINT,
//     SIGTERM and SIGHUP sent to this process are forwarded to that whole group, so a
//     `kill PID` or Ctrl-C stops yosys, nextpnr and whatever else the command started instead
//     of leaving them running as orphans (std::system ignores SIGINT in the caller and leaves
//     SIGTERM to kill the caller alone). SIGINT and SIGHUP are followed by a SIGTERM to the
//     group: a non-interactive shell starts its background jobs (`cmd &`) with SIGINT ignored;
//   - when such a signal arrived, run_shell waits for the group's leader to end and then
//     raises the signal again in this process with the handler that was installed before
//     (install_output_cleanup_on_signals: unlink the temporaries, die of the signal).
// The return value is the wait status, as std::system's (WIFEXITED / WEXITSTATUS); -1 if the
// command could not be started.
#include <string>

namespace ranging {

int run_shell(const std::string& cmd);

}  // namespace ranging
