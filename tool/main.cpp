// `ranging`: the command-line front end of the golden model.
#include <malloc.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>
#include <vector>

#include "model/base/atomic_file.hpp"
#include "model/base/error.hpp"
#include "tool/build_info.hpp"
#include "tool/commands.hpp"

namespace {

void print_usage(std::ostream& os) {
  os << "usage: ranging <command> [options]    (ranging help <command> for details; ranging --version)\n\n"
        "Coded ultrasonic ranging co-design toolkit (Lu et al., Micromachines 2025, 16, 240).\n\n"
        "commands:\n";
  std::size_t width = 0;  // the longest name, then two spaces
  for (const ranging::tool::Command& c : ranging::tool::commands()) width = std::max(width, std::string(c.name).size());
  for (const ranging::tool::Command& c : ranging::tool::commands()) {
    os << "  " << c.name << std::string(width + 2 - std::string(c.name).size(), ' ') << c.summary << "\n";
  }
}

}  // namespace

int main(int argc, char** argv) {
  // A scene run allocates and frees stream buffers of 0.1-1 MB in turn. With glibc's default
  // 128 KiB trim threshold every free gave the top of the heap back (brk shrink, TLB flush) and
  // the next stream faulted it in again: 19 % of `simulate scenes/default.yaml` in perf. Keep
  // up to 256 MiB of freed heap; allocations under 64 MiB come from the heap, not from mmap.
  mallopt(M_TRIM_THRESHOLD, 256 << 20);
  mallopt(M_MMAP_THRESHOLD, 64 << 20);
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) {
    print_usage(std::cerr);
    return 2;
  }
  if (args[0] == "--version" || args[0] == "-V") {
    std::cout << "ranging " << ranging::tool::build_info::kVersion << " (git " << ranging::tool::build_info::git_commit()
              << ")\n";
    return 0;
  }
  if (args[0] == "help" && args.size() == 2) {
    args = {args[1], "--help"};  // ranging help CMD: CMD --help
  } else if (args[0] == "--help" || args[0] == "-h" || args[0] == "help") {
    if (args.size() > 2) {
      std::cerr << "ranging help: give one command (ranging help CMD)\n";
      return 2;
    }
    print_usage(std::cout);
    return 0;
  }
  ranging::install_output_cleanup_on_signals();  // Ctrl-C leaves no temporary output file
  for (const ranging::tool::Command& c : ranging::tool::commands()) {
    if (args[0] == c.name) {
      try {
        const int status = c.run({args.begin() + 1, args.end()});
        // A full disk or a closed pipe on stdout must not pass for success.
        std::cout.flush();
        if (!std::cout || std::fflush(stdout) != 0 || std::ferror(stdout)) {
          std::cerr << "ranging " << c.name << ": error: cannot write to standard output (disk full?)\n";
          return 2;
        }
        return status;
      } catch (const ranging::InputError& e) {
        std::cerr << "ranging " << c.name << ": error: " << e.what() << "\n";
        return 2;
      } catch (const std::exception& e) {
        std::cerr << "ranging " << c.name << ": internal error: " << e.what() << "\n";
        return 1;
      }
    }
  }
  std::cerr << "ranging: unknown command '" << args[0] << "'\n\n";
  print_usage(std::cerr);
  return 2;
}
