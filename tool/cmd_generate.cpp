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
#include "tool/guard.hpp"
#include "tool/commands.hpp"

namespace ranging::tool {

int cmd_generate(const Args& args) {
  cli::Parser p("ranging generate",
                "Generate the self-contained IP folder of the receiver described by a configuration\n"
                "file: the Verilog top and parameters, copies of every RTL source it needs, the HLS\n"
                "C++ and its configuration header, filelists (files.f: receiver_top, system.f: the\n"
                "ranging system), a README of the ports, a FuseSoC CAPI2 .core file and a GTKWave\n"
                "save file. The output folder is replaced atomically: on error nothing is written.");
  p.option("--config", "FILE", "receiver configuration (YAML, docs/configuration.md)");
  p.option("--out", "DIR", "output folder");
  p.option("--rtl", "DIR", "take the RTL sources from DIR instead of the project's rtl/");
  p.option("--origin", "NAME", "name of the configuration in the generated banners (default: FILE as given)");
  p.option("--set", "KEY=VALUE", "override a key of the configuration, a dotted YAML path (repeatable): correlator_fixed.chip_bits=18, filter.type=ellip; the effective configuration is written as DIR/config.yaml");
  p.flag("--no-sources", "write only the configuration-dependent files (tops, parameters, HLS configuration, manifest, README): no copies of rtl/ and hls/, no filelists, no .core; the form committed in generated/");
  p.flag("--allow-out-of-spec", kAllowOutOfSpecHelp);
  if (!p.parse(args)) return 0;
  const std::string config = p.required("--config");
  const std::string out = p.required("--out");
  {  // the folder is replaced as a whole: never replace a file, and fail before the design work
    std::error_code ec;
    if (std::filesystem::exists(out, ec) && !std::filesystem::is_directory(out, ec)) {
      throw InputError("option --out: '" + out + "' exists and is not a folder; expected a folder");
    }
  }
  const Overrides overrides = parse_overrides(p.values("--set"));
  const ReceiverConfig cfg = load_receiver_config(config, overrides, p.has("--allow-out-of-spec"));
  warn_if_out_of_spec("generate", cfg);
  check_generatable(cfg);  // cheap checks first: the design of a large family takes time
  const ReceiverDesign design = design_receiver(cfg);
  std::map<std::string, std::string> files;
  try {
    files = generate_hardware_files(design, p.get_or("--origin", config));
  } catch (const InputError& e) {  // the system design's checks name system.* keys
    throw InputError(locate_in_config(config, e.what()));
  }
  add_ip_package(files, design, p.get_or("--rtl", std::string(build_info::kSourceDir) + "/rtl"),
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
