#include "tool/options.hpp"

#include <cstdio>

#include "tool/guard.hpp"

namespace ranging::tool {

void add_scene_options(cli::Parser& p) {
  p.option("--set", "KEY=VALUE",
           "override a key of the scene, a dotted YAML path (repeatable): noise.noise_v=0.01; receiver.config.KEY "
           "sets a key of its receiver configuration, e.g. receiver.config.correlator_fixed.chip_bits=18");
  p.flag("--quiet", "no progress bar");
  p.flag("--allow-out-of-spec", kAllowOutOfSpecHelp);
}

Scene load_scene_options(const cli::Parser& p, const std::string& cmd, Overrides* overrides) {
  const Overrides ov = parse_overrides(p.values("--set"));
  Scene scene = load_scene(p.positionals().at(0), ov, p.has("--allow-out-of-spec"));
  warn_if_out_of_spec(cmd, scene.receiver.config);
  for (const auto& w : scene.warnings) std::fprintf(stderr, "ranging %s: warning: %s\n", cmd.c_str(), w.c_str());
  if (overrides) *overrides = ov;
  return scene;
}

}  // namespace ranging::tool
