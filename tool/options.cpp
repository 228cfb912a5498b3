#include "tool/options.hpp"

#include <cstdio>
#include <utility>

#include "model/config/receiver_config.hpp"
#include "tool/build_info.hpp"
#include "tool/guard.hpp"

namespace ranging::tool {

void add_config_options(cli::Parser& p, const ConfigOptions& o) {
  p.option("--config", "FILE",
           std::string("receiver configuration (YAML, docs/configuration.md)") +
               (o.required ? "" : "; default: the built-in default") + o.config_note);
  if (o.overrides) {
    p.option("--set", "KEY=VALUE",
             std::string("override a key of the configuration, a dotted YAML path (repeatable): "
                         "correlator_fixed.chip_bits=18, filter.type=ellip") +
                 (o.required ? "" : " (of --config, else of the built-in default)") +
                 (o.writes_effective ? "; the effective configuration is written as DIR/config.yaml" : ""));
  }
  if (o.allow_out_of_spec) p.flag("--allow-out-of-spec", kAllowOutOfSpecHelp);
}

ReceiverConfig load_config_options(const cli::Parser& p, const std::string& cmd, Overrides* overrides) {
  const Overrides ov = parse_overrides(p.values("--set"));
  const bool allow = p.has("--allow-out-of-spec");
  ReceiverConfig cfg = p.has("--config") ? load_receiver_config(*p.get("--config"), ov, allow)
                                         : default_receiver_config(ov);
  cfg.allow_out_of_spec = allow;
  warn_if_out_of_spec(cmd, cfg);
  if (overrides) *overrides = ov;
  return cfg;
}

void add_scene_argument(cli::Parser& p) {
  p.positional("SCENE", "scene file (YAML, docs/scenes.md)");
}

void add_scene_overrides(cli::Parser& p, const std::string& scene) {
  p.option("--set", "KEY=VALUE",
           "override a key of " + scene +
               ", a dotted YAML path (repeatable, docs/scenes.md): noise.noise_v=0.01; receiver.config.KEY sets a "
               "key of its receiver configuration, e.g. receiver.config.correlator_fixed.chip_bits=18");
  p.flag("--allow-out-of-spec", kAllowOutOfSpecHelp);
}

void add_scene_options(cli::Parser& p) {
  add_scene_argument(p);
  add_scene_overrides(p);
}

Scene load_scene_options(const cli::Parser& p, const std::string& cmd, Overrides* overrides) {
  const Overrides ov = parse_overrides(p.values("--set"));
  Scene scene = load_scene(p.positionals().at(0), ov, p.has("--allow-out-of-spec"));
  warn_if_out_of_spec(cmd, scene.receiver.config);
  for (const auto& w : scene.warnings) std::fprintf(stderr, "ranging %s: warning: %s\n", cmd.c_str(), w.c_str());
  if (overrides) *overrides = ov;
  return scene;
}

void add_output_options(cli::Parser& p, const OutputOptions& o) {
  if (o.out) {
    p.option("--out", "DIR",
             "output folder (created" + (o.out_default.empty() ? std::string() : "; default: " + o.out_default) + ")");
  }
  if (o.json) p.flag("--json", "machine-readable output" + (o.json_note.empty() ? std::string() : " (" + o.json_note + ")"));
  if (o.quiet) p.flag("--quiet", "no progress on stderr");
}

void add_jobs_option(cli::Parser& p, const std::string& what, const std::string& note) {
  p.option("--jobs", "N", what + " in parallel, 1..256 (the output does not depend on it" + note + ")", "1");
}

int jobs_option(const cli::Parser& p) { return static_cast<int>(p.integer("--jobs", 1, 1, 256)); }

void add_rtl_option(cli::Parser& p, const std::string& when) {
  p.option("--rtl", "DIR", (when.empty() ? "" : when + ": ") + "the RTL sources (default: the project's rtl/)");
}

std::string rtl_dir_option(const cli::Parser& p) {
  return p.get_or("--rtl", std::string(build_info::kSourceDir) + "/rtl");
}

void add_family_option(cli::Parser& p, const std::string& note, std::optional<std::string> default_value) {
  p.option("--family", "NAME", "code family, e.g. M1 or Gold4 (ranging codes --list): " + note, std::move(default_value));
}

void add_speed_of_sound_option(cli::Parser& p, const std::string& default_note) {
  if (default_note.empty()) {
    p.option("--speed-of-sound", "M/S", "speed of sound, 100..10000", "340");
    return;
  }
  p.option("--speed-of-sound", "M/S", "speed of sound, 100..10000 (default: " + default_note + ")");
}

double speed_of_sound_option(const cli::Parser& p) { return p.number("--speed-of-sound", 340, 100, 10000); }

}  // namespace ranging::tool
