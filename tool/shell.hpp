#pragma once
// Shell quoting for the commands the tool runs (yosys, verilator, iverilog, nextpnr, the plot
// scripts): one definition for every caller.
#include <string>

namespace ranging::tool {

// s in single quotes, each embedded ' written as '\'': one word for /bin/sh whatever s holds.
inline std::string shell_quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace ranging::tool
