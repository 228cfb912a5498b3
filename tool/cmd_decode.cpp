// Placeholder until the decode subcommand lands; it refuses to run rather than print anything.
#include <stdexcept>
#include "tool/commands.hpp"
namespace ranging::tool {
int cmd_decode(const Args&) { throw std::runtime_error("'decode' is not implemented yet"); }
}  // namespace ranging::tool
