// `ranging generate`: the hardware files of one receiver configuration (docs/hardware.md).
#include <filesystem>
#include <iostream>

#include "model/config/receiver_config.hpp"
#include "model/base/error.hpp"
#include "model/hw/realtime.hpp"
#include "model/hw/hw_generator.hpp"
#include "model/hw/hw_params.hpp"
#include "model/hw/ip_package.hpp"
#include "tool/build_info.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/options.hpp"

namespace ranging::tool {

int cmd_generate(const Args& args) {
  cli::Parser p = command_parser("generate");
  add_config_options(p, {.required = true, .writes_effective = true});
  add_output_options(p, {.out = true});
  add_rtl_option(p);
  p.option("--origin", "NAME", "name of the configuration in the generated banners (default: FILE as given)");
  p.flag("--no-sources", "write only the configuration-dependent files (tops, parameters, HLS configuration, manifest, README): no copies of rtl/ and hls/, no filelists, no .core; the form committed in generated/");
  if (!p.parse(args)) return 0;
  const std::string config = p.required("--config");
  const std::string out = p.required("--out");
  {  // the folder is replaced as a whole: never replace a file, and fail before the design work
    std::error_code ec;
    if (std::filesystem::exists(out, ec) && !std::filesystem::is_directory(out, ec)) {
      throw InputError("option --out: '" + out + "' exists and is not a folder; expected a folder");
    }
  }
  Overrides overrides;
  const ReceiverConfig cfg = load_config_options(p, "generate", &overrides);
  check_generatable(cfg);  // cheap checks first: the design of a large family takes time
  const ReceiverDesign design = design_receiver(cfg);
  std::map<std::string, std::string> files;
  try {
    files = generate_hardware_files(design, p.get_or("--origin", config));
  } catch (const InputError& e) {  // the system design's checks name system.* keys
    throw InputError(locate_in_config(config, e.what()));
  }
  add_ip_package(files, design, rtl_dir_option(p),
                 std::string(build_info::kSourceDir) + "/hls", build_info::kVersion, "--rtl",
                 !p.has("--no-sources"));
  if (!overrides.empty()) files["config.yaml"] = receiver_config_yaml(cfg);  // re-run: --config DIR/config.yaml
  write_hardware_files(files, out);
  const RealTimeBudget rt = realtime_budget(design);  // also in manifest.json
  if (!rt.real_time) std::cerr << "ranging generate: warning: " << rt.summary() << "\n";
  std::cout << "generated " << files.size() << " files for configuration '" << design.config.name
            << "' in " << out << "\n";
  return 0;
}

}  // namespace ranging::tool
