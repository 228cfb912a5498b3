#pragma once
// Option sets several subcommands share, declared and read in one place (the help text and
// the errors are then the same everywhere).
#include <optional>
#include <string>

#include "model/config/overrides.hpp"
#include "model/dsp/receiver.hpp"
#include "model/sim/scene.hpp"
#include "tool/cli.hpp"

namespace ranging::tool {

// --- a receiver configuration: --config FILE, --set KEY=VALUE, --allow-out-of-spec ---

struct ConfigOptions {
  bool required = false;          // --config is required (the command calls p.required("--config")); else
                                  // the built-in default serves without it. Said in the help.
  bool overrides = true;          // --set KEY=VALUE (repeatable) of the configuration
  bool allow_out_of_spec = true;  // --allow-out-of-spec (kAllowOutOfSpecHelp)
  bool writes_effective = false;  // with --set, the effective configuration is written as DIR/config.yaml
  std::string config_note{};      // appended to the help of --config ("; its system: section ...")
};
void add_config_options(cli::Parser& p, const ConfigOptions& o = {});

// The configuration of --config (the built-in default without it) with the --set overrides
// applied (and returned in *overrides when not null), allow_out_of_spec from --allow-out-of-spec;
// when that let an out-of-spec receiver through, "ranging CMD: warning: ..." goes to stderr.
ReceiverConfig load_config_options(const cli::Parser& p, const std::string& cmd, Overrides* overrides = nullptr);

// --- a scene: SCENE, --set KEY=VALUE, --allow-out-of-spec ---

// The SCENE argument alone (a scene file, YAML).
void add_scene_argument(cli::Parser& p);

// --set KEY=VALUE (repeatable) of `scene` ("the scene") and --allow-out-of-spec.
void add_scene_overrides(cli::Parser& p, const std::string& scene = "the scene");

// The options of a command that runs a scene: SCENE and add_scene_overrides.
void add_scene_options(cli::Parser& p);

// The scene named by the first positional argument with the --set overrides applied (and
// returned in *overrides when not null). When --allow-out-of-spec let an out-of-spec receiver
// through, "ranging CMD: warning: ..." goes to stderr.
Scene load_scene_options(const cli::Parser& p, const std::string& cmd, Overrides* overrides = nullptr);

// --- outputs: --out DIR, --json, --quiet ---

struct OutputOptions {
  bool out = false;           // --out DIR: the output folder (created)
  std::string out_default{};  // its default, said in the help ("out/<scene name>"); empty: none
  bool json = false;          // --json: machine-readable output
  std::string json_note{};    // what --json prints, said in the help ("the tables as JSON on stdout")
  bool quiet = false;         // --quiet: no progress on stderr
};
void add_output_options(cli::Parser& p, const OutputOptions& o);

// --jobs N, `what` ("points evaluated") in parallel, 1..256 (the output does not depend on it),
// `note` appended; jobs_option reads it (default 1).
void add_jobs_option(cli::Parser& p, const std::string& what, const std::string& note = "");
int jobs_option(const cli::Parser& p);

// --- the RTL: --rtl DIR ---

// --rtl DIR, the RTL sources (default: the project's rtl/); `when` prefixes the help
// ("with --precision rtl"). rtl_dir_option: the folder given, else the project's rtl/.
void add_rtl_option(cli::Parser& p, const std::string& when = "");
std::string rtl_dir_option(const cli::Parser& p);

// --- what a code family sends: --family NAME, --speed-of-sound M/S ---

// --family NAME, with what the command does with it ("overrides the configuration's") and its
// default (none: the option has no default).
void add_family_option(cli::Parser& p, const std::string& note, std::optional<std::string> default_value = std::nullopt);

// --speed-of-sound M/S (100..10000), default 340 or, when the command has another, that in
// words ("the capture's metadata, else 340"); speed_of_sound_option reads it within that range.
void add_speed_of_sound_option(cli::Parser& p, const std::string& default_note = "");
double speed_of_sound_option(const cli::Parser& p);

}  // namespace ranging::tool
