// Placeholder until the simulate subcommand lands; it refuses to run rather than print anything.
#include <stdexcept>
#include "tool/commands.hpp"
namespace ranging::tool {
int cmd_simulate(const Args&) { throw std::runtime_error("'simulate' is not implemented yet"); }
}  // namespace ranging::tool
