// Placeholder until the evaluate subcommand lands; it refuses to run rather than print anything.
#include <stdexcept>
#include "tool/commands.hpp"
namespace ranging::tool {
int cmd_evaluate(const Args&) { throw std::runtime_error("'evaluate' is not implemented yet"); }
}  // namespace ranging::tool
