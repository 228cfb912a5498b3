// `ranging simulate SCENE`: run a scene (model/sim/scene_simulator.hpp) and write one CSV row per
// measurement and a summary JSON. Also home of the helpers `ranging evaluate` shares
// (tool/scene_run.hpp).
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "model/base/atomic_file.hpp"
#include "model/sim/capture.hpp"
#include "model/base/error.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"
#include "tool/options.hpp"
#include "tool/cli.hpp"
#include "tool/guard.hpp"
#include "tool/commands.hpp"
#include "tool/rotor_run.hpp"
#include "tool/json_meta.hpp"
#include "tool/plot.hpp"
#include "tool/rtl_scene_check.hpp"
#include "tool/scene_run.hpp"

namespace ranging::tool {
namespace {

// A progress bar that appears only when a run has lasted about two seconds.
class Progress {
 public:
  Progress(std::size_t total, bool enabled)
      : total_(total), enabled_(enabled && isatty(STDERR_FILENO)), t0_(std::chrono::steady_clock::now()) {}
  void tick() {
    ++done_;
    if (!enabled_) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0_).count();
    if (s < 2.0 || (done_ % 16 != 0 && done_ != total_)) return;
    const int width = 40;
    const int fill = static_cast<int>(width * static_cast<double>(done_) / static_cast<double>(total_));
    std::fprintf(stderr, "\r[%s%s] %zu/%zu streams, %.0f s", std::string(static_cast<std::size_t>(fill), '#').c_str(),
                 std::string(static_cast<std::size_t>(width - fill), '.').c_str(), done_, total_, s);
    shown_ = true;
  }
  ~Progress() {
    if (shown_) std::fprintf(stderr, "\n");
  }

 private:
  std::size_t total_, done_ = 0;
  bool enabled_, shown_ = false;
  std::chrono::steady_clock::time_point t0_;
};

std::string num(double v, int prec = 9) {
  if (std::isnan(v)) return "";
  std::ostringstream os;
  os.precision(prec);
  os << v;
  return os.str();
}

nlohmann::json jnum(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

// simulate --plot: distance error against true distance per family (scripts/plot_simulate_error.py).
// A measurement counts as decoded when the receiver detected the code that was sent; the others
// (missed, misdecoded) are drawn apart at error 0, never as an error value.
nlohmann::json error_plot_data(const Scene& scene, const SceneRun& run) {
  nlohmann::json j;
  j["title"] = "ranging simulate: " + scene.name + " (" + scene.receiver.precision + " receiver)";
  j["families"] = nlohmann::json::array();
  for (const auto& f : run.summaries) {
    std::vector<double> true_m, err_m, failed_m;
    std::map<double, std::vector<double>> by_distance;
    std::size_t n = 0;
    for (const auto& r : run.rows) {
      if (r.family != f.family) continue;
      ++n;
      if (r.detected && (r.code_sent <= 0 || r.det.code == r.code_sent)) {
        true_m.push_back(r.true_distance_m);
        err_m.push_back(r.error_m);
        by_distance[r.true_distance_m].push_back(r.error_m);
      } else {
        failed_m.push_back(r.true_distance_m);
      }
    }
    std::vector<double> dist, mean, sd;
    for (const auto& [x, es] : by_distance) {
      double m = 0, v = 0;
      for (double e : es) m += e;
      m /= static_cast<double>(es.size());
      for (double e : es) v += (e - m) * (e - m);
      dist.push_back(x);
      mean.push_back(m);
      sd.push_back(es.size() > 1 ? std::sqrt(v / static_cast<double>(es.size() - 1)) : 0.0);
    }
    j["families"].push_back({{"family", f.family}, {"measurements", n}, {"detected", true_m.size()},
                             {"true_m", true_m}, {"error_m", err_m}, {"failed_m", failed_m},
                             {"distance_m", dist}, {"mean_error_m", mean}, {"std_error_m", sd}});
  }
  return j;
}

}  // namespace

SceneRun run_scene(SceneSimulator& sim, bool quiet, const std::string& capture_dir) {
  std::size_t total = 0;
  for (const auto& f : sim.scene().excitation.families) total += sim.streams(f);
  Progress bar(total, !quiet);
  SceneRun out;
  for (const auto& f : sim.scene().excitation.families) {
    std::size_t fa = 0;
    std::uint64_t ovf = 0;
    auto capture = [&](const CaptureStream& c) {
      Capture cap;
      cap.sample_rate = c.fs;
      cap.samples = *c.volts;
      // What decode needs to reproduce the run (model/sim/capture.hpp): CSV header and sidecar.
      const Scene& sc = sim.scene();
      cap.meta.scene = sc.name;
      cap.meta.family = c.family;
      cap.meta.code_sent = c.code;
      cap.meta.true_distance_m = c.distance_m;
      cap.meta.speed_of_sound = sc.speed();
      cap.meta.sample_rate = c.fs;
      if (sc.excitation.schedule.mode == "periodic") cap.meta.period_s = sc.excitation.schedule.period_s;
      std::ostringstream name;
      name << capture_dir << "/" << c.family << "_" << std::llround(c.distance_m * 1e3) << "mm_r" << c.repeat;
      if (c.code > 0) name << "_j" << c.code;
      write_file_atomic(name.str() + ".csv", capture_csv(cap));
      write_file_atomic(name.str() + ".wav", capture_wav(cap, WavFormat::Float32));
      write_file_atomic(name.str() + ".json", capture_meta_json(cap.meta));
    };
    auto rows = sim.run(f, [&] { bar.tick(); },
                        capture_dir.empty() ? std::function<void(const CaptureStream&)>{} : capture, &fa, &ovf);
    FamilySummary s = summarize(sim.scene(), f, rows, fa);
    s.overflows = ovf;
    out.summaries.push_back(s);
    out.rows.insert(out.rows.end(), rows.begin(), rows.end());
  }
  return out;
}

std::string measurements_csv(const SceneRun& run, double /*c*/) {
  std::ostringstream os;
  os << "family,repeat,burst,true_distance_m,code_sent,code_decoded,tof_s,distance_m,error_m,"
        "rho_max,rho_submax,u,energy_v2,td_s,pearson_code,receiver_rho2,receiver_rho2_margin,pearson_margin,"
        "td_clipped,td_noise_limited,adc_clipped,range_ambiguous,speed_used,reference_missed\n";
  for (const auto& r : run.rows) {
    os << r.family << "," << r.repeat << "," << r.burst << "," << num(r.true_distance_m) << "," << r.code_sent
       << "," << (r.detected ? r.det.code : 0) << "," << (r.detected ? num(r.det.tof_s, 12) : "") << ","
       << (r.detected ? num(r.distance_m, 12) : "") << "," << (r.detected ? num(r.error_m, 6) : "") << ","
       << num(r.det.rho_max, 6) << "," << num(r.det.rho_submax, 6) << "," << num(r.u, 6) << ","
       << num(r.det.energy, 6) << "," << num(r.det.td_s, 6) << "," << r.det.pearson_code << ","
       << (r.detected ? num(r.det.score, 6) : "") << "," << (r.detected ? num(r.det.detector_margin, 6) : "") << ","
       << num(r.det.pearson_margin, 6) << "," << r.det.td_clipped << "," << r.det.td_noise_limited << ","
       << r.adc_clipped << "," << r.range_ambiguous << "," << num(r.speed_used, 9) << "," << r.reference_missed
       << "\n";
  }
  return os.str();
}

nlohmann::json summary_json(const SceneSimulator& sim, const SceneRun& run) {
  const Scene& s = sim.scene();
  nlohmann::json j;
  stamp_build_info(j);
  j["scene"] = s.name;
  j["file"] = s.origin;
  j["precision"] = s.receiver.precision;
  j["speed_of_sound"] = s.speed();
  j["receiver_speed_of_sound"] = s.receiver_speed();
  j["compensation"] = s.compensation ? nlohmann::json{{"reference_distance_m", s.compensation->reference_distance_m},
                                                      {"equation", "c_est = d_ref / tof_ref; d = c_est * tof"}}
                                     : nlohmann::json(nullptr);
  j["warnings"] = s.warnings;
  j["max_range_m"] = s.range_l();
  j["metrics"] = s.receiver.metrics.names();  // receiver.metrics: the others are null below
  j["samples_simulated"] = sim.samples_simulated();
  j["stages"] = nlohmann::json::array();
  for (const auto& st : sim.stages()) j["stages"].push_back({{"name", st.name}, {"description", st.description}});
  j["families"] = nlohmann::json::array();
  std::size_t n = 0, err = 0;
  for (const auto& f : run.summaries) {
    n += f.measurements;
    err += f.decode_errors;
    nlohmann::json per;
    for (std::size_t k = 0; k < f.u_per_code.size(); ++k) {
      per.push_back({{"code", k + 1}, {"u", jnum(f.u_per_code[k])}, {"energy_v2", jnum(f.energy_per_code[k])},
                     {"td_s", jnum(f.td_per_code[k])},
                     {"detector_rho2_margin", jnum(f.detector_margin_per_code[k])}});
    }
    j["families"].push_back({{"family", f.family}, {"eta", f.eta}, {"measurements", f.measurements},
                             {"decode_errors", f.decode_errors}, {"decode_error_rate", f.error_rate},
                             {"missed", f.missed}, {"false_alarms", f.false_alarms},
                             {"distance_rmse_m", jnum(f.rmse_m)}, {"u_min", jnum(f.u_min)},
                             {"energy_min_v2", jnum(f.energy_min)}, {"td_max_s", jnum(f.td_max_s)},
                             {"vmax_hz", jnum(f.vmax_hz)}, {"fixed_overflows", f.overflows},
                             // decode_errors above is the union of the two decoders' errors.
                             {"detector", {{"metric", "receiver rho^2 (hardware detector)"},
                                           {"decode_errors", f.detector_errors},
                                           {"rho2_margin_min", jnum(f.detector_margin_min)}}},
                             {"pearson", s.receiver.metrics.pearson
                                             ? nlohmann::json{{"metric", "paper: Pearson matched filter over +-L chips, u by eq. 10"},
                                                              {"decode_errors", f.pearson_errors}, {"u_min", jnum(f.u_min)},
                                                              {"u_max_over_min", jnum(f.u_max_over_min)}}
                                             : nlohmann::json(nullptr)},
                             {"td_clipped", f.td_clipped}, {"td_noise_limited", f.td_noise_limited},
                             {"input_clipping", {{"stage", s.noise.adc ? "adc" : "receiver input clamp"},
                                                 {"measurements_clipped", f.clipped_measurements},
                                                 {"samples_clipped", f.clipped_samples},
                                                 {"max_samples_per_measurement", f.clipped_max}}},
                             {"range_ambiguous", f.range_ambiguous},
                             {"unambiguous_range_m", f.unambiguous_range_m > 0 ? jnum(f.unambiguous_range_m) : nlohmann::json(nullptr)},
                             {"distance_rmse_with_ambiguous_m", jnum(f.distance_rmse_with_ambiguous_m)},
                             {"compensation_reference_missed", f.reference_missed},
                             {"per_code", per}});
  }
  j["decode_errors"] = err;
  j["measurements"] = n;
  j["decode_error_rate"] = n ? static_cast<double>(err) / static_cast<double>(n) : 0.0;
  return j;
}

std::string stages_text(const SceneSimulator& sim) {
  std::ostringstream os;
  os << "stages built (" << sim.stages().size() << "):\n";
  for (const auto& st : sim.stages()) os << "  " << st.name << ": " << st.description << "\n";
  return os.str();
}

int cmd_simulate(const Args& args) {
  cli::Parser p = command_parser("simulate");
  p.option("--precision", "float|fixed|rtl",
           "receiver precision (overrides the scene's receiver.precision); rtl: the fixed model, and every\n"
           "stream also through the Verilated receiver (built at run time), whose events must be identical");
  p.flag("--check-rtl", "the same as --precision rtl");
  add_rtl_option(p, "with --precision rtl");
  p.option("--rtl-simulator", "verilator|postsynth|icarus|hls|systemc",
           "with --precision rtl: what runs the streams: verilator (the RTL), postsynth (the iCE40\n"
           "gate-level netlist of yosys synth_ice40 -dsp, Verilated with yosys' cell models) or icarus\n"
           "(the RTL in Icarus Verilog: slow, for cross-checking the simulator) or hls (the HLS C++,\n"
           "C simulation: events only) or systemc (the RTL Verilated as an SC_MODULE, driven under the\n"
           "SystemC kernel)", "verilator");
  add_output_options(p, {.out = true, .out_default = "out/<scene name>", .json = true,
                         .json_note = "the summary JSON on stdout instead of the text summary", .quiet = true});
  p.flag("--write-captures", "also write every received stream as DIR/captures/*.csv and *.wav");
  p.option("--plot", "FILE.png", "draw the distance error against the true distance, per family");
  p.flag("--timing", "also record the seconds spent per stage (channel, receiver, metrics; summed over\n"
                     "threads) in summary.json as stage_seconds: a speed figure that changes run to run");
  add_jobs_option(p, "streams (distances, repeats, codes) simulated", "; --precision rtl runs one");
  add_scene_options(p);
  if (!p.parse(args)) return 0;
  if (p.has("--plot")) check_png_option("--plot", *p.get("--plot"));
  Scene scene = load_scene_options(p, "simulate");  // prints the scene's warnings
  if (p.has("--precision")) {
    const std::string prec = *p.get("--precision");
    if (prec != "float" && prec != "fixed" && prec != "rtl") {
      throw InputError("option --precision: '" + prec + "' is not valid; valid: float, fixed, rtl");
    }
    scene.receiver.precision = prec;
  }
  const bool rtl = p.has("--check-rtl") || scene.receiver.precision == "rtl";
  if (p.has("--check-rtl") && p.has("--precision") && scene.receiver.precision != "rtl" &&
      scene.receiver.precision != "fixed") {
    throw InputError("option --check-rtl: the RTL is checked against the fixed model; not valid with --precision " +
                     scene.receiver.precision);
  }
  if (p.has("--rtl") && !rtl) throw InputError("option --rtl: only with --precision rtl or --check-rtl");
  const std::string rtl_sim = p.get_or("--rtl-simulator", "verilator");
  if (rtl_sim != "verilator" && rtl_sim != "postsynth" && rtl_sim != "icarus" && rtl_sim != "hls" &&
      rtl_sim != "systemc") {
    throw InputError("option --rtl-simulator: '" + rtl_sim +
                     "' is not valid; valid: verilator, postsynth, icarus, hls, systemc");
  }
  if (p.has("--rtl-simulator") && !rtl) throw InputError("option --rtl-simulator: only with --precision rtl or --check-rtl");
  if (rtl) scene.receiver.precision = "fixed";
  const std::string out = p.get_or("--out", "out/" + scene.name);
  const bool json = p.has("--json");
  if (scene.geometry.type == "rotor" && p.has("--plot")) {
    throw InputError("option --plot: not available for rotor scenes");
  }
  if (scene.geometry.type == "rotor" && p.has("--timing")) {
    throw InputError("option --timing: not available for rotor scenes");
  }
  if (scene.geometry.type == "rotor" && p.has("--write-captures")) {
    throw InputError("option --write-captures: not available for rotor scenes");
  }
  const int jobs = jobs_option(p);
  OutputDir out_dir(out, "option --out");  // checked before any work; removed again if the run fails
  SceneSimulator sim(scene);
  sim.set_jobs(jobs);
  RtlSceneCheck rtl_check(p.get_or("--rtl", ""), "", p.has("--quiet"), rtl_sim);
  if (rtl) rtl_check.attach(sim);
  // stdout is written only once the run has succeeded: a failing command prints nothing there.
  std::ostringstream text;
  if (!json) text << "scene " << scene.name << " (" << scene.origin << ")\n" << stages_text(sim);

  namespace fs = std::filesystem;
  std::error_code ec;
  if (scene.geometry.type == "rotor") {  // tool/rotor_run.hpp
    std::cout << text.str() << std::flush;
    const int status = simulate_rotor(sim, out, json, p.has("--quiet"));
    out_dir.keep();
    return status;
  }
  // Captures go to a staging directory that becomes DIR/captures only when the run succeeds.
  const std::string staging = out + "/.captures.tmp";
  if (p.has("--write-captures")) {
    fs::remove_all(staging, ec);
    fs::create_directories(staging, ec);
    if (ec) throw InputError("option --out: cannot create '" + staging + "': " + ec.message());
  }
  SceneRun run;
  try {
    run = run_scene(sim, p.has("--quiet") || json, p.has("--write-captures") ? staging : "");
  } catch (...) {
    fs::remove_all(staging, ec);
    throw;
  }
  nlohmann::json summary = summary_json(sim, run);
  // The guard's verdict on the receiver's quantized filter (refused at load unless allowed).
  summary["design_guard"] = guard_json(check_quantized_design(scene.receiver.config), scene.receiver.config.filter_order);
  if (p.has("--timing")) {
    const StageSeconds& t = sim.stage_seconds();
    summary["stage_seconds"] = {{"channel", t.channel}, {"receiver", t.receiver}, {"metrics", t.metrics}};
  }
  if (rtl) {
    summary["precision"] = "rtl";
    summary["rtl"] = rtl_check.run();
    summary["rtl"]["simulator"] = rtl_sim;
  }
  if (p.has("--plot")) plot_with_script("option --plot", "scripts/plot_simulate_error.py", error_plot_data(scene, run), *p.get("--plot"));
  write_file_atomic(out + "/measurements.csv", measurements_csv(run, scene.speed()));
  write_file_atomic(out + "/summary.json", summary.dump(2) + "\n");
  write_effective_scene(scene, out);  // DIR/scene.yaml (+ config.yaml): re-run with `simulate DIR/scene.yaml`
  if (p.has("--write-captures")) {
    fs::remove_all(out + "/captures", ec);
    fs::rename(staging, out + "/captures", ec);
    if (ec) throw InputError("option --out: cannot move captures into place: " + ec.message());
  }
  out_dir.keep();
  if (json) {
    std::cout << summary.dump(2) << "\n";
  } else {
    char line[512];
    std::snprintf(line, sizeof line, "\n%-8s %4s %6s %7s %7s %7s %10s %10s %9s %11s %9s %9s %7s %8s\n", "family",
                  "eta", "n", "errors", "det.err", "prs.err", "rmse_mm", "rho2_mrg", "u_min", "energy_min", "Td_max_us",
                  "vmax_Hz", "Td_clip", "Td_noise");
    text << line;
    const SceneMetrics& mt = scene.receiver.metrics;
    for (const auto& f : run.summaries) {
      // A metric the scene does not compute prints "-", never a 0 that reads as a result.
      const auto cell = [](bool on, const char* fmt, auto v) {
        char b[32];
        if (!on) return std::string("-");
        std::snprintf(b, sizeof b, fmt, v);
        return std::string(b);
      };
      std::snprintf(line, sizeof line, "%-8s %4d %6zu %7zu %7zu %7s %10.4f %10.4f %9s %11s %9s %9s %7s %8s\n",
                    f.family.c_str(), f.eta, f.measurements, f.decode_errors, f.detector_errors,
                    cell(mt.pearson, "%zu", f.pearson_errors).c_str(), f.rmse_m * 1e3, f.detector_margin_min,
                    cell(mt.pearson, "%.4f", f.u_min).c_str(), cell(mt.energy, "%.4g", f.energy_min).c_str(),
                    cell(mt.td, "%.1f", f.td_max_s * 1e6).c_str(), cell(mt.td, "%.0f", f.vmax_hz).c_str(),
                    cell(mt.td, "%zu", f.td_clipped).c_str(), cell(mt.td, "%zu", f.td_noise_limited).c_str());
      text << line;
    }
    text << "errors = missed or misdecoded by either decoder; det.err / rho2_mrg: the receiver's (hardware)\n"
            "rho^2 detector and its smallest per-code mean margin; prs.err / u_min: the paper's Pearson\n"
            "matched filter (+-L chips) and eq. 10's u; Td_clip / Td_noise: T_d measurements the search\n"
            "range clipped / whose threshold the noise floor set (docs/signal-model.md)\n";
    if (!mt.all()) {
      const SceneMetrics none{!mt.pearson, !mt.energy, !mt.td};
      std::string off;
      for (const auto& m : none.names()) off += (off.empty() ? "" : ", ") + m;
      text << "not computed (receiver.metrics): " << off << " (\"-\" above, empty in measurements.csv)\n";
    }
    for (const auto& f : run.summaries) {
      if (f.clipped_measurements > 0) {
        text << "warning: " << f.family << ": input clipped (" << (scene.noise.adc ? "ADC" : "receiver input clamp")
             << ") in " << f.clipped_measurements << " of " << f.measurements << " measurements, "
             << f.clipped_samples << " samples, up to " << f.clipped_max << " per measurement\n";
      } else {
        text << f.family << ": input clipping: none\n";
      }
      if (f.range_ambiguous > 0) {
        char b[256];
        std::snprintf(b, sizeof b, "%.1f mm with them", f.distance_rmse_with_ambiguous_m * 1e3);
        text << "warning: " << f.family << ": " << f.range_ambiguous << " range-ambiguous measurements (distance >= "
             << "eta*c*T = " << f.unambiguous_range_m << " m aliased), counted as errors and left out of rmse ("
             << b << ")\n";
      }
      if (f.reference_missed > 0) {
        text << "warning: " << f.family << ": compensation reference burst missed in " << f.reference_missed
             << " measurements (the receiver's c " << scene.receiver_speed() << " m/s used)\n";
      }
    }
    if (scene.compensation) {
      text << "sound-velocity compensation: reference path " << scene.compensation->reference_distance_m
           << " m, c_est = d_ref / tof_ref, d = c_est * tof\n";
    }
    if (rtl) {
      const auto& r = summary["rtl"];
      text << "\nRTL (" << (rtl_sim == "postsynth" ? "Verilated iCE40 gate-level netlist"
                             : rtl_sim == "icarus"  ? "receiver_top in Icarus Verilog"
                             : rtl_sim == "hls"     ? "HLS C++, C simulation"
                             : rtl_sim == "systemc" ? "Verilated receiver_top under SystemC"
                                                    : "Verilated receiver_top")
           << "): " << r["streams"] << " streams, " << r["events_compared"]
           << " events compared with the fixed model, " << r["mismatches"] << " mismatches"
           << (r["pass"].get<bool>() ? ": identical\n" : "\n");
      if (!r["first_mismatch"].is_null()) text << "first mismatch: " << r["first_mismatch"].dump() << "\n";
    }
    text << "\nwrote " << out << "/measurements.csv, " << out << "/summary.json, " << out << "/scene.yaml"
         << (p.has("--plot") ? ", " + *p.get("--plot") : std::string())
         << (p.has("--write-captures") ? ", " + out + "/captures/" : std::string()) << "\n";
    std::cout << text.str();
  }
  return (rtl && !summary["rtl"]["pass"].get<bool>()) ? 1 : 0;
}

}  // namespace ranging::tool
