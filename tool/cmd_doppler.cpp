// `ranging doppler SCENE`: decode rate and ToF bias against a constant line-of-sight speed
// (model/sim/rotor.hpp doppler_point), through the scene's transducers, noise, ADC and receiver.
#include <cstdio>
#include <sstream>

#include "model/base/error.hpp"
#include "model/sim/capture.hpp"
#include "model/sim/rotor.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/options.hpp"

namespace ranging::tool {

int cmd_doppler(const Args& args) {
  cli::Parser p = command_parser("doppler");
  add_scene_argument(p);
  p.option("--speeds", "LIST", "comma-separated line-of-sight speeds, m/s", "0,10,20,40,80");
  p.option("--distance", "M", "distance at the burst centre's arrival, m", "0.5");
  p.option("--repeats", "N", "repeats of every code", "3");
  p.option("--out", "FILE", "also write the table as CSV");
  if (!p.parse(args)) return 0;
  const Scene scene = load_scene(p.positionals().at(0));
  if (scene.excitation.schedule.period_s <= 0) {
    throw InputError(scene.origin + ": excitation.schedule.period_s: the doppler study needs the burst period");
  }
  const double d = p.number("--distance", 0.5, 0.01, 20.0);
  const int repeats = static_cast<int>(p.number("--repeats", 3, 1, 1000));
  std::vector<double> speeds;
  for (const std::string& item : p.items("--speeds")) {
    const double v = cli::list_number("--speeds", item);
    if (!(v > -0.9 * scene.speed() && v < 0.9 * scene.speed())) {
      throw InputError("option --speeds: " + item + " m/s is out of range; valid range is (-0.9 c, 0.9 c)");
    }
    speeds.push_back(v);
  }
  SceneSimulator sim(scene);
  std::ostringstream csv;
  csv << "los_speed_mps,doppler,bursts,decoded,misdecoded,missed,bias_start_m,bias_centre_m,std_m,adc_clipped\n";
  std::printf("%10s %8s %6s %7s %7s %6s %13s %14s %9s\n", "v_los_m/s", "doppler", "bursts", "decoded", "misdec",
              "missed", "bias_start_mm", "bias_centre_mm", "std_mm");
  for (double v : speeds) {
    const DopplerPoint pt = doppler_point(sim, d, v, repeats);
    std::printf("%10.2f %8.4f %6d %7d %7d %6d %13.4f %14.4f %9.4f\n", v, pt.doppler, pt.bursts, pt.decoded,
                pt.misdecoded, pt.missed, pt.bias_start_m * 1e3, pt.bias_centre_m * 1e3, pt.std_m * 1e3);
    csv << v << ',' << pt.doppler << ',' << pt.bursts << ',' << pt.decoded << ',' << pt.misdecoded << ',' << pt.missed
        << ',' << pt.bias_start_m << ',' << pt.bias_centre_m << ',' << pt.std_m << ',' << pt.adc_clipped << '\n';
    if (pt.adc_clipped) {
      std::fprintf(stderr, "doppler: warning: at %.2f m/s the ADC clipped %llu received samples\n", v,
                   static_cast<unsigned long long>(pt.adc_clipped));
    }
  }
  if (p.has("--out")) write_file_atomic(*p.get("--out"), csv.str());
  return 0;
}

}  // namespace ranging::tool
