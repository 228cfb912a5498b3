#pragma once
// The one reader of the generated module parameters for the testbenches. The generator writes
// generated/<config>/rtl/<module>.vc (-GNAME=value, what Verilator gets) and manifest.json from
// the same list, hardware_parameters() (model/hw/hw_params.hpp); the testbenches take that list
// in-process instead of parsing the text back. manifest_module() reads manifest.json, for the
// test that the committed file holds the same values (tests/test_generate.cpp checks the
// committed files against the generator byte for byte).
#include <nlohmann/json.hpp>

#include <cstdint>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "model/config/receiver_config.hpp"
#include "model/hw/hw_params.hpp"

namespace ranging::tb {

#ifdef RANGING_CONFIG
// The design of the configuration this testbench is built for (RANGING_CONFIG, a YAML path set
// per target by tb/CMakeLists.txt): what the Verilated module's parameters were generated from.
inline const ReceiverDesign& configured_design() {
  static const ReceiverDesign d = design_receiver(load_receiver_config(RANGING_CONFIG));
  return d;
}
#endif

// (NAME, Verilog value) in the order of the .vc: scalars as decimal, tables packed (element i
// at [i*bits +: bits]).
using ParamList = std::vector<std::pair<std::string, std::string>>;

inline HwModuleParams generated_module(const ReceiverDesign& design, const std::string& module) {
  for (auto& m : hardware_parameters(design)) {
    if (m.module == module) return m;
  }
  throw std::logic_error("generated_module: no module " + module);
}

inline ParamList verilog_params(const HwModuleParams& m) {
  ParamList out;
  for (const auto& p : m.params) out.emplace_back(p.name, p.verilog);
  return out;
}

// manifest.json's "modules"/<module>: every parameter as its list of elements (one for a scalar).
inline std::map<std::string, std::vector<std::int64_t>> manifest_module(const std::string& path,
                                                                        const std::string& module) {
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot read " + path);
  const nlohmann::json j = nlohmann::json::parse(f);
  std::map<std::string, std::vector<std::int64_t>> out;
  for (const auto& [name, v] : j.at("modules").at(module).items()) {
    out[name] = v.is_array() ? v.get<std::vector<std::int64_t>>() : std::vector<std::int64_t>{v.get<std::int64_t>()};
  }
  return out;
}

}  // namespace ranging::tb
