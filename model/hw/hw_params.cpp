#include "model/hw/hw_params.hpp"

#include <sstream>

#include "model/base/error.hpp"

namespace ranging {
namespace {

HwParam scalar(const std::string& name, std::int64_t v) {
  return HwParam{name, std::to_string(v), {v}, 0};
}

HwParam packed(const std::string& name, const std::vector<std::int64_t>& e, int bits) {
  return HwParam{name, verilog_packed(e, bits), e, bits};
}

int rounding_code(Rounding r) {
  switch (r) {
    case Rounding::Truncate: return 0;
    case Rounding::RoundHalfUp: return 1;
    case Rounding::Convergent: return 2;
  }
  return 1;
}

int bits_for(std::int64_t v) {  // unsigned width holding v
  int b = 1;
  while ((std::int64_t{1} << b) <= v) ++b;
  return b;
}

}  // namespace

const HwParam& HwModuleParams::at(const std::string& name) const {
  for (const auto& p : params) {
    if (p.name == name) return p;
  }
  throw std::out_of_range(module + ": no parameter " + name);
}

std::int64_t HwModuleParams::value(const std::string& name) const { return at(name).elements.at(0); }

std::string verilog_packed(const std::vector<std::int64_t>& elements, int bits) {
  const std::size_t total = elements.size() * static_cast<std::size_t>(bits);
  std::vector<bool> v(total, false);
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const std::uint64_t u = static_cast<std::uint64_t>(elements[i]);
    for (int b = 0; b < bits; ++b) v[i * bits + b] = b < 64 ? ((u >> b) & 1u) : (elements[i] < 0);
  }
  std::string hex;
  const std::size_t digits = (total + 3) / 4;
  for (std::size_t d = digits; d-- > 0;) {
    int nib = 0;
    for (int b = 3; b >= 0; --b) {
      const std::size_t idx = d * 4 + b;
      nib = nib * 2 + (idx < total && v[idx] ? 1 : 0);
    }
    hex += "0123456789abcdef"[nib];
  }
  return std::to_string(total) + "'h" + hex;
}

namespace {

void check_family_size(const std::string& name, int chips, int codes) {
  if (chips > 63) {
    throw InputError("family: " + name + " has codes of " + std::to_string(chips) +
                     " chips, which the hardware does not support; valid range is [1, 63]");
  }
  if (codes > 63) {
    throw InputError("family: " + name + " has " + std::to_string(codes) +
                     " codes, which the hardware does not support; valid range is [1, 63]");
  }
}

}  // namespace

void check_generatable(const ReceiverConfig& config) {
  const CodeFamily f = code_family(config.family);
  check_family_size(f.name, f.length, f.eta());
}

void check_generatable(const ReceiverDesign& d) {
  const auto& l = d.layout;
  const auto& b = d.config.bandpass;
  if (b.acc_bits > 64) throw InputError("bandpass_fixed.acc_bits: hardware supports at most 64");
  if (l.fir_bits > 63) throw InputError("correlator_fixed: chip filter accumulator above 63 bits");
  check_family_size(d.family.name, l.chips, l.codes);
}

std::vector<HwModuleParams> hardware_parameters(const ReceiverDesign& d) {
  check_generatable(d);
  const ReceiverConfig& c = d.config;
  const CorrelatorFixedLayout& l = d.layout;
  const BandpassFixedLayout bp = resolve_bandpass_layout(d.filter, c.bandpass);
  std::vector<HwModuleParams> out;

  HwModuleParams sos{"bandpass_sos", {}};
  const std::vector<std::int64_t> coefs = bp.flat();
  sos.params = {scalar("SECTIONS", static_cast<std::int64_t>(bp.sections())),
                scalar("IN_W", c.bandpass.input_bits),
                scalar("DATA_W", c.bandpass.data_bits),
                scalar("DATA_FRAC", c.bandpass.data_frac),
                scalar("COEF_W", c.bandpass.coef_bits),
                scalar("COEF_FRAC", c.bandpass.coef_frac),
                scalar("ACC_W", c.bandpass.acc_bits),
                scalar("ROUNDING", rounding_code(c.bandpass.rounding)),
                scalar("SATURATE", c.bandpass.overflow == Overflow::Saturate ? 1 : 0),
                packed("COEFS", coefs, c.bandpass.coef_bits),
                // clocks per input sample: how many sections share a multiplier
                scalar("SAMPLE_CYCLES", c.sample_cycles())};
  out.push_back(sos);

  const int time_w = c.system.time_w;  // system.time_w
  HwModuleParams bank{"correlator_bank", {}};
  std::vector<std::int64_t> code_bits;  // one element per code: bit m = chip m
  std::vector<std::int64_t> chips_flat;
  for (const auto& code : d.family.codes) {
    for (auto chip : code) chips_flat.push_back(chip);
  }
  bank.params = {scalar("DATA_W", c.correlator.data_bits),
                 scalar("DATA_FRAC", c.correlator.data_frac),
                 scalar("PERIOD", l.period),
                 scalar("LO_W", c.correlator.lo_bits),
                 scalar("MIX_W", c.correlator.mix_bits),
                 scalar("MIX_FRAC", l.mix_frac),
                 scalar("MIX_SHIFT", l.mix_shift),
                 scalar("DECIM", l.decimation),
                 scalar("DEC_W", l.dec_bits),
                 scalar("TAPS", l.taps),
                 scalar("TAP_W", c.correlator.tap_bits),
                 scalar("FIR_W", l.fir_bits),
                 scalar("CHIP_W", c.correlator.chip_bits),
                 scalar("CHIP_SHIFT", l.chip_shift),
                 scalar("CHIPS", l.chips),
                 scalar("CODES", l.codes),
                 scalar("CHIP_STEP", l.chip_samples / l.decimation),
                 scalar("COMB_W", l.comb_bits),
                 scalar("CORR_W", c.correlator.corr_bits),
                 scalar("CORR_SHIFT", l.corr_shift),
                 scalar("POWER_W", l.power_bits),
                 scalar("WEIGHT_W", c.correlator.weight_bits),
                 scalar("WEIGHTED_W", l.weighted_bits),
                 scalar("WINDOW", l.window),
                 scalar("ENERGY_W", l.energy_bits),
                 scalar("TIME_W", time_w),
                 packed("LO_COS", l.lo_cos, c.correlator.lo_bits),
                 packed("LO_SIN", l.lo_sin, c.correlator.lo_bits),
                 packed("TAP_VALUES", l.taps_q, c.correlator.tap_bits),
                 packed("CODE_BITS", chips_flat, 1),
                 packed("WEIGHTS", l.weights, c.correlator.weight_bits),
                 scalar("CODE_W", bits_for(l.codes))};  // m_code: j of the beat, 0-based
  out.push_back(bank);

  const PeakDetectorFixedLayout det = resolve_detector_layout(c.detector, l, c.correlator);
  HwModuleParams pd{"peak_detector", {}};
  pd.params = {scalar("CODES", l.codes),
               scalar("WEIGHTED_W", l.weighted_bits),
               scalar("ENERGY_W", l.energy_bits),
               scalar("ENERGY_SHIFT", l.energy_shift),
               scalar("SCORE_W", c.correlator.score_bits),
               scalar("FRAC_W", c.detector.frac_bits),
               scalar("DECIM", l.decimation),
               scalar("TIME_W", time_w),
               scalar("HOLDOFF", det.holdoff),
               packed("THRESHOLD", {static_cast<std::int64_t>(det.threshold_q)}, c.correlator.score_bits),
               packed("MIN_NORM", {static_cast<std::int64_t>(det.min_norm_q)}, l.energy_bits),
               scalar("CODE_W", bits_for(l.codes))};
  out.push_back(pd);
  return out;
}

}  // namespace ranging
