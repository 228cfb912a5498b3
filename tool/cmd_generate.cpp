// `ranging generate`: the hardware files of one receiver configuration (docs/hardware.md).
#include <filesystem>
#include <iostream>

#include "model/config/receiver_config.hpp"
#include "model/base/error.hpp"
#include "model/hw/hw_generator.hpp"
#include "model/hw/hw_params.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"

namespace ranging::tool {

int cmd_generate(const Args& args) {
  cli::Parser p("ranging generate",
                "Generate the HLS C++ configuration and the Verilog of the receiver described by a\n"
                "configuration file. The output folder is replaced atomically: on error nothing is\n"
                "written.");
  p.option("--config", "FILE", "receiver configuration (YAML, docs/configuration.md)");
  p.option("--out", "DIR", "output folder");
  p.option("--origin", "NAME", "name of the configuration in the generated banners (default: FILE as given)");
  if (!p.parse(args)) return 0;
  const auto config = p.get("--config");
  const auto out = p.get("--out");
  if (!config) throw InputError("option --config is required");
  if (!out) throw InputError("option --out is required");
  {  // the folder is replaced as a whole: never replace a file, and fail before the design work
    std::error_code ec;
    if (std::filesystem::exists(*out, ec) && !std::filesystem::is_directory(*out, ec)) {
      throw InputError("option --out: '" + *out + "' exists and is not a folder; expected a folder");
    }
  }
  const ReceiverConfig cfg = load_receiver_config(*config);
  check_generatable(cfg);  // cheap checks first: the design of a large family takes time
  const ReceiverDesign design = design_receiver(cfg);
  const auto files = generate_hardware_files(design, p.get_or("--origin", *config));
  write_hardware_files(files, *out);
  std::cout << "generated " << files.size() << " files for configuration '" << design.config.name
            << "' in " << *out << "\n";
  return 0;
}

}  // namespace ranging::tool
