// Placeholder until the demo subcommand lands; it refuses to run rather than print anything.
#include <stdexcept>
#include "tool/commands.hpp"
namespace ranging::tool {
int cmd_demo(const Args&) { throw std::runtime_error("'demo' is not implemented yet"); }
}  // namespace ranging::tool
