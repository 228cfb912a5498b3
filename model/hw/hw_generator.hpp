#pragma once
// Generates the configuration-dependent hardware files of a receiver design (docs/hardware.md):
// Verilog top with literal parameters, Verilator -G parameter files per module, the HLS C++
// configuration header, a GTKWave save file and a manifest. Generated files are never edited
// by hand: the build regenerates them and a test diffs the committed default.
#include <map>
#include <string>

#include "model/dsp/receiver.hpp"

namespace ranging {

// File name (relative to the output folder) -> content.
std::map<std::string, std::string> generate_hardware_files(const ReceiverDesign& design,
                                                           const std::string& config_origin);

// Writes the files into out_dir atomically: into a temporary sibling folder first, which
// replaces out_dir only when everything was written. On error nothing is left behind.
void write_hardware_files(const std::map<std::string, std::string>& files, const std::string& out_dir);

}  // namespace ranging
