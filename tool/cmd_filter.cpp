// Placeholder until the filter subcommand lands; it refuses to run rather than print anything.
#include <stdexcept>
#include "tool/commands.hpp"
namespace ranging::tool {
int cmd_filter(const Args&) { throw std::runtime_error("'filter' is not implemented yet"); }
}  // namespace ranging::tool
