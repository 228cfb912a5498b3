#pragma once
// A scene: what the user wants simulated (docs/scenes.md). Every section but geometry is
// optional, and a stage of the channel exists only when the scene names what it needs
// (model/sim/scene_simulator.hpp). The loader is strict: unknown keys, wrong types and
// out-of-range values are InputErrors naming "file:line: field".
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "model/config/overrides.hpp"
#include "model/sim/medium.hpp"
#include "model/dsp/receiver.hpp"
#include "model/sim/rotor.hpp"

namespace ranging {

struct SceneMedium {
  std::optional<AirConditions> air;        // temperature/humidity/pressure: absorption stage
  std::optional<double> speed_of_sound;    // fixed c (overrides the one computed from air)
};

struct SceneTransducers {
  double centre_hz = 200e3;
  double q = 7.5;                 // or bandwidth_hz = centre_hz / q
  double beam_angle_deg = 14.5;   // full -3 dB beam angle (piston directivity)
  bool named = false;             // the scene has a transducers section: resonator stage
};

// Pitch-catch sensitivity: received volts per transmitted volt on axis at 0.1 m at the
// centre frequency. Applies with or without the transducers section (the ideal link keeps
// the level), calibrated in docs/scenes.md against Table 4's M1 energy.
inline constexpr double kDefaultSensitivity = 0.02;

struct SceneGeometry {
  std::string type = "static";           // static | rotor (model/sim/rotor.hpp)
  std::vector<double> distances_m;       // line of sight TX-RX, m
  int repeats = 1;
  std::optional<double> angle_deg;       // off-axis angle of both transducers: directivity stage
  RotorParams rotor;                     // type rotor: the coaxial rotor and its crossings
};

struct SceneSchedule {
  std::string mode = "single";  // single: one burst per measurement; periodic: a train
  double period_s = 0;          // periodic: burst period T
  int bursts = 0;               // periodic: bursts per train (0: eta, every code once)
};

struct SceneExcitation {
  std::vector<std::string> families = {"Gold4"};
  int cycles_per_chip = 4;      // q
  std::map<std::string, int> cycles_per_chip_by_family;  // q overrides (the paper: M3/M4 at q = 2)
  int q_of(const std::string& family) const {
    const auto it = cycles_per_chip_by_family.find(family);
    return it != cycles_per_chip_by_family.end() ? it->second : cycles_per_chip;
  }
  double carrier_hz = 200e3;
  double drive_vpp = 5.0;       // signal generator, Vpp
  double amplifier_gain = 10.0; // V/V
  std::vector<int> codes;       // 1-based j to send; empty: all of the family
  SceneSchedule schedule;
  double amplitude() const { return drive_vpp / 2.0 * amplifier_gain; }
};

// The ADC: code = clamp(round((v + dc_offset_v) / q), -2^(bits-1), 2^(bits-1) - 1),
// q = full_scale_v / 2^(bits-1); the output is code * q volts. Samples whose rounded code lay
// outside the range are clipped and counted (Measurement::adc_clipped). A stuck bit (a fault):
// bit stuck_bit (0 = LSB .. bits-1 = sign) of the two's-complement code is forced to
// stuck_value after clipping.
struct SceneAdc {
  int bits = 12;
  double full_scale_v = 1.0;   // +-full_scale_v maps to the code range; beyond clips
  double dc_offset_v = 0.0;    // fault: DC offset added at the ADC input
  int stuck_bit = -1;          // fault: -1 none, else the stuck bit's index
  int stuck_value = 0;         // 0 or 1
};

struct SceneNoise {
  bool named = false;
  std::optional<double> snr_db;   // vs the mean square of the noise-free burst over its T_d
  std::optional<double> noise_v;  // or an absolute rms, volts
  std::uint64_t seed = 1;
  std::optional<SceneAdc> adc;    // ADC stage
};

// The paper's metrics computed per measurement (receiver.metrics: a list of pearson, energy,
// td; all three by default, [] for none). pearson: rho (eq. 9) and u (eq. 10) by the matched
// filter over +-L chips, and the Pearson decoder's errors; energy: the burst window's V^2;
// td: T_d (section 2.2) and v_max from it. A metric not named is not computed (NaN / null in
// the outputs), and with none the float bandpass that feeds them does not run either: the
// receiver's decode, ToF and distance are all that is modelled.
struct SceneMetrics {
  bool pearson = true, energy = true, td = true;
  bool any() const { return pearson || energy || td; }
  bool all() const { return pearson && energy && td; }
  std::vector<std::string> names() const;  // the ones computed, in that order
};

struct SceneReceiver {
  ReceiverConfig config;            // family/q/carrier/fs follow the excitation and the scene
  std::string config_file;          // the receiver.config file it was read from ("": built in)
  std::string precision = "float";  // float | fixed
  std::string reference = "received";  // received | ideal | files (Pearson templates)
  std::string references_dir;       // reference = files
  double full_scale_v = 1.0;        // receiver input scale without an ADC stage
  double calibration_distance_m = 0.1;
  // The c the receiver converts ToF to distance with (receiver.speed_of_sound); unset: the
  // channel's c (Scene::speed()). With compensation it is replaced by each measurement's c_est.
  std::optional<double> speed_of_sound;
  SceneMetrics metrics;
};

// Sound-velocity compensation (paper section 3.1, issue 14 section 6): with every measurement
// the system also sends a burst (the same code) over a reference path of calibrated length
// d_ref through the same channel (same c, noise and ADC, its own noise draw), and measures its
// one-way time of flight tof_ref with the same receiver. Then
//   c_est = d_ref / tof_ref,   d = c_est * tof.
// The RTL's tof_distance speed register takes the same c_est (the loop helper wires it).
struct SceneCompensation {
  double reference_distance_m = 0.1;
};

struct Scene {
  std::string name = "scene";
  std::string origin;               // file the scene came from
  double fs = 5e6;                  // simulation = ADC sample rate (sample_rate, adc.sample_rate)
  SceneMedium medium;
  SceneTransducers transducers;
  double sensitivity = kDefaultSensitivity;
  SceneGeometry geometry;
  SceneExcitation excitation;
  SceneNoise noise;
  SceneReceiver receiver;
  std::optional<SceneCompensation> compensation;  // compensation: {reference_distance_m: D}
  double max_range_m = 0;           // L of eq. 3/4 (0: the largest distance)
  // The effective documents (after --set overrides), written next to every output so a run can
  // be repeated: the scene refers to its receiver configuration as "config.yaml" beside it.
  YAML::Node effective_document;       // the scene document, paths made absolute
  std::string effective_config_yaml;   // empty: the scene uses the built-in configuration

  double speed() const;             // c of the channel (and the receiver's calibration)
  double receiver_speed() const;    // c the receiver assumes: receiver.speed_of_sound, else speed()
  double range_l() const;
  // Periodic schedule: eta * c * T, the largest distance that does not alias (eq. 3); 0 in
  // single mode (every burst alone in its stream: no ambiguity).
  double unambiguous_range_m(int eta) const;
  // Warnings found at load (the tools print them on stderr): a periodic scene whose largest
  // distance reaches the unambiguous range eta * c * T of a family; a receiver clock moved to a
  // multiple of sample_rate.
  std::vector<std::string> warnings;
  // The configuration's hardware.clock_hz when it did not divide by sample_rate and the
  // receiver's clock was moved to the next multiple (receiver.config.clock_hz); a sweep refuses
  // such a point, whose requested clock would not be the one evaluated.
  std::optional<double> moved_clock_from_hz;
};

// overrides (--set KEY=VALUE, model/config/overrides.hpp) apply to the scene document before it
// is parsed; keys under "receiver.config." apply to the receiver configuration the scene
// references (or to the built-in one), e.g. receiver.config.correlator_fixed.chip_bits=18.
// allow_out_of_spec: accept a receiver whose quantized filter is unstable or out of spec
// (model/dsp/stability.hpp; refused otherwise, naming the file).
Scene load_scene(const std::string& path, const Overrides& overrides = {}, bool allow_out_of_spec = false);
// origin names the file in errors; base_dir resolves relative paths (receiver.config, ...).
Scene parse_scene(const std::string& yaml_text, const std::string& origin, const std::string& base_dir = ".",
                  const Overrides& overrides = {}, bool allow_out_of_spec = false);
// The effective scene as YAML text, its receiver.config naming config_file (when it has one).
std::string effective_scene_yaml(const Scene& scene, const std::string& config_file = "config.yaml");
// Writes DIR/<prefix>scene.yaml and, if the scene has a configuration, DIR/<prefix>config.yaml
// (atomically); returns the paths written.
std::vector<std::string> write_effective_scene(const Scene& scene, const std::string& dir,
                                               const std::string& prefix = "");

}  // namespace ranging
