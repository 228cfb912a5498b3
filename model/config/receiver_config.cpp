#include "model/config/receiver_config.hpp"

#include <fstream>
#include <sstream>

#include "model/base/error.hpp"
#include "model/base/input_file.hpp"
#include "model/base/names.hpp"
#include "model/config/yaml_reader.hpp"

namespace ranging {

namespace {

using yaml::Reader;
using yaml::section;

constexpr NameTable<Rounding, 3> kRoundings{{
    {Rounding::Truncate, "truncate"}, {Rounding::RoundHalfUp, "round-half-up"}, {Rounding::Convergent, "convergent"}}};
constexpr NameTable<Overflow, 2> kOverflows{{{Overflow::Wrap, "wrap"}, {Overflow::Saturate, "saturate"}}};

// The value of a name in the table; else an error naming the key and the valid names.
template <class E, std::size_t N>
E parse_name(Reader& r, const std::string& k, const std::string& s, const NameTable<E, N>& table) {
  if (const auto v = value_of(table, s)) return *v;
  r.error(k, "'" + s + "' is not valid; valid: " + names_list(table));
}

}  // namespace

namespace {

ReceiverConfig parse_document(YAML::Node root, const std::string& origin, bool allow_out_of_spec) {
  ReceiverConfig cfg;
  cfg.allow_out_of_spec = allow_out_of_spec;
  if (!root || root.IsNull()) throw InputError(origin + ": the configuration is empty");
  Reader top(root, origin, "");
  top.get("name", cfg.name);
  top.get("family", cfg.family);
  top.get("architecture", cfg.architecture);
  section(top, "signal", [&](Reader& r) {
    r.get("carrier_hz", cfg.carrier_hz);
    r.get("cycles_per_chip", cfg.cycles_per_chip);
    r.get("fs", cfg.fs);
  });
  std::string type = filter_type_name(cfg.filter_type);
  section(top, "filter", [&](Reader& r) {
    r.get("type", type);
    r.get("order", cfg.filter_order);
    r.get("structure", cfg.filter_structure);
    r.get("fp1", cfg.filter.fp1);
    r.get("fp2", cfg.filter.fp2);
    r.get("fs1", cfg.filter.fs1);
    r.get("fs2", cfg.filter.fs2);
    r.get("rp_db", cfg.filter.rp_db);
    r.get("rs_db", cfg.filter.rs_db);
    try {
      cfg.filter_type = parse_filter_type(type);
    } catch (const InputError&) {
      r.error("type", "'" + type + "' is not valid; valid: butter, cheby1, ellip");
    }
  });
  cfg.filter.fs = cfg.fs;
  section(top, "bandpass_fixed", [&](Reader& r) {
    auto& b = cfg.bandpass;
    r.get("input_bits", b.input_bits);
    r.get("coef_bits", b.coef_bits);
    r.get("coef_frac", b.coef_frac);
    r.get("data_bits", b.data_bits);
    r.get("data_frac", b.data_frac);
    r.get("acc_bits", b.acc_bits);
    std::string rnd = name_of(kRoundings, b.rounding), ovf = name_of(kOverflows, b.overflow);
    r.get("rounding", rnd);
    r.get("overflow", ovf);
    b.rounding = parse_name(r, "rounding", rnd, kRoundings);
    b.overflow = parse_name(r, "overflow", ovf, kOverflows);
  });
  section(top, "correlator", [&](Reader& r) {
    r.get("reference", cfg.reference);
    r.get("transducer_centre_hz", cfg.reference_transducer.centre_hz);
    r.get("transducer_q", cfg.reference_transducer.q);
    r.get("decimation", cfg.decimation);
    r.get("template_floor", cfg.template_floor);
  });
  section(top, "correlator_fixed", [&](Reader& r) {
    auto& c = cfg.correlator;
    r.get("lo_bits", c.lo_bits);
    r.get("mix_bits", c.mix_bits);
    r.get("tap_bits", c.tap_bits);
    r.get("chip_bits", c.chip_bits);
    r.get("corr_bits", c.corr_bits);
    r.get("weight_bits", c.weight_bits);
    r.get_auto("corr_shift", c.corr_shift);
    r.get_auto("energy_shift", c.energy_shift);
    r.get("score_bits", c.score_bits);
  });
  section(top, "detector", [&](Reader& r) {
    auto& d = cfg.detector;
    r.get("threshold", d.threshold);
    r.get_auto("holdoff", d.holdoff);
    r.get("min_energy", d.min_energy);
    r.get("frac_bits", d.frac_bits);
  });
  section(top, "hardware", [&](Reader& r) { r.get("clock_hz", cfg.clock_hz); });
  section(top, "system", [&](Reader& r) {
    auto& s = cfg.system;
    r.get("speed_of_sound", s.speed_of_sound);
    r.get("max_range_m", s.max_range_m);
    r.get("baud", s.baud);
    r.get("calibration_distance_m", s.calibration_distance_m);
    r.get("time_w", s.time_w);
    r.get("off_w", s.off_w);
    r.get("c_frac", s.c_frac);
  });
  top.finish();
  cfg.correlator.data_bits = cfg.bandpass.data_bits;
  cfg.correlator.data_frac = cfg.bandpass.data_frac;
  try {
    validate(cfg);
    (void)design_receiver(cfg);  // every derived bound is checked too
  } catch (const InputError& e) {
    throw InputError(yaml::locate(root, origin, e.what()));
  }
  return cfg;
}

}  // namespace

ReceiverConfig parse_receiver_config(const std::string& yaml_text, const std::string& origin,
                                     const Overrides& overrides, bool allow_out_of_spec) {
  YAML::Node root = yaml::load(yaml_text, origin);
  apply_overrides(root, overrides, origin);
  return with_override_errors(overrides, origin, [&] { return parse_document(root, origin, allow_out_of_spec); });
}

ReceiverConfig default_receiver_config(const Overrides& overrides) {
  if (overrides.empty()) return ReceiverConfig{};
  return parse_receiver_config("", "(built-in default configuration)", overrides);
}

ReceiverConfig load_receiver_config(const std::string& path, const Overrides& overrides, bool allow_out_of_spec) {
  return parse_receiver_config(read_input_file(path, "configuration file", std::size_t{1} << 24), path, overrides,
                               allow_out_of_spec);
}

std::string locate_in_config(const std::string& path, const std::string& message) {
  try {
    const YAML::Node root = yaml::load(read_input_file(path, "configuration file", std::size_t{1} << 24), path);
    return yaml::locate(root, path, message);
  } catch (const std::exception&) {
    return path + ": " + message;
  }
}

std::string receiver_config_yaml(const ReceiverConfig& c) {
  auto autoint = [](int v) { return v < 0 ? std::string("auto") : std::to_string(v); };
  std::ostringstream os;
  os.precision(17);
  os << "# Receiver configuration (docs/configuration.md): the single source of truth for the\n"
        "# golden model and the generated HLS C++ and Verilog.\n";
  os << "name: " << c.name << "\nfamily: " << c.family << "\narchitecture: " << c.architecture << "\n";
  os << "signal:\n  carrier_hz: " << c.carrier_hz << "\n  cycles_per_chip: " << c.cycles_per_chip
     << "\n  fs: " << c.fs << "\n";
  os << "filter:\n  type: " << filter_type_name(c.filter_type) << "\n  order: " << c.filter_order
     << "\n  fp1: " << c.filter.fp1 << "\n  fp2: " << c.filter.fp2 << "\n  fs1: " << c.filter.fs1
     << "\n  fs2: " << c.filter.fs2 << "\n  rp_db: " << c.filter.rp_db << "\n  rs_db: " << c.filter.rs_db
     << "\n";
  const auto& b = c.bandpass;
  os << "bandpass_fixed:\n  input_bits: " << b.input_bits << "\n  coef_bits: " << b.coef_bits
     << "\n  coef_frac: " << b.coef_frac << "\n  data_bits: " << b.data_bits << "\n  data_frac: "
     << b.data_frac << "\n  acc_bits: " << b.acc_bits << "\n  rounding: " << name_of(kRoundings, b.rounding)
     << "\n  overflow: " << name_of(kOverflows, b.overflow) << "\n";
  os << "correlator:\n  reference: " << c.reference << "\n  transducer_centre_hz: "
     << c.reference_transducer.centre_hz << "\n  transducer_q: " << c.reference_transducer.q
     << "\n  decimation: " << c.decimation << "\n  template_floor: " << c.template_floor << "\n";
  const auto& k = c.correlator;
  os << "correlator_fixed:\n  lo_bits: " << k.lo_bits << "\n  mix_bits: " << k.mix_bits
     << "\n  tap_bits: " << k.tap_bits << "\n  chip_bits: " << k.chip_bits
     << "\n  corr_bits: " << k.corr_bits << "\n  weight_bits: " << k.weight_bits
     << "\n  corr_shift: " << autoint(k.corr_shift)
     << "\n  energy_shift: " << autoint(k.energy_shift) << "\n  score_bits: " << k.score_bits << "\n";
  const auto& d = c.detector;
  os << "detector:\n  threshold: " << d.threshold << "\n  holdoff: " << autoint(d.holdoff)
     << "\n  min_energy: " << d.min_energy << "\n  frac_bits: " << d.frac_bits << "\n";
  os << "hardware:\n  clock_hz: " << c.clock_hz << "\n";
  const auto& s = c.system;
  os << "system:\n  speed_of_sound: " << s.speed_of_sound << "\n  max_range_m: " << s.max_range_m
     << "\n  baud: " << s.baud << "\n  calibration_distance_m: " << s.calibration_distance_m
     << "\n  time_w: " << s.time_w << "\n  off_w: " << s.off_w << "\n  c_frac: " << s.c_frac << "\n";
  return os.str();
}

}  // namespace ranging
