#pragma once
// The hardware parameters of a receiver design: every width, shift, table and constant the
// Verilog modules and the HLS C++ take, derived only from the golden model (one source of
// truth). The generator (tool/cmd_generate.cpp) emits them; the testbenches read them back.
#include <cstdint>
#include <string>
#include <vector>

#include "model/dsp/receiver.hpp"

namespace ranging {

struct HwParam {
  std::string name;
  std::string verilog;  // value in Verilog syntax: 40, or 80'h0123... for packed arrays
  // The same value for C++: an integer, or the list of array elements.
  std::vector<std::int64_t> elements;
  int element_bits = 0;  // 0 for a scalar
};

struct HwModuleParams {
  std::string module;              // bandpass_sos, correlator_bank, peak_detector
  std::vector<HwParam> params;
  const HwParam& at(const std::string& name) const;
  std::int64_t value(const std::string& name) const;  // scalar
};

// Packs signed or unsigned elements of `bits` each into a Verilog literal, element i at
// [i*bits +: bits] (two's complement).
std::string verilog_packed(const std::vector<std::int64_t>& elements, int bits);

std::vector<HwModuleParams> hardware_parameters(const ReceiverDesign& design);

// Throws InputError naming the configuration key when the design cannot be generated
// (a width the hardware modules cannot hold, a code too long, ...).
void check_generatable(const ReceiverDesign& design);
// The cheap part of the same check, before the design is computed (family size).
void check_generatable(const ReceiverConfig& config);

}  // namespace ranging
