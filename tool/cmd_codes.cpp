// Placeholder until the codes subcommand lands; it refuses to run rather than print anything.
#include <stdexcept>
#include "tool/commands.hpp"
namespace ranging::tool {
int cmd_codes(const Args&) { throw std::runtime_error("'codes' is not implemented yet"); }
}  // namespace ranging::tool
