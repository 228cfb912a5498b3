#include "model/config/ice40_pll.hpp"
#include "model/config/receiver_config.hpp"
#include "model/sim/scene.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "model/dsp/codes.hpp"
#include "model/sim/capture.hpp"
#include "model/base/error.hpp"
#include "model/base/input_file.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/stability.hpp"
#include "model/config/yaml_reader.hpp"

namespace ranging {

double Scene::speed() const {
  if (medium.speed_of_sound) return *medium.speed_of_sound;
  if (medium.air) return speed_of_sound(*medium.air);
  return 340.0;  // the paper's value
}

std::vector<std::string> SceneMetrics::names() const {
  std::vector<std::string> v;
  if (pearson) v.push_back("pearson");
  if (energy) v.push_back("energy");
  if (td) v.push_back("td");
  return v;
}

double Scene::receiver_speed() const { return receiver.speed_of_sound.value_or(speed()); }

double Scene::unambiguous_range_m(int eta) const {
  if (excitation.schedule.mode != "periodic") return 0.0;
  return eta * speed() * excitation.schedule.period_s;
}

double Scene::range_l() const {
  if (max_range_m > 0) return max_range_m;
  double l = 0;
  for (double d : geometry.distances_m) l = std::max(l, d);
  return l;
}

namespace {

using yaml::Reader;
using yaml::one_of;
using yaml::section;

// Errors of the configuration's overrides name them as the user wrote them (receiver.config.KEY).
template <class F>
auto config_errors(F&& load) -> decltype(load()) {
  try {
    return load();
  } catch (const InputError& e) {
    std::string m = e.what();
    for (std::size_t at = m.find("--set "); at != std::string::npos; at = m.find("--set ", at + 6)) {
      m.insert(at + 6, "receiver.config.");
    }
    throw InputError(m);
  }
}

// The sections of a scene, one reader each (parse_document calls them in the file's order).

void read_medium(Reader& r, Scene& s) {
  AirConditions a;
  bool any = false;
  any |= r.get_range("temperature_c", a.temperature_c, -40, 60);
  any |= r.get_range("relative_humidity", a.relative_humidity, 0, 100);
  any |= r.get_range("pressure_kpa", a.pressure_kpa, 50, 120);
  if (any) s.medium.air = a;
  double c = 0;
  if (r.get_range("speed_of_sound", c, 100, 10000)) s.medium.speed_of_sound = c;
}

void read_transducers(Reader& r, Scene& s) {
  auto& t = s.transducers;
  t.named = true;
  r.get_range("centre_hz", t.centre_hz, 1e3, 10e6);
  const bool q = r.get_range("q", t.q, 0.1, 1000);
  double bw = 0;
  if (r.get_range("bandwidth_hz", bw, 1.0, 10e6)) {
    if (q) r.error("bandwidth_hz", "give q or bandwidth_hz, not both");
    t.q = t.centre_hz / bw;
    r.check("bandwidth_hz", t.q, 0.1, 1000);
  }
  r.get_range("beam_angle_deg", t.beam_angle_deg, 0.5, 170);
  r.get_range("sensitivity", s.sensitivity, 1e-9, 1e3);
}

void read_geometry(Reader& r, Scene& s) {
  r.get("type", s.geometry.type);
  if (s.geometry.type == "moving") r.error("type", "'moving' geometry is not implemented yet (a later issue); valid: static, rotor");
  one_of(r, "type", s.geometry.type, {"static", "rotor"});
  if (s.geometry.type == "rotor") {
    parse_rotor(r, s.geometry.rotor, s.speed());  // model/sim/rotor.cpp
    return;
  }
  if (!r.get_list("distances_m", s.geometry.distances_m) || s.geometry.distances_m.empty()) {
    r.error("distances_m", "give at least one distance (metres)");
  }
  for (std::size_t i = 0; i < s.geometry.distances_m.size(); ++i) {
    r.check("distances_m", s.geometry.distances_m[i], 0.01, 20.0);
  }
  r.get_range("repeats", s.geometry.repeats, 1, 100000);
  double a = 0;
  if (r.get_range("angle_deg", a, 0, 89)) s.geometry.angle_deg = a;
}

// excitation.family: one name or a list, every one a known family.
void read_families(Reader& r, SceneExcitation& e) {
  if (!r.has("family")) {
    r.child("family");
    return;
  }
  const YAML::Node f = r.node("family");
  if (f.IsSequence()) {
    r.get_list("family", e.families);
  } else {
    std::string one;
    r.get("family", one);
    e.families = {one};
  }
  if (e.families.empty()) r.error("family", "give at least one code family");
  for (const auto& name : e.families) {
    try {
      (void)code_family(name);
    } catch (const InputError& err) {
      r.error("family", err.what());
    }
  }
}

void read_excitation(Reader& r, Scene& s) {
  auto& e = s.excitation;
  read_families(r, e);
  r.get_range("cycles_per_chip", e.cycles_per_chip, 1, 64);
  r.get_range("carrier_hz", e.carrier_hz, 1e3, 10e6);
  section(r, "cycles_per_chip_by_family", [&](Reader& q) {
    // Any family name (a family the scene does not send is harmless); others are unknown keys.
    for (const auto& name : code_family_names()) {
      int v = 0;
      if (q.get_range(name, v, 1, 64)) e.cycles_per_chip_by_family[name] = v;
    }
  });
  r.get_range("drive_vpp", e.drive_vpp, 1e-6, 1e4);
  r.get_range("amplifier_gain", e.amplifier_gain, 1e-6, 1e4);
  if (r.get_list("codes", e.codes)) {
    for (int j : e.codes) {
      for (const auto& name : e.families) {
        const int eta = code_family(name).eta();
        if (j < 1 || j > eta) {
          r.error("codes", std::to_string(j) + " is out of range; family " + name + " has codes 1.." + std::to_string(eta));
        }
      }
    }
  }
  section(r, "schedule", [&](Reader& q) {
    q.get("mode", e.schedule.mode);
    one_of(q, "mode", e.schedule.mode, {"single", "periodic"});
    q.get_range("period_s", e.schedule.period_s, 1e-6, 10.0);
    q.get_range("bursts", e.schedule.bursts, 0, 10000);
    if (e.schedule.mode == "periodic" && e.schedule.period_s <= 0) q.error("period_s", "periodic mode needs period_s");
  });
}

void read_noise(Reader& r, Scene& s) {
  auto& n = s.noise;
  n.named = true;
  double v = 0;
  if (r.get_range("snr_db", v, -40, 200)) n.snr_db = v;
  if (r.get_range("noise_v", v, 0, 1e3)) {
    if (n.snr_db) r.error("noise_v", "give snr_db or noise_v, not both");
    n.noise_v = v;
  }
  long long seed = 1;
  if (r.get_range("seed", seed, 0, 9.0e18)) n.seed = static_cast<std::uint64_t>(seed);
  section(r, "adc", [&](Reader& a) {
    SceneAdc adc;
    a.get_range("bits", adc.bits, 2, 24);
    a.get_range("full_scale_v", adc.full_scale_v, 1e-6, 1e4);
    a.get_range("sample_rate", s.fs, 1e4, 1e9);
    a.get_range("dc_offset_v", adc.dc_offset_v, -1e4, 1e4);
    a.get_range("stuck_bit", adc.stuck_bit, -1, adc.bits - 1);
    a.get_range("stuck_value", adc.stuck_value, 0, 1);
    n.adc = adc;
  });
}

// A relative path of the scene names a file beside it.
std::string beside(const std::string& base_dir, const std::string& path) {
  std::filesystem::path p(path);
  if (p.is_relative()) p = std::filesystem::path(base_dir) / p;
  return p.string();
}

// receiver: its configuration file (or the built-in one under receiver.config overrides) and
// the keys a scene sets on it.
void read_receiver(Reader& r, Scene& s, const std::string& base_dir, const Overrides& config_overrides,
                   bool allow_out_of_spec, bool config_loaded) {
  auto& rc = s.receiver;
  std::string cfg;
  if (r.get("config", cfg)) {
    rc.config = config_errors([&] { return load_receiver_config(beside(base_dir, cfg), config_overrides, allow_out_of_spec); });
    rc.config_file = cfg;
    config_loaded = true;
  }
  if (config_loaded) s.effective_config_yaml = receiver_config_yaml(rc.config);
  std::string type;
  if (r.get("filter_type", type)) {
    try {
      rc.config.filter_type = parse_filter_type(type);
    } catch (const InputError&) {
      r.error("filter_type", "'" + type + "' is not valid; valid: butter, cheby1, ellip");
    }
  }
  r.get_range("filter_order", rc.config.filter_order, 0, 20);
  r.get_range("threshold", rc.config.detector.threshold, 0, 1);
  r.get("precision", rc.precision);
  one_of(r, "precision", rc.precision, {"float", "fixed"});
  r.get("reference", rc.reference);
  one_of(r, "reference", rc.reference, {"received", "ideal", "files"});
  if (r.get("references_dir", rc.references_dir)) rc.references_dir = beside(base_dir, rc.references_dir);
  if (rc.reference == "files" && rc.references_dir.empty()) r.error("reference", "'files' needs references_dir");
  r.get_range("full_scale_v", rc.full_scale_v, 1e-6, 1e4);
  r.get_range("calibration_distance_m", rc.calibration_distance_m, 0.01, 20);
  double c = 0;
  if (r.get_range("speed_of_sound", c, 100, 10000)) rc.speed_of_sound = c;
  std::vector<std::string> metrics;
  if (r.get_list("metrics", metrics)) {
    rc.metrics = {false, false, false};
    for (std::size_t i = 0; i < metrics.size(); ++i) {
      const std::string& m = metrics[i];
      bool* flag = m == "pearson" ? &rc.metrics.pearson : m == "energy" ? &rc.metrics.energy
                                                        : m == "td"     ? &rc.metrics.td : nullptr;
      const std::string at = "metrics[" + std::to_string(i) + "]";
      if (!flag) r.error("metrics", at + ": '" + m + "' is not valid; valid: pearson, energy, td (or [] for none)");
      if (*flag) r.error("metrics", at + ": '" + m + "' is listed twice");
      *flag = true;
    }
  }
}

// The receiver follows the excitation and the sample rate; the combination is checked now so a
// bad scene fails at load time, naming the file.
void derive_receiver_config(Scene& s, const YAML::Node& root, const std::string& origin, bool allow_out_of_spec) {
  auto& rc = s.receiver.config;
  // A configuration file's signal keys give way to the scene's (the receiver runs on the
  // scene's ADC stream): said in a warning when they differ, so no setting is dropped quietly.
  if (!s.receiver.config_file.empty()) {
    std::ostringstream os;
    os.precision(9);
    auto differs = [](double a, double b) { return std::abs(a - b) > 1e-9 * std::abs(b); };
    if (differs(rc.fs, s.fs)) os << ", signal.fs " << rc.fs / 1e6 << " MS/s -> sample_rate " << s.fs / 1e6 << " MS/s";
    if (differs(rc.carrier_hz, s.excitation.carrier_hz)) {
      os << ", signal.carrier_hz " << rc.carrier_hz << " -> excitation.carrier_hz " << s.excitation.carrier_hz;
    }
    if (rc.cycles_per_chip != s.excitation.cycles_per_chip) {
      os << ", signal.cycles_per_chip " << rc.cycles_per_chip << " -> excitation.cycles_per_chip "
         << s.excitation.cycles_per_chip;
    }
    if (!os.str().empty()) {
      s.warnings.push_back(s.origin + ": the scene's values replace receiver.config " + s.receiver.config_file + "'s" +
                           os.str().substr(1));
    }
  }
  rc.carrier_hz = s.excitation.carrier_hz;
  rc.cycles_per_chip = s.excitation.cycles_per_chip;
  rc.fs = s.fs;
  rc.filter.fs = s.fs;
  // The hardware clock (the RTL's: clock_hz / fs clocks per sample, an integer) follows the
  // sample rate too: a scene rate that does not divide the configuration's clock (4, 4.8 or 20
  // MS/s into 30 MHz) gets the next multiple of it that the system can run at (the board's PLL
  // makes it exactly and system.baud divides it, so the RTL and the bitstream flow accept it;
  // else the next multiple), said in a warning. The model's results do not depend on the clock.
  if (rc.fs > kMaxClockHz) {  // one sample per clock at most, and the clock is at most kMaxClockHz
    std::ostringstream os;
    os.precision(9);
    os << "sample_rate: " << rc.fs / 1e6 << " MS/s is above what the receiver takes (" << kMaxClockHz / 1e6
       << " MS/s: one sample per clock of at most " << kMaxClockHz / 1e6 << " MHz, hardware.clock_hz); "
       << "decimate the signal first (the paper's 5 MS/s is 25 samples per carrier cycle)";
    throw InputError(yaml::locate(root, origin, os.str()));
  }
  if (const double per = rc.clock_hz / rc.fs;
      per > 0 && std::abs(per - std::round(per)) > 1e-9 * per && std::ceil(per) * rc.fs <= kMaxClockHz) {
    double k = std::ceil(per);
    bool system_ok = false;
    for (double m = k; m * rc.fs <= 275e6 && !system_ok; ++m) {  // the iCE40 PLL's output tops out below 275 MHz
      const double clk = m * rc.fs, div = clk / rc.system.baud;
      if (find_ice40_pll(kBoardOscillatorHz, clk) && div >= 2 && std::abs(div - std::round(div)) <= 1e-9 * div) {
        k = m;
        system_ok = true;
      }
    }
    std::ostringstream os;
    os.precision(9);
    os << s.origin << ": sample_rate: " << s.fs / 1e6 << " MS/s does not divide the receiver's hardware.clock_hz ("
       << rc.clock_hz / 1e6 << " MHz); the receiver's clock is " << k * rc.fs / 1e6 << " MHz (" << k
       << " clocks per sample"
       << (system_ok ? ", the next multiple of the sample rate that the board's PLL makes and system.baud divides)"
                     : "; no multiple up to 275 MHz is one that the board's PLL makes and system.baud divides: "
                       "the RTL and the bitstream need a hardware.clock_hz that is)");
    s.warnings.push_back(os.str());
    s.moved_clock_from_hz = rc.clock_hz;
    rc.clock_hz = k * rc.fs;
  }
  rc.family = s.excitation.families.front();
  if (s.receiver.reference != "files") rc.reference = s.receiver.reference;
  rc.reference_transducer.centre_hz = s.transducers.centre_hz;
  rc.reference_transducer.q = s.transducers.q;
  fit_decimation_to_chip(rc);  // also per family in SceneSimulator (q_of)
  rc.allow_out_of_spec = allow_out_of_spec;
  try {
    validate(rc);
    enforce_quantized_design(rc);  // the filter at the scene's sample rate
    validate(TransducerParams{s.transducers.centre_hz, s.transducers.q, false}, s.fs);
    ExcitationParams ex{s.excitation.carrier_hz, s.excitation.cycles_per_chip, s.fs, 1.0};
    validate(ex);
  } catch (const InputError& e) {
    throw InputError(yaml::locate(root, origin, e.what()));
  }
}

// A periodic schedule whose largest distance reaches a family's unambiguous range (eq. 3) is
// a warning: those measurements alias.
void warn_unambiguous_range(Scene& s) {
  if (s.excitation.schedule.mode != "periodic") return;
  double dmax = 0;
  for (double d : s.geometry.distances_m) dmax = std::max(dmax, d);
  for (const auto& name : s.excitation.families) {
    const int eta = code_family(name).eta();
    const double ru = s.unambiguous_range_m(eta);
    if (dmax >= ru * (1.0 - 1e-9)) {
      std::ostringstream os;
      os << s.origin << ": geometry.distances_m: the largest distance " << dmax << " m reaches the unambiguous range "
         << "eta*c*T = " << eta << " * " << s.speed() << " m/s * " << s.excitation.schedule.period_s << " s = " << ru
         << " m of " << name << " (eq. 3): measurements at or beyond it alias and count as range-ambiguous errors";
      s.warnings.push_back(os.str());
    }
  }
}

// The effective scene document: paths made absolute (the configuration goes beside it).
void keep_effective_document(Scene& s, const YAML::Node& root) {
  s.effective_document = YAML::Clone(root);
  YAML::Node eff = s.effective_document;
  if (eff["receiver"] && eff["receiver"].IsMap() && eff["receiver"]["references_dir"] &&
      !s.receiver.references_dir.empty()) {
    eff["receiver"]["references_dir"] = std::filesystem::absolute(s.receiver.references_dir).string();
  }
}

Scene parse_document(YAML::Node root, const std::string& origin, const std::string& base_dir,
                     const Overrides& config_overrides, bool allow_out_of_spec) {
  if (!root || root.IsNull()) throw InputError(origin + ": the scene is empty (it needs at least geometry.distances_m)");
  Scene s;
  s.origin = origin;
  Reader top(root, origin, "");
  top.get("name", s.name);
  top.get_range("max_range_m", s.max_range_m, 0.0, 1000.0);
  top.get_range("sample_rate", s.fs, 1e4, 1e9);
  section(top, "medium", [&](Reader& r) { read_medium(r, s); });
  section(top, "transducers", [&](Reader& r) { read_transducers(r, s); });
  if (!section(top, "geometry", [&](Reader& r) { read_geometry(r, s); })) {
    throw InputError(origin + ": geometry: missing; a scene needs at least geometry.distances_m");
  }
  section(top, "excitation", [&](Reader& r) { read_excitation(r, s); });
  section(top, "noise", [&](Reader& r) { read_noise(r, s); });

  // receiver.config overrides without a receiver.config file: the built-in configuration.
  bool config_loaded = false;
  const YAML::Node& croot = root;  // const: looking a key up does not add it
  const bool names_config = croot["receiver"] && croot["receiver"].IsMap() && croot["receiver"]["config"];
  if (!names_config && !config_overrides.empty()) {
    s.receiver.config = config_errors([&] { return default_receiver_config(config_overrides); });
    s.effective_config_yaml = receiver_config_yaml(s.receiver.config);
    config_loaded = true;
  }
  section(top, "receiver", [&](Reader& r) {
    read_receiver(r, s, base_dir, config_overrides, allow_out_of_spec, config_loaded);
  });
  section(top, "compensation", [&](Reader& r) {
    SceneCompensation comp;
    r.get_range("reference_distance_m", comp.reference_distance_m, 0.01, 20);
    s.compensation = comp;
  });
  top.finish();
  if (s.geometry.type == "rotor") check_rotor_scene(s);  // model/sim/rotor.cpp

  derive_receiver_config(s, root, origin, allow_out_of_spec);
  warn_unambiguous_range(s);
  keep_effective_document(s, root);
  return s;
}

}  // namespace

Scene parse_scene(const std::string& text, const std::string& origin, const std::string& base_dir,
                  const Overrides& overrides, bool allow_out_of_spec) {
  YAML::Node root = yaml::load(text, origin);
  const Overrides scene_overrides = overrides_not_under(overrides, "receiver.config");
  const Overrides config_overrides = overrides_under(overrides, "receiver.config");
  apply_overrides(root, scene_overrides, origin);
  return with_override_errors(scene_overrides, origin,
                              [&] { return parse_document(root, origin, base_dir, config_overrides, allow_out_of_spec); });
}

Scene load_scene(const std::string& path, const Overrides& overrides, bool allow_out_of_spec) {
  const std::string text = read_input_file(path, "scene file", std::size_t{1} << 24);
  const std::string dir = std::filesystem::path(path).parent_path().string();
  return parse_scene(text, path, dir.empty() ? "." : dir, overrides, allow_out_of_spec);
}

std::string effective_scene_yaml(const Scene& scene, const std::string& config_file) {
  YAML::Node eff = YAML::Clone(scene.effective_document);
  if (!eff || !eff.IsMap()) eff = YAML::Node(YAML::NodeType::Map);
  const bool has_config = !scene.effective_config_yaml.empty();
  if (has_config) {
    if (!eff["receiver"] || !eff["receiver"].IsMap()) eff["receiver"] = YAML::Node(YAML::NodeType::Map);
    eff["receiver"]["config"] = config_file;
  }
  return "# Effective scene: " + scene.origin + " with its overrides; receiver configuration: " +
         (has_config ? config_file + " beside this file" : std::string("built-in")) + "\n" + emit_yaml(eff);
}

std::vector<std::string> write_effective_scene(const Scene& scene, const std::string& dir, const std::string& prefix) {
  std::vector<std::string> out{dir + "/" + prefix + "scene.yaml"};
  write_file_atomic(out[0], effective_scene_yaml(scene, prefix + "config.yaml"));
  if (!scene.effective_config_yaml.empty()) {
    out.push_back(dir + "/" + prefix + "config.yaml");
    write_file_atomic(out[1], scene.effective_config_yaml);
  }
  return out;
}

}  // namespace ranging
