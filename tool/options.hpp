#pragma once
// Option sets several subcommands share, declared and read in one place (the help text and
// the errors are then the same everywhere).
#include <string>

#include "model/config/overrides.hpp"
#include "model/sim/scene.hpp"
#include "tool/cli.hpp"

namespace ranging::tool {

// The options of a command that runs a scene: --set KEY=VALUE (of the scene, repeatable),
// --quiet (no progress bar) and --allow-out-of-spec.
void add_scene_options(cli::Parser& p);

// The scene named by the first positional argument with the --set overrides applied (and
// returned in *overrides when not null). When --allow-out-of-spec let an out-of-spec receiver
// through, "ranging CMD: warning: ..." goes to stderr.
Scene load_scene_options(const cli::Parser& p, const std::string& cmd, Overrides* overrides = nullptr);

}  // namespace ranging::tool
