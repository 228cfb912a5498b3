// The rotor branch of `ranging simulate` (tool/rotor_run.hpp).
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "model/base/error.hpp"
#include "model/sim/capture.hpp"
#include "model/sim/rotor.hpp"
#include "model/sim/scene.hpp"
#include "tool/rotor_run.hpp"

namespace ranging::tool {
namespace {

nlohmann::json jn(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

std::string n9(double v) {
  if (!std::isfinite(v)) return "";
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

struct Stats {
  std::size_t n = 0;
  double se = 0, sum = 0;
  void add(double e) {
    ++n;
    se += e * e;
    sum += e;
  }
  nlohmann::json json() const {
    return {{"n", n}, {"rms_m", n ? jn(std::sqrt(se / static_cast<double>(n))) : nullptr},
            {"mean_m", n ? jn(sum / static_cast<double>(n)) : nullptr}};
  }
};

}  // namespace

int simulate_rotor(SceneSimulator& sim, const std::string& out, bool json, bool quiet) {
  const Scene& s = sim.scene();
  const RotorParams& p = s.geometry.rotor;
  if (!json) {
    std::printf("  %s: %s\n", "rotor",
                ("R " + n9(p.radius_m) + " m, " + n9(p.rpm) + " RPM, " + std::to_string(p.blades) +
                 " blades, transducers at " + n9(p.r()) + " m (" + n9(p.omega_u() * p.r()) + " m/s), " +
                 std::to_string(p.crossings) + " crossings every " + n9(p.crossing_interval_s() * 1e3) + " ms")
                    .c_str());
    std::fflush(stdout);
  }
  std::size_t done = 0;
  const bool bar = !quiet && !json && isatty(STDERR_FILENO);
  const RotorRun run = run_rotor(sim, [&] {
    ++done;
    if (bar) std::fprintf(stderr, "\r%zu/%d crossings", done, p.crossings);
  });
  if (bar) std::fprintf(stderr, "\n");

  nlohmann::json j = {{"scene", s.name}, {"geometry", "rotor"}, {"family", run.family},
                      {"period_s", run.period_s}, {"burst_s", run.burst_s}, {"relative_tip_speed_mps", run.v_rel},
                      {"misdecodes", run.misdecodes}, {"false_alarms", run.false_alarms}, {"overflows", run.overflows},
                      {"adc_clipped", run.adc_clipped}};
  Stats motion, paper;
  std::size_t fail_motion = 0, fail_paper = 0, decoded = 0;
  for (const auto& b : run.bursts) decoded += b.decoded;
  j["crossings"] = nlohmann::json::array();
  for (const auto& c : run.crossings) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& m : c.list) {
      list.push_back({{"t_emit_s", m.t_emit_s}, {"tof_s", m.tof_s}, {"distance_m", m.distance_m}, {"code", m.code},
                      {"burst", m.burst}, {"correct", m.correct}});
    }
    j["crossings"].push_back({{"index", c.index}, {"t_s", c.t_s}, {"h_true_m", c.h_true_m}, {"h_est_m", jn(c.h_est_m)},
                              {"h_est_paper_m", jn(c.h_est_paper_m)}, {"measurements", c.measurements},
                              {"list", list}});
    if (std::isfinite(c.h_est_m)) motion.add(c.h_est_m - c.h_true_m); else ++fail_motion;
    if (std::isfinite(c.h_est_paper_m)) paper.add(c.h_est_paper_m - c.h_true_m); else ++fail_paper;
  }
  j["h_error_motion"] = motion.json();
  j["h_error_paper"] = paper.json();
  j["h_error_motion"]["failed"] = fail_motion;
  j["h_error_paper"]["failed"] = fail_paper;
  j["bursts_rendered"] = run.bursts.size();
  j["bursts_decoded"] = decoded;

  std::ostringstream bc;
  bc << "crossing,burst,code,t_emit_s,t_rel_s,angle_deg,doppler,los_speed_mps,amplitude_rel,decoded,"
        "tof_error_start_m,tof_error_centre_m,h_true_m\n";
  for (const auto& b : run.bursts) {
    bc << b.crossing << ',' << b.burst << ',' << b.code << ',' << n9(b.t_emit_s) << ',' << n9(b.t_rel_s) << ','
       << n9(b.angle_deg) << ',' << n9(b.doppler) << ',' << n9(b.los_speed_mps) << ',' << n9(b.amplitude_rel) << ','
       << (b.decoded ? 1 : 0) << ',' << n9(b.tof_error_start_m) << ',' << n9(b.tof_error_centre_m) << ','
       << n9(run.crossings[static_cast<std::size_t>(b.crossing)].h_true_m) << '\n';
  }
  std::ostringstream mc;
  mc << "crossing,burst,code,correct,t_emit_s,tof_s,distance_m,score,true_tof_start_s,true_tof_centre_s\n";
  for (const auto& c : run.crossings) {
    for (const auto& m : c.list) {
      mc << m.crossing << ',' << m.burst << ',' << m.code << ',' << (m.correct ? 1 : 0) << ',' << n9(m.t_emit_s) << ','
         << n9(m.tof_s) << ',' << n9(m.distance_m) << ',' << n9(m.score) << ',' << n9(m.true_tof_start_s) << ','
         << n9(m.true_tof_centre_s) << '\n';
    }
  }
  write_file_atomic(out + "/bursts.csv", bc.str());
  write_file_atomic(out + "/measurements.csv", mc.str());
  write_file_atomic(out + "/summary.json", j.dump(2) + "\n");
  if (json) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  auto rms = [](const Stats& st) {
    if (!st.n) return std::string("none (no crossing with two accepted measurements)");
    char b[64];
    std::snprintf(b, sizeof b, "%.4f mm", std::sqrt(st.se / static_cast<double>(st.n)) * 1e3);
    return std::string(b);
  };
  std::printf("\n%zu crossings, %zu bursts rendered, %zu decoded, %zu misdecoded, %zu false alarms, %llu fixed-point"
              " saturations/wraps, %llu ADC samples clipped\n",
              run.crossings.size(), run.bursts.size(), decoded, run.misdecodes, run.false_alarms,
              static_cast<unsigned long long>(run.overflows), static_cast<unsigned long long>(run.adc_clipped));
  std::printf("h error rms, motion-aware: %s; %zu crossings estimated, %zu not\n", rms(motion).c_str(), motion.n,
              fail_motion);
  std::printf("h error rms, paper eq. 1:  %s; %zu crossings estimated, %zu not\n", rms(paper).c_str(), paper.n,
              fail_paper);
  std::printf("\nwrote %s/summary.json, %s/bursts.csv, %s/measurements.csv\n", out.c_str(), out.c_str(), out.c_str());
  return 0;
}

}  // namespace ranging::tool
