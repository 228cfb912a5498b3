// `ranging decode CAPTURE --family NAME`: decode a recorded received signal (an oscilloscope
// CSV export or a WAV file, model/sim/capture.hpp) with the receiver and the paper's Pearson
// decoder; print every received burst: code j, ToF, distance, rho_max, u.
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "model/sim/capture.hpp"
#include "model/dsp/codes.hpp"
#include "model/base/error.hpp"
#include "model/sim/medium.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/json_meta.hpp"

namespace ranging::tool {

int cmd_decode(const Args& args) {
  cli::Parser p("ranging decode",
                "Decode a capture: oscilloscope CSV (header lines, then rows 'time_s,volts') or WAV\n"
                "(16/24-bit PCM, 32-bit float), t = 0 at the start of transmission of the first\n"
                "burst. The receiver (bandpass, correlator bank, peak detector) adapts to the file's\n"
                "sample rate (it must be an integer multiple of the 200 kHz carrier); its latency and\n"
                "the Pearson references are simulated with the calibrated transducers (docs/scenes.md)\n"
                "unless --references gives recorded ones (DIR/<family>-<j>.csv or .wav).");
  p.positional("CAPTURE", "capture file (.csv or .wav)");
  p.option("--family", "NAME", "code family the transmitter used (ranging codes --list)");
  p.option("--references", "DIR", "recorded reference bursts DIR/<family>-<j>.csv|.wav for the Pearson decoder");
  p.option("--speed-of-sound", "M/S", "speed of sound, 100..10000 (default 340)");
  p.option("--temperature", "C", "air temperature -40..60 C: speed of sound at 50 % RH, 101.325 kPa");
  p.option("--period", "S", "bursts were sent every S seconds, codes 1..eta in turn (default: one burst per code, all at t = 0)");
  p.option("--min-rho", "R", "report bursts whose Pearson rho_max (eq. 9) is at least R, 0..1 (noise triggers score lower)", "0.7");
  p.flag("--json", "machine-readable output");
  if (!p.parse(args)) return 0;
  if (!p.has("--family")) throw InputError("option --family: required (ranging codes --list)");
  const std::string family = *p.get("--family");
  try {
    (void)code_family(family);
  } catch (const InputError& e) {
    throw InputError(std::string("option --family: ") + e.what());
  }
  if (p.has("--speed-of-sound") && p.has("--temperature")) {
    throw InputError("options --speed-of-sound and --temperature: give one, not both");
  }
  double c = p.number("--speed-of-sound", 340, 100, 10000);
  if (p.has("--temperature")) {
    AirConditions a;
    a.temperature_c = p.number("--temperature", 20, -40, 60);
    c = speed_of_sound(a);
  }
  const double period = p.number("--period", 0, 0, 10);
  const double min_rho = p.number("--min-rho", 0.7, 0, 1);
  const std::string path = p.positionals().at(0);
  Capture cap = read_capture(path);

  // The receiver needs an integer number of samples per carrier cycle.
  constexpr double carrier = 200e3;
  const double ratio = cap.sample_rate / carrier;
  if (std::abs(ratio - std::round(ratio)) > 1e-3 * ratio || std::round(ratio) < 4) {
    std::ostringstream os;
    os << path << ": sample rate " << cap.sample_rate << " Hz is " << ratio
       << " samples per 200 kHz carrier cycle; the receiver needs an integer >= 4 (e.g. 1, 2.5, 5 or 10 MS/s)";
    throw InputError(os.str());
  }
  const double fs = std::round(ratio) * carrier;

  std::ostringstream yaml;
  yaml.precision(17);
  yaml << "name: decode\nsample_rate: " << fs << "\nmedium:\n  speed_of_sound: " << c
       << "\ntransducers: {}\ngeometry:\n  distances_m: [1.0]\nexcitation:\n  family: " << family << "\n";
  if (p.has("--references")) yaml << "receiver:\n  reference: files\n  references_dir: \"" << *p.get("--references") << "\"\n";
  Scene scene = parse_scene(yaml.str(), path);
  const CodeFamily fam = code_family(family);
  const std::size_t burst = static_cast<std::size_t>(fam.length + 3) * static_cast<std::size_t>(scene.receiver.config.chip_samples());
  if (cap.samples.size() < burst) {
    std::ostringstream os;
    os << path << ": too short: " << cap.samples.size() << " samples (" << cap.samples.size() / fs * 1e6
       << " us) hold less than one burst of " << family << " (" << burst << " samples, " << burst / fs * 1e6 << " us)";
    throw InputError(os.str());
  }
  SceneSimulator sim(scene);
  std::vector<Detection> dets;
  for (const auto& d : sim.decode(family, cap.samples, cap.t0, period)) {
    if (d.rho_max >= min_rho) dets.push_back(d);
  }

  if (p.has("--json")) {
    nlohmann::json j;
    j["sample_rate"] = cap.sample_rate;
    j["family"] = family;
    j["speed_of_sound"] = c;
    j["detections"] = nlohmann::json::array();
    for (const auto& d : dets) {
      j["detections"].push_back({{"code", d.code}, {"tof_s", d.tof_s}, {"distance_m", d.tof_s * c},
                                 {"rho", d.rho_max}, {"u", d.u}, {"pearson_code", d.pearson_code},
                                 {"receiver_rho2", d.score}});
    }
    std::cout << stamp_build_info(j).dump(2) << "\n";
  } else {
    std::printf("%s: %zu samples at %.6g MS/s, family %s, c = %.2f m/s\n", path.c_str(), cap.samples.size(),
                cap.sample_rate / 1e6, family.c_str(), c);
    std::printf("%5s %12s %12s %8s %8s\n", "code", "tof_us", "distance_mm", "rho_max", "u");
    for (const auto& d : dets) {
      std::printf("%5d %12.3f %12.3f %8.4f %8.4f\n", d.code, d.tof_s * 1e6, d.tof_s * c * 1e3, d.rho_max, d.u);
    }
    if (dets.empty()) std::printf("no burst detected\n");
  }
  return 0;
}

}  // namespace ranging::tool
