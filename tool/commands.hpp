#pragma once
// The subcommands of `ranging`. Each lives in tool/cmd_<name>.cpp, takes the arguments
// after its name and returns the process exit status (InputError propagates: status 2).
// What `ranging help` and `ranging NAME --help` say of them is kept in one table
// (tool/commands.cpp): the name, the one-line summary and the description.
#include <span>
#include <string>
#include <vector>

#include "tool/cli.hpp"

namespace ranging::tool {

using Args = std::vector<std::string>;

int cmd_codes(const Args& args);   // code families (cmd_codes.cpp)
int cmd_filter(const Args& args);  // bandpass filter design (cmd_filter.cpp)
int cmd_demo(const Args& args);    // encode, channel, filter, decode every code (cmd_demo.cpp)
int cmd_generate(const Args& args);  // HLS C++ and Verilog from a configuration (cmd_generate.cpp)
int cmd_simulate(const Args& args);  // run a scene (cmd_simulate.cpp)
int cmd_evaluate(const Args& args);  // reproduce the paper's Section 4 (cmd_evaluate.cpp)
int cmd_decode(const Args& args);    // decode a real capture (cmd_decode.cpp)
int cmd_doppler(const Args& args);   // decode rate and ToF bias vs line-of-sight speed (cmd_doppler.cpp)
int cmd_sweep(const Args& args);     // design-space sweep and merge (cmd_sweep.cpp)
int cmd_wordlength(const Args& args);  // word-length optimization (cmd_wordlength.cpp)
int cmd_stability(const Args& args); // numerical stability report (cmd_stability.cpp)
int cmd_frames(const Args& args);    // decode the board's UART frames (cmd_frames.cpp)
int cmd_verify(const Args& args);    // the RTL of a configuration against the model (cmd_verify.cpp)
int cmd_bitstream(const Args& args); // iCEBreaker bitstream of a configuration, --program (cmd_bitstream.cpp)

struct Command {
  const char* name;
  int (*run)(const Args&);
  const char* summary;            // its line in `ranging help`
  const char* description;        // `ranging NAME --help`, below the usage line
  const char* synopsis = nullptr;  // the usage line after "ranging " (null: NAME)
};

// Every subcommand, in the order `ranging help` lists them.
std::span<const Command> commands();

// The parser of subcommand `name` (one of commands()): its usage line and description, and
// --help; the command adds its options.
cli::Parser command_parser(const std::string& name);

}  // namespace ranging::tool
