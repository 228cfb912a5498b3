// `ranging demo`: the main job at this stage (model/sim/demo.hpp).
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cstdio>
#include <iostream>

#include "model/config/receiver_config.hpp"
#include "model/sim/demo.hpp"
#include "model/base/error.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/json_meta.hpp"
#include "tool/options.hpp"

namespace ranging::tool {

int cmd_demo(const Args& args) {
  cli::Parser p = command_parser("demo");
  add_config_options(p);
  add_family_option(p, "overrides the configuration's", "Gold4");
  p.option("--distances", "LIST", "comma-separated distances in metres, 0.01..20", "0.1,0.55,1.0");
  add_speed_of_sound_option(p);
  p.option("--gain", "FS", "received amplitude at 0.1 m in ADC full-scale units, 1e-6..10", "0.5");
  p.option("--noise-rms", "FS", "white noise rms at the ADC in full-scale units, 0..10", "0.002");
  p.option("--seed", "N", "noise seed", "1");
  add_output_options(p, {.json = true, .quiet = true});
  add_jobs_option(p, "rows (distance x code) simulated");
  if (!p.parse(args)) return 0;

  DemoParams d;
  d.receiver = load_config_options(p, "demo");
  if (p.has("--family") || !p.has("--config")) d.receiver.family = p.get_or("--family", "Gold4");
  d.distances_m = p.number_list("--distances");
  d.speed_of_sound = speed_of_sound_option(p);
  d.gain = p.number("--gain", 0.5, 1e-6, 10);
  d.noise_rms = p.number("--noise-rms", 0.002, 0, 10);
  d.seed = static_cast<std::uint64_t>(p.integer("--seed", 1, 0, 1LL << 62));
  d.jobs = jobs_option(p);
  const bool json = p.has("--json");
  // Progress only where a person watches it.
  const bool quiet = p.has("--quiet") || json || !isatty(STDERR_FILENO);

  auto rows = run_demo(d, [&](std::size_t done, std::size_t total) {
    if (!quiet) std::fprintf(stderr, "\rsimulating %zu/%zu bursts", done, total);
  });
  if (!quiet) std::fprintf(stderr, "\n");

  int errors_flt = 0, errors_fix = 0, errors_pearson = 0;
  for (const auto& r : rows) {
    errors_flt += r.flt.decoded != r.code;
    errors_fix += r.fix.decoded != r.code;
    errors_pearson += r.pearson_decoded != r.code;
  }
  if (json) {
    nlohmann::json out;
    out["family"] = d.receiver.family;
    out["speed_of_sound"] = d.speed_of_sound;
    out["noise_rms"] = d.noise_rms;
    out["decode_errors"] = {{"float", errors_flt}, {"fixed", errors_fix}, {"pearson", errors_pearson}};
    out["rows"] = nlohmann::json::array();
    auto dec = [](const DemoDecode& x) {
      return nlohmann::json{{"detected", x.detected}, {"decoded", x.decoded}, {"tof_s", x.tof_s},
                            {"distance_m", x.distance_m}, {"error_m", x.error_m},
                            {"rho2", x.score}, {"margin", x.margin}};
    };
    for (const auto& r : rows) {
      out["rows"].push_back({{"code", r.code}, {"true_distance_m", r.distance_m},
                             {"float", dec(r.flt)}, {"fixed", dec(r.fix)},
                             {"pearson_decoded", r.pearson_decoded}, {"rho_max", r.rho_max},
                             {"rho_submax", r.rho_submax}, {"u", r.u}, {"energy", r.energy},
                             {"fixed_overflows", r.overflows}});
    }
    std::cout << stamp_build_info(out).dump(2) << "\n";
  } else {
    std::printf("family %s, c = %.1f m/s, noise rms %.4g FS; ToF calibrated at 0.1 m\n\n",
                d.receiver.family.c_str(), d.speed_of_sound, d.noise_rms);
    std::printf("%4s %8s | %5s %10s %9s %8s | %5s %10s %9s %8s | %6s %6s\n", "sent", "true_mm",
                "f.dec", "f.tof_us", "f.dist_mm", "f.err_mm", "x.dec", "x.tof_us", "x.dist_mm",
                "x.err_mm", "u_eq10", "rho2");
    for (const auto& r : rows) {
      std::printf("%4d %8.1f | %5d %10.3f %9.3f %8.3f | %5d %10.3f %9.3f %8.3f | %6.3f %6.3f\n",
                  r.code, r.distance_m * 1e3, r.flt.decoded, r.flt.tof_s * 1e6,
                  r.flt.distance_m * 1e3, r.flt.error_m * 1e3, r.fix.decoded, r.fix.tof_s * 1e6,
                  r.fix.distance_m * 1e3, r.fix.error_m * 1e3, r.u, r.fix.score);
    }
    std::printf("\ndecode errors: float %d/%zu, fixed %d/%zu, Pearson %d/%zu\n", errors_flt, rows.size(), errors_fix,
                rows.size(), errors_pearson, rows.size());
    std::printf("(u_eq10: the paper's Pearson matched filter, rho(sent) - max rho(other), < 0 on a misdecode;\n"
                " rho2: the hardware detector's score)\n");
  }
  return (errors_flt == 0 && errors_fix == 0 && errors_pearson == 0) ? 0 : 1;
}

}  // namespace ranging::tool
