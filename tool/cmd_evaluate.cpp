// `ranging evaluate SCENE`: the paper's Section 4 (Tables 4-6, Figures 13-15) recomputed from a
// scene (scenes/paper-section4.yaml), written as data, PNG figures (scripts/plot_section4.py)
// and a generated Markdown document that sets the paper's values beside ours.
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>

#include "model/base/atomic_file.hpp"
#include "model/sim/capture.hpp"
#include "model/base/error.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/scene_run.hpp"

namespace ranging::tool {
namespace {

// The paper's published values (Lu et al. 2025, Tables 4, 5 and 6), for the comparison.
struct PaperRow {
  double u_min, energy_min, td_max_us, vmax_hz;  // NaN where the paper gives none
};
const std::map<std::string, PaperRow>& paper_values() {
  const double nan = std::nan("");
  static const std::map<std::string, PaperRow> v = {
      {"M1", {0.129, 1.964, 182.2, 2380}},    {"M2", {0.115, 1.909, 184.8, 2380}},
      {"M3", {0.007, 1.335, nan, nan}},       {"M4", {0.026, 1.375, nan, nan}},
      {"Gold1", {0.145, 0.897, 176.0, 3060}}, {"Gold2", {0.098, 0.972, 185.8, 3060}},
      {"Gold3", {0.101, 0.561, 189.2, 3060}}, {"Gold4", {0.185, 0.945, 183.0, 3060}},
      {"Gold5", {0.175, 0.815, 185.6, 3060}}, {"Gold6", {0.104, 0.897, 180.8, 3060}},
      {"Gold7", {0.143, 0.873, 183.0, 3060}}};
  return v;
}

std::string f(double v, int prec) {
  if (!std::isfinite(v)) return "--";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", prec, v);
  return buf;
}

bool is_m(const std::string& fam) { return fam.size() == 2 && fam[0] == 'M'; }

}  // namespace

int cmd_evaluate(const Args& args) {
  cli::Parser p("ranging evaluate",
                "Reproduce the paper's Section 4 from a scene: Table 4 (u_min, Energy_min), Table 5\n"
                "(T_d-max), Table 6 (v_max), Figures 13-15 (PNG via scripts/plot_section4.py) and a\n"
                "generated Markdown document comparing the paper's values with ours.");
  p.positional("SCENE", "scene file, e.g. scenes/paper-section4.yaml");
  p.option("--out", "DIR", "output directory", "docs/results");
  p.flag("--no-plots", "skip the PNG figures (no Python needed)");
  p.flag("--json", "print the tables as JSON on stdout");
  p.flag("--quiet", "no progress bar");
  if (!p.parse(args)) return 0;
  const std::string scene_path = p.positionals().at(0);
  Scene scene = load_scene(scene_path);
  const std::string out = p.get_or("--out", "docs/results");
  namespace fs = std::filesystem;
  OutputDir out_dir(out, "option --out");  // removed again if the run fails

  SceneSimulator sim(scene);
  if (!p.has("--json") && !p.has("--quiet")) std::cerr << stages_text(sim);
  const SceneRun run = run_scene(sim, p.has("--quiet") || p.has("--json"));
  const std::string stem = out + "/" + scene.name;

  // Data for the figures: per code (Fig. 14, 15 and T_d) and Figure 13's waveforms.
  std::ostringstream per;
  per << "family,code,u_mean,energy_at_max_distance_v2,td_max_s\n";
  for (const auto& s : run.summaries) {
    for (std::size_t k = 0; k < s.u_per_code.size(); ++k) {
      per << s.family << "," << k + 1 << "," << s.u_per_code[k] << "," << s.energy_per_code[k] << ","
          << s.td_per_code[k] << "\n";
    }
  }
  write_file_atomic(stem + "-per-code.csv", per.str());
  const std::string fig13_family = scene.excitation.families.front();
  const double dmin = *std::min_element(scene.geometry.distances_m.begin(), scene.geometry.distances_m.end());
  {
    std::ostringstream w;
    const int eta = code_family(fig13_family).eta();
    std::vector<std::vector<double>> waves;
    std::size_t n = 0;
    for (int j = 1; j <= eta; ++j) {
      waves.push_back(sim.filtered_burst(fig13_family, j, dmin));
      n = std::max(n, waves.back().size());
    }
    w << "time_s";
    for (int j = 1; j <= eta; ++j) w << "," << fig13_family << "-" << j;
    w << "\n";
    for (std::size_t i = 0; i < n; ++i) {
      w << static_cast<double>(i) / scene.fs;
      for (const auto& v : waves) w << "," << (i < v.size() ? v[i] : 0.0);
      w << "\n";
    }
    write_file_atomic(stem + "-fig13.csv", w.str());
  }
  write_file_atomic(stem + "-summary.json", summary_json(sim, run).dump(2) + "\n");

  std::vector<std::string> figures;
  if (!p.has("--no-plots")) {
    // The script ships with the sources: next to this file's tree, else under the working directory.
    std::string script = (fs::path(__FILE__).parent_path().parent_path() / "scripts/plot_section4.py").string();
    if (!fs::exists(script)) script = "scripts/plot_section4.py";
    const std::string cmd = "/usr/bin/python3 '" + script + "' '" + stem + "' '" + fig13_family + "' > /dev/null";
    if (std::system(cmd.c_str()) != 0) {
      throw InputError("figures: '" + cmd + "' failed (matplotlib missing? use --no-plots)");
    }
    for (const char* k : {"fig13", "fig14", "fig15"}) figures.push_back(scene.name + "-" + k + ".png");
  }

  // The comparison document, generated.
  std::ostringstream md;
  const auto& paper = paper_values();
  md << "# The paper's Section 4, reproduced\n\n"
     << "Generated by `ranging evaluate " << scene_path << "` -- do not edit by hand.\n\n"
     << "Scene `" << scene_path << "`: families";
  for (const auto& fam : scene.excitation.families) md << " " << fam;
  md << "; distances " << f(dmin * 1e3, 0) << "-" << f(scene.range_l() * 1e3, 0) << " mm ("
     << scene.geometry.distances_m.size() << " points), " << scene.geometry.repeats << " repeats; "
     << run.rows.size() << " bursts; receiver precision " << scene.receiver.precision << ".\n\nStages built:\n\n";
  for (const auto& st : sim.stages()) md << "- **" << st.name << "**: " << st.description << "\n";
  md << "\nDefinitions (as in the paper): u = rho_max - rho_submax (eq. 12) with Pearson coefficients "
        "against received templates (filtered noise-free bursts at "
     << f(scene.receiver.calibration_distance_m * 1e3, 0)
     << " mm), averaged per code over all distances and repeats, u_min = the smallest code average (Table 4, "
        "Figure 14); energy = sum of squares of the filtered received burst (V^2), averaged per code over the "
        "repeats at the largest distance, Energy_min = the smallest (Table 4, Figure 15); T_d = first to last "
        "sample above b/10 of the filtered burst, T_d-max = the largest per-distance mean over codes and "
        "distances (Table 5); v_max = min(1/(1.5 T_d-max), eta c / L) with c = "
     << f(scene.speed(), 1) << " m/s, L = " << f(scene.range_l(), 2) << " m (eq. 4, Table 6).\n\n";
  md << "## Side by side\n\n"
     << "| family | u_min paper | u_min ours | Energy_min paper (V^2) | Energy_min ours (V^2) | T_d-max paper (us) | "
        "T_d-max ours (us) | T_d diff | v_max paper (Hz) | v_max ours (Hz) | decode errors |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  bool vmax_ok = true, td_ok = true;
  double m_energy = 1e300, gold_energy = 0;
  bool have_m = false, have_gold = false;
  nlohmann::json tables = nlohmann::json::array();
  for (const auto& s : run.summaries) {
    const auto it = paper.find(s.family);
    const PaperRow pr = it != paper.end() ? it->second : PaperRow{std::nan(""), std::nan(""), std::nan(""), std::nan("")};
    const double td_us = s.td_max_s * 1e6;
    const double diff = std::isfinite(pr.td_max_us) ? (td_us - pr.td_max_us) / pr.td_max_us * 100 : std::nan("");
    if (std::isfinite(pr.vmax_hz) && std::abs(s.vmax_hz - pr.vmax_hz) > 0.5) vmax_ok = false;
    if (std::isfinite(diff) && std::abs(diff) > 10) td_ok = false;
    if (is_m(s.family) && (s.family == "M1" || s.family == "M2")) {
      m_energy = std::min(m_energy, s.energy_min);
      have_m = true;
    }
    if (s.family.rfind("Gold", 0) == 0) {
      gold_energy = std::max(gold_energy, s.energy_min);
      have_gold = true;
    }
    md << "| " << s.family << " | " << f(pr.u_min, 3) << " | " << f(s.u_min, 3) << " | " << f(pr.energy_min, 3)
       << " | " << f(s.energy_min, 3) << " | " << f(pr.td_max_us, 1) << " | " << f(td_us, 1) << " | "
       << (std::isfinite(diff) ? f(diff, 1) + " %" : "--") << " | " << f(pr.vmax_hz, 0) << " | "
       << f(s.vmax_hz, 0) << " | " << s.decode_errors << "/" << s.measurements << " |\n";
    tables.push_back({{"family", s.family}, {"u_min", s.u_min}, {"energy_min_v2", s.energy_min},
                      {"td_max_s", s.td_max_s}, {"vmax_hz", s.vmax_hz}, {"decode_errors", s.decode_errors},
                      {"measurements", s.measurements},
                      {"paper", {{"u_min", std::isfinite(pr.u_min) ? nlohmann::json(pr.u_min) : nlohmann::json()},
                                 {"energy_min_v2", std::isfinite(pr.energy_min) ? nlohmann::json(pr.energy_min) : nlohmann::json()},
                                 {"td_max_us", std::isfinite(pr.td_max_us) ? nlohmann::json(pr.td_max_us) : nlohmann::json()},
                                 {"vmax_hz", std::isfinite(pr.vmax_hz) ? nlohmann::json(pr.vmax_hz) : nlohmann::json()}}}});
  }
  const bool energy_ok = have_m && have_gold && m_energy > gold_energy;
  std::string worst_u;
  double worst_u_value = 1e300;
  for (const auto& s : run.summaries) {
    if (s.u_min < worst_u_value) {
      worst_u_value = s.u_min;
      worst_u = s.family;
    }
  }
  md << "\n## Checks\n\n"
     << "- v_max equal to Table 6 (2380 Hz for M1/M2, 3060 Hz for Gold): **" << (vmax_ok ? "yes" : "NO") << "**\n"
     << "- T_d-max within 10 % of Table 5: **" << (td_ok ? "yes" : "NO") << "**\n";
  if (have_m && have_gold) {
    md << "- M-sequence (M1/M2) Energy_min above every Gold family's, as in Table 4: **" << (energy_ok ? "yes" : "NO")
       << "** (M1/M2 smallest " << f(m_energy, 3) << " V^2, Gold largest " << f(gold_energy, 3) << " V^2)\n";
  }
  md << "\n## Why the numbers differ\n\n"
     << "- **Energy level.** One number sets the absolute level: the pitch-catch sensitivity ("
     << scene.sensitivity << " V/V at 0.1 m, `transducers.sensitivity`), chosen so M1's Energy_min at 1 m "
        "lands near the paper's 1.964 V^2 (docs/scenes.md). Every other energy is a prediction: the ratios "
        "between codes and families come from the codes, the transducer resonance (Q 7.5) and the "
        "bandpass. The model's energy of a code grows with its run lengths (long runs of equal chips let "
        "the resonators ring up), which is why M-sequences (runs up to 3) beat Gold codes (many single-chip "
        "runs); the paper's measured ratios are larger (max/min 2.1-2.2 within M1/M2, 3.0-4.4 within Gold), "
        "since real transducers are not single resonators and each recording has its own alignment.\n"
     << "- **u (distinguishability).** The simulated channel is linear, the templates are the same "
        "channel's response, and the only impairments are the scene's noise and ADC, so rho_max stays near 1 "
        "and u is set by the cross-correlation of the received templates: clean simulation distinguishes the "
        "codes better than the measured u of Table 4. Effects that would lower it and are not in this scene: "
        "transducer-to-transducer differences between the recording of the references and the measurement "
        "(a scene can use `receiver.reference: files` with recorded templates), multipath from the "
        "coordinate measuring machine and housings, turbulence and temperature drift (changing c during a "
        "burst), misalignment (add `geometry.angle_deg`), a lower SNR (`noise.snr_db`), and the 8-bit "
        "oscilloscope (`noise.adc.bits`). The order between families is the comparable quantity: "
        "the paper's smallest u_min is M3's (0.007), ours is "
     << worst_u << "'s (" << f(worst_u_value, 3) << ").\n"
     << "- **T_d-max.** Q = 7.5 was calibrated on M1 alone (docs/signal-model.md); the other families' "
        "T_d follow from their codes. T_d moves in steps of about half a carrier period (2.5 us) because the "
        "b/10 crossing jumps between ring-down half-cycle peaks; the paper's per-family spread (176-189 us) "
        "is wider than ours, as expected from real transducers with more than one mode and from noise on "
        "the threshold crossing.\n"
     << "- **v_max** is eta c / L for every family in both (1/(1.5 T_d-max) is larger), so it matches "
        "Table 6 exactly as long as T_d-max stays below 1/(1.5 eta c/L) = "
     << f(1e6 / (1.5 * 9 * scene.speed() / scene.range_l()), 1) << " us for Gold.\n";
  if (!figures.empty()) {
    md << "\n## Figures\n\n";
    md << "![Figure 13](" << figures[0] << ")\n\nFigure 13: filtered noise-free received bursts of every "
       << fig13_family << " code at " << f(dmin * 1e3, 0) << " mm.\n\n";
    md << "![Figure 14](" << figures[1] << ")\n\nFigure 14: u per code (mean over distances and repeats).\n\n";
    md << "![Figure 15](" << figures[2] << ")\n\nFigure 15: energy per code at "
       << f(scene.range_l() * 1e3, 0) << " mm (mean over repeats).\n";
  }
  md << "\nData: `" << scene.name << "-per-code.csv`, `" << scene.name << "-fig13.csv`, `" << scene.name
     << "-summary.json`.\n";
  write_file_atomic(stem + ".md", md.str());
  out_dir.keep();

  if (p.has("--json")) {
    nlohmann::json j;
    j["families"] = tables;
    j["checks"] = {{"vmax_equals_table6", vmax_ok}, {"td_within_10_percent", td_ok}, {"m_energy_above_gold", energy_ok}};
    j["document"] = stem + ".md";
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << md.str();
  }
  return 0;
}

}  // namespace ranging::tool
