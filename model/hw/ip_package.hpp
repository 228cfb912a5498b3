#pragma once
// The self-contained IP folder of one receiver configuration (docs/hardware.md, "IP folder"):
// on top of the generated files (hw_generator.hpp) it carries copies of every RTL source the
// generated tops instantiate, the HLS receiver, filelists, a port README and a FuseSoC CAPI2
// core file, so that the folder alone lints, simulates and synthesizes:
//
//   cd OUT && verilator --lint-only -Wall -f files.f      # receiver_top
//   cd OUT && iverilog -g2012 -c files.f -o /dev/null
//   cd OUT && yosys -p "read_verilog $(cat files.f | tr '\n' ' '); hierarchy -top receiver_top"
//   cd OUT && verilator --lint-only -Wall -f system.f     # ranging_system_top
//
// Filelists hold plain paths relative to the IP folder, one per line (the subset every tool
// reads). The copied sources are verbatim (no banner): they are the project's RTL, or the
// user's when `--rtl DIR` is given.
#include <map>
#include <string>
#include <vector>

#include "model/dsp/receiver.hpp"

namespace ranging {

// RTL files (names in rtl/) of the receiver and of the ranging system around it.
const std::vector<std::string>& receiver_rtl_sources();
const std::vector<std::string>& system_rtl_sources();
// The HLS headers (hls/, one per stage; receiver_hls.hpp includes them all).
const std::vector<std::string>& hls_sources();

// Reads the RTL sources from rtl_dir and the HLS headers from hls_dir and adds them to `files`
// (the output of generate_hardware_files), with files.f, system.f, README.md and
// <core name>.core. A missing source is an InputError naming it and `rtl_option`.
// With copy_sources false only the configuration-dependent README.md is added (the form
// committed in generated/, `ranging generate --no-sources`): no copies, no filelists, no .core.
void add_ip_package(std::map<std::string, std::string>& files, const ReceiverDesign& design,
                    const std::string& rtl_dir, const std::string& hls_dir, const std::string& version,
                    const std::string& rtl_option = "--rtl", bool copy_sources = true);

// FuseSoC VLNV name part of a configuration: letters, digits and '_' only.
std::string core_name(const std::string& config_name);

}  // namespace ranging
