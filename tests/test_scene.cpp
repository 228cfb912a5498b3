// Scenes: strict loading, "model only what a scene requires" (stage selection), determinism,
// the medium (speed of sound, ISO 9613-1 absorption) and `ranging simulate`.
#include <gtest/gtest.h>

#include <sstream>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>

#include "model/base/error.hpp"
#include "model/config/ice40_pll.hpp"
#include "model/dsp/filter_design.hpp"
#include "model/dsp/receiver.hpp"
#include "model/hw/hw_system.hpp"
#include "model/sim/medium.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"
#include "tests/scratch.hpp"

using namespace ranging;

namespace {

std::vector<std::string> stage_names(const std::string& yaml) {
  std::vector<std::string> out;
  for (const auto& s : scene_stages(parse_scene(yaml, "s.yaml"))) out.push_back(s.name);
  return out;
}

std::string error_of(const std::string& yaml) {
  try {
    parse_scene(yaml, "s.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

struct ToolRun {
  int status;
  std::string out;
};
ToolRun run_tool(const std::string& args) {
  const std::string cmd = std::string(RANGING_TOOL) + " " + args + " 2>/dev/null";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  std::string out;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe.get())) > 0) out.append(buf, n);
  const int status = pclose(pipe.release());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}

const std::string kMinimal = "geometry:\n  distances_m: [0.5]\n";

}  // namespace

TEST(SceneStages, MinimalSceneBuildsOnlyDelayAndGain) {
  EXPECT_EQ(stage_names(kMinimal), (std::vector<std::string>{"delay", "gain"}));
  // The committed minimal scene is that scene.
  EXPECT_EQ(stage_names([] {
              std::ifstream in(std::string(RANGING_SOURCE_DIR) + "/scenes/minimal.yaml");
              std::stringstream ss;
              ss << in.rdbuf();
              return ss.str();
            }()),
            (std::vector<std::string>{"delay", "gain"}));
}

TEST(SceneStages, EachKeyAddsExactlyItsStage) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"transducers:\n  q: 7.5\n", "transducers"},
      {"medium:\n  temperature_c: 25\n", "absorption"},
      {"geometry_angle", "directivity"},
      {"noise:\n  noise_v: 0.001\n", "noise"},
      {"noise:\n  snr_db: 20\n", "noise"},
      {"noise:\n  adc:\n    bits: 10\n", "adc"},
  };
  const auto base = stage_names(kMinimal);
  for (const auto& [extra, stage] : cases) {
    const std::string yaml = extra == "geometry_angle" ? "geometry:\n  distances_m: [0.5]\n  angle_deg: 3\n"
                                                       : kMinimal + extra;
    const auto got = stage_names(yaml);
    SCOPED_TRACE(yaml);
    ASSERT_EQ(got.size(), base.size() + 1);
    EXPECT_NE(std::find(got.begin(), got.end(), stage), got.end());
  }
  // Parameters of existing stages add nothing: a fixed speed of sound, the excitation, the
  // receiver, a noise seed alone.
  for (const char* extra : {"medium:\n  speed_of_sound: 343\n", "excitation:\n  family: M1\n",
                                  "receiver:\n  precision: fixed\n", "noise:\n  seed: 5\n"}) {
    EXPECT_EQ(stage_names(kMinimal + std::string(extra)), base) << extra;
  }
}

TEST(SceneLoader, BadScenesNameFileLineAndField) {
  auto has = [](const std::string& yaml, const std::string& what) {
    const std::string e = error_of(yaml);
    EXPECT_NE(e.find(what), std::string::npos) << "error: '" << e << "' for:\n" << yaml;
  };
  has(kMinimal + "bogus: 1\n", "s.yaml:3: bogus: unknown key");
  has(kMinimal + "medium:\n  temprature_c: 20\n", "s.yaml:4: medium.temprature_c: unknown key");
  has(kMinimal + "medium:\n  temperature_c: hot\n", "s.yaml:4: medium.temperature_c: 'hot' is not a finite number");
  has(kMinimal + "medium:\n  relative_humidity: 120\n", "s.yaml:4: medium.relative_humidity: 120 is out of range");
  has("geometry:\n  distances_m: [0.5, 30]\n", "s.yaml:2: geometry.distances_m: 30 is out of range");
  has("geometry:\n  distances_m: 0.5\n", "geometry.distances_m: expected a list");
  has("geometry:\n  type: moving\n  distances_m: [1]\n", "not implemented yet");
  has(kMinimal + "excitation:\n  family: Gold9\n", "s.yaml:4: excitation.family");
  has(kMinimal + "excitation:\n  family: M1\n  codes: [8]\n", "family M1 has codes 1..7");
  has(kMinimal + "noise:\n  snr_db: 10\n  noise_v: 0.1\n", "not both");
  has(kMinimal + "receiver:\n  precision: double\n", "valid: float, fixed");
  has(kMinimal + "excitation:\n  schedule:\n    mode: periodic\n", "periodic mode needs period_s");
  has("name: x\n", "geometry: missing");
  has("", "empty");
  has("geometry: [\n", "YAML syntax error");
  has(kMinimal + "noise:\n  adc:\n    sample_rate: 3300000\n", "integer");
}

TEST(SceneSimulator, DeterministicForASeedAndTheSeedMatters) {
  const std::string yaml = "transducers: {}\ngeometry:\n  distances_m: [0.4]\n  repeats: 2\n"
                           "excitation:\n  family: M1\n  codes: [1, 4]\nnoise:\n  noise_v: 0.004\n  seed: 7\n";
  auto run = [](const std::string& y) {
    SceneSimulator sim(parse_scene(y, "s.yaml"));
    return sim.run("M1");
  };
  const auto a = run(yaml), b = run(yaml);
  ASSERT_EQ(a.size(), 4u);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].det.tof_s, b[i].det.tof_s);
    EXPECT_EQ(a[i].det.pearson_margin, b[i].det.pearson_margin);
    EXPECT_EQ(a[i].u, b[i].u);
    EXPECT_EQ(a[i].det.energy, b[i].det.energy);
    EXPECT_EQ(a[i].det.code, a[i].code_sent);
    EXPECT_LT(std::abs(a[i].error_m), 1e-4);
  }
  // Repeats see different noise, another seed other noise again.
  EXPECT_NE(a[0].det.energy, a[2].det.energy);
  std::string other = yaml;
  other.replace(other.find("seed: 7"), 7, "seed: 8");
  EXPECT_NE(run(other)[0].det.energy, a[0].det.energy);
}

// A sample rate that does not divide the configuration's 30 MHz clock (a 4 MS/s or 20 MS/s
// scope) gets the next multiple as the receiver's clock that the system can run at (the board's
// PLL makes it from 12 MHz, the 1.5 Mbaud UART divides it: 32 and 40 MHz are not made by the PLL),
// with a warning, and decodes; the system files (PLL, UART divider) generate for it, so the RTL
// and bitstream flows take it; a rate that divides it keeps the clock and says nothing.
TEST(SceneSimulator, ASampleRateThatDoesNotDivideTheClockMovesTheClockAndDecodes) {
  EXPECT_FALSE(find_ice40_pll(12e6, 32e6));
  EXPECT_FALSE(find_ice40_pll(12e6, 40e6));
  for (const auto& [rate, clock] : {std::pair{4e6, 36e6}, std::pair{20e6, 60e6}, std::pair{5e6, 30e6}}) {
    std::ostringstream y;
    y << "sample_rate: " << rate << "\ntransducers: {}\ngeometry:\n  distances_m: [0.3, 0.8]\n"
      << "excitation:\n  family: Gold4\n  codes: [2, 7]\nnoise:\n  noise_v: 0.002\n";
    const Scene scene = parse_scene(y.str(), "s.yaml");
    SCOPED_TRACE(rate);
    EXPECT_EQ(scene.receiver.config.clock_hz, clock);
    const bool moved = clock != 30e6;
    ASSERT_EQ(scene.warnings.size(), moved ? 1u : 0u);
    if (moved) {
      EXPECT_NE(scene.warnings[0].find("does not divide the receiver's hardware.clock_hz (30 MHz)"), std::string::npos)
          << scene.warnings[0];
      EXPECT_NE(scene.warnings[0].find("that the board's PLL makes and system.baud divides)"), std::string::npos)
          << scene.warnings[0];
    }
    const auto files = generate_system_files(design_receiver(scene.receiver.config), "s.yaml");
    EXPECT_NE(files.at("rtl/ice40_pll.vh").find("RANGING_CLK_HZ " + std::to_string(static_cast<long>(clock))),
              std::string::npos);
    SceneSimulator sim(scene);
    const auto rows = sim.run("Gold4");
    ASSERT_EQ(rows.size(), 4u);
    for (const auto& r : rows) {
      EXPECT_TRUE(r.detected);
      EXPECT_EQ(r.det.code, r.code_sent);
      EXPECT_LT(std::abs(r.error_m), 1e-3);
    }
  }
}

// A receiver configuration file whose signal keys differ from the scene's: the scene's win (the
// receiver runs on the scene's ADC stream) and a warning names each replaced key; the same file
// with matching keys gives no warning; the built-in configuration gives none either.
TEST(Scene, AConfigurationFilesSignalKeysReplacedByTheScenesAreNamed) {
  const testing_support::ScratchDir scratch("scene_cfg", ::testing::TempDir());
  const std::string dir = scratch.str();
  std::ofstream(dir + "/mine.yaml") << "name: mine\nsignal:\n  fs: 4000000\n  cycles_per_chip: 2\n"
                                       "correlator:\n  decimation: 10\nhardware:\n  clock_hz: 24000000\n";
  std::ofstream(dir + "/same.yaml") << "name: same\n";
  const std::string body = "transducers: {}\ngeometry:\n  distances_m: [0.5]\nexcitation:\n  family: M1\n";
  std::ofstream(dir + "/s.yaml") << body << "receiver:\n  config: mine.yaml\n";
  std::ofstream(dir + "/t.yaml") << body << "receiver:\n  config: same.yaml\n";
  const Scene s = load_scene(dir + "/s.yaml");
  ASSERT_GE(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("the scene's values replace receiver.config mine.yaml's signal.fs 4 MS/s -> "
                               "sample_rate 5 MS/s, signal.cycles_per_chip 2 -> excitation.cycles_per_chip 4"),
            std::string::npos)
      << s.warnings[0];
  EXPECT_EQ(s.receiver.config.fs, 5e6);
  EXPECT_EQ(s.receiver.config.cycles_per_chip, 4);
  EXPECT_EQ(s.receiver.config.clock_hz, 30e6);  // 24 MHz moved: 25 MHz is not made by the PLL
  EXPECT_TRUE(load_scene(dir + "/t.yaml").warnings.empty());
  EXPECT_TRUE(parse_scene(body, "u.yaml").warnings.empty());
}

TEST(SceneSimulator, StagesChangeTheSignalAsTheyShould) {
  auto energy_at = [](const std::string& extra, double d) {
    SceneSimulator sim(parse_scene("geometry:\n  distances_m: [" + std::to_string(d) +
                                       "]\nexcitation:\n  family: M1\n  codes: [1]\n" + extra, "s.yaml"));
    return sim.run("M1").at(0).det.energy;
  };
  // Spherical spreading: energy ~ 1/d^2 without absorption.
  EXPECT_NEAR(energy_at("", 0.2) / energy_at("", 0.8), 16.0, 0.05 * 16);
  // Absorption takes more at 1 m than at 0.2 m (ISO 9613-1, ~8 dB/m at 200 kHz, 20 C 50 %).
  const std::string air = "medium:\n  temperature_c: 20\n  relative_humidity: 50\n";
  const double loss_02 = energy_at(air, 0.2) / energy_at("", 0.2);
  const double loss_10 = energy_at(air, 1.0) / energy_at("", 1.0);
  EXPECT_LT(loss_10, loss_02);
  // Power and amplitude share the dB figure: -alpha * 0.8 m at the carrier; the burst is
  // broadband, its lower frequencies lose less, hence the tolerance.
  EXPECT_NEAR(10 * std::log10(loss_10 / loss_02), -absorption_db_per_m(200e3, {}) * 0.8, 0.6);
  // Directivity at half the beam angle is -3 dB per transducer: -6 dB of power... squared.
  EXPECT_NEAR(piston_directivity(14.5, 7.25), 1 / std::sqrt(2.0), 1e-6);
  const double off = energy_at("", 0.5);
  SceneSimulator tilted(parse_scene("geometry:\n  distances_m: [0.5]\n  angle_deg: 7.25\nexcitation:\n"
                                    "  family: M1\n  codes: [1]\n", "s.yaml"));
  EXPECT_NEAR(tilted.run("M1").at(0).det.energy / off, 0.25, 0.01);
}

TEST(Medium, SpeedOfSoundAndAbsorptionMatchPublishedValues) {
  // Cramer 1993: 331.46 m/s dry at 0 C (his zero-frequency value); ~343.2-343.4 at 20 C;
  // humidity raises it (~0.6 m/s at 50 %).
  EXPECT_NEAR(speed_of_sound({20, 0, 101.325}), 343.3, 0.15);
  EXPECT_GT(speed_of_sound({20, 50, 101.325}), speed_of_sound({20, 0, 101.325}) + 0.4);
  EXPECT_NEAR(speed_of_sound({0, 0, 101.325}), 331.46, 0.05);
  // ISO 9613-1 Table 1 at 20 C, 50 % RH, 101.325 kPa, 1 kHz: 4.66 dB/km; at 200 kHz the
  // classical f^2 term dominates: more than 7 dB/m.
  EXPECT_GT(absorption_db_per_m(200e3, {20, 50, 101.325}), 7.0);
  EXPECT_NEAR(absorption_db_per_m(1000, {20, 50, 101.325}) * 1e3, 4.66, 0.1);
  EXPECT_THROW(speed_of_sound({100, 50, 101.325}), InputError);
  // The FIR realizes the attenuation at the carrier within 0.05 dB.
  const auto h = absorption_fir({20, 50, 101.325}, 1.0, 5e6);
  double re = 0, im = 0;
  const double w = 2 * M_PI * 200e3 / 5e6;
  const long half = static_cast<long>(h.size() / 2);
  for (long n = 0; n < static_cast<long>(h.size()); ++n) {
    re += h[static_cast<std::size_t>(n)] * std::cos(w * (n - half));
    im += h[static_cast<std::size_t>(n)] * std::sin(w * (n - half));
  }
  EXPECT_NEAR(20 * std::log10(std::hypot(re, im)), -absorption_db_per_m(200e3, {20, 50, 101.325}), 0.05);
  EXPECT_NEAR(im, 0.0, 1e-9);  // zero phase: no added delay
  // The taps are the windowed inverse DFT of |H| on the 4096-point grid, as the direct sum
  // with libm's cosine gives them (the model reduces the argument exactly through a table).
  for (double dist : {0.1, 1.0, 7.0}) {
    const AirConditions air{20, 50, 101.325};
    const auto g = absorption_fir(air, dist, 5e6);
    ASSERT_EQ(g.size() % 2, 1u);
    const int hh = static_cast<int>(g.size() / 2);
    const int M = 4096;
    double peak = 0;
    for (double v : g) peak = std::max(peak, std::abs(v));
    for (int n = -hh; n <= hh; n += 7) {
      double acc = std::pow(10.0, -absorption_db_per_m(0, air) * dist / 20.0);
      for (int k = 1; k < M / 2; ++k) {
        acc += 2.0 * std::pow(10.0, -absorption_db_per_m(5e6 * k / M, air) * dist / 20.0) *
               std::cos(2.0 * M_PI * k * n / M);
      }
      acc += std::pow(10.0, -absorption_db_per_m(2.5e6, air) * dist / 20.0) * std::cos(M_PI * n);
      const double want = acc / M * kaiser_window(static_cast<double>(n) / (hh + 1), 8.0);
      EXPECT_NEAR(g[static_cast<std::size_t>(n + hh)], want, 1e-12 * peak) << dist << " m, tap " << n;
      EXPECT_EQ(g[static_cast<std::size_t>(n + hh)], g[static_cast<std::size_t>(hh - n)]);
    }
  }
}

TEST(SimulateCli, WritesCsvAndSummaryAndPrintsStages) {
  const testing_support::ScratchDir scratch("sim_cli", ::testing::TempDir());
  const std::string dir = scratch.file("out");  // made by simulate
  const ToolRun r = run_tool("simulate " + std::string(RANGING_SOURCE_DIR) + "/scenes/minimal.yaml --out " + dir +
                             " --quiet");
  ASSERT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("stages built (2)"), std::string::npos) << r.out;
  std::ifstream csv(dir + "/measurements.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("family,repeat,burst,true_distance_m,code_sent,code_decoded,tof_s,distance_m,error_m,"
                         "rho_max,rho_submax,u,energy_v2,td_s", 0), 0u);
  int rows = 0;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, 9);  // Gold4, one distance
  std::ifstream js(dir + "/summary.json");
  const auto j = nlohmann::json::parse(js);
  EXPECT_EQ(j["decode_errors"], 0);
  EXPECT_EQ(j["stages"].size(), 2u);
  for (const char* k : {"u_min", "energy_min_v2", "td_max_s", "vmax_hz", "distance_rmse_m", "decode_error_rate"}) {
    EXPECT_TRUE(j["families"][0].contains(k)) << k;
  }
  // Fixed precision decodes the same scene too; a bad option is exit 2 with nothing on stdout.
  const ToolRun fx = run_tool("simulate " + std::string(RANGING_SOURCE_DIR) + "/scenes/default.yaml --precision fixed --json --out " + dir);
  ASSERT_EQ(fx.status, 0);
  EXPECT_EQ(nlohmann::json::parse(fx.out)["decode_errors"], 0);
  for (const std::string& bad : {std::string("simulate /nonexistent.yaml"), "simulate " + std::string(RANGING_SOURCE_DIR) +
                                                                   "/scenes/minimal.yaml --precision double"}) {
    const ToolRun b = run_tool(bad);
    EXPECT_EQ(b.status, 2) << bad;
    EXPECT_TRUE(b.out.empty()) << bad;
  }
}

TEST(SceneSimulator, PeriodicTrainDecodesEveryBurstWithItsOwnTof) {
  // Bursts every 0.6 ms while a burst takes 2.9 ms to arrive at 1 m: several in flight.
  SceneSimulator sim(parse_scene("transducers: {}\ngeometry:\n  distances_m: [1.0]\nexcitation:\n  family: Gold4\n"
                                 "  schedule:\n    mode: periodic\n    period_s: 0.0006\n    bursts: 9\n", "s.yaml"));
  const auto rows = sim.run("Gold4");
  ASSERT_EQ(rows.size(), 9u);
  for (const auto& r : rows) {
    EXPECT_TRUE(r.detected);
    EXPECT_EQ(r.det.code, r.code_sent);
    EXPECT_NEAR(r.distance_m, 1.0, 1e-3);
  }
}

// receiver.metrics: a metric the scene does not name is not computed (NaN, no Pearson
// decoder), and what the receiver decodes does not depend on it.
TEST(SceneMetrics, UnnamedMetricsAreNotComputedAndTheReceiverDecodeIsUnchanged) {
  const std::string base = "transducers: {}\ngeometry:\n  distances_m: [0.3, 0.7]\n  repeats: 2\n"
                           "excitation:\n  family: M1\nnoise:\n  noise_v: 0.004\n  seed: 3\n";
  auto run = [&](const std::string& metrics, const std::string& precision) {
    std::string y = base + "receiver:\n  precision: " + precision + "\n";
    if (!metrics.empty()) y += "  metrics: " + metrics + "\n";
    const Scene sc = parse_scene(y, "s.yaml");
    SceneSimulator sim(sc);
    auto rows = sim.run("M1");
    return std::make_pair(rows, summarize(sc, "M1", rows));
  };
  for (const std::string prec : {"float", "fixed"}) {
    const auto [all, sall] = run("", prec);
    ASSERT_EQ(all.size(), 28u);
    const auto [none, snone] = run("[]", prec);
    const auto [pearson, sp] = run("[pearson]", prec);
    const auto [et, set] = run("[energy, td]", prec);
    for (const auto* v : {&none, &pearson, &et}) {
      ASSERT_EQ(v->size(), all.size());
      for (std::size_t i = 0; i < all.size(); ++i) {  // the receiver's decode, bit for bit
        EXPECT_EQ((*v)[i].detected, all[i].detected) << prec << " " << i;
        EXPECT_EQ((*v)[i].det.code, all[i].det.code);
        EXPECT_EQ((*v)[i].det.tof_s, all[i].det.tof_s);
        EXPECT_EQ((*v)[i].det.score, all[i].det.score);
        EXPECT_EQ((*v)[i].error_m, all[i].error_m);
      }
    }
    for (std::size_t i = 0; i < all.size(); ++i) {
      EXPECT_FALSE(all[i].det.rho.empty());
      EXPECT_TRUE(std::isfinite(all[i].det.energy) && std::isfinite(all[i].det.td_s));
      EXPECT_TRUE(none[i].det.rho.empty());
      EXPECT_TRUE(std::isnan(none[i].det.rho_max) && std::isnan(none[i].u));
      EXPECT_TRUE(std::isnan(none[i].det.energy) && std::isnan(none[i].det.td_s));
      EXPECT_FALSE(none[i].pearson_error);  // no Pearson decoder, no Pearson error
      EXPECT_EQ(pearson[i].det.rho, all[i].det.rho);
      EXPECT_EQ(pearson[i].u, all[i].u);
      EXPECT_TRUE(std::isnan(pearson[i].det.energy) && std::isnan(pearson[i].det.td_s));
      EXPECT_EQ(et[i].det.energy, all[i].det.energy);
      EXPECT_EQ(et[i].det.td_s, all[i].det.td_s);
      EXPECT_TRUE(et[i].det.rho.empty());
    }
    EXPECT_TRUE(std::isfinite(sall.u_min) && std::isfinite(sall.energy_min) && std::isfinite(sall.vmax_hz));
    EXPECT_TRUE(std::isnan(snone.u_min) && std::isnan(snone.energy_min) && std::isnan(snone.td_max_s) &&
                std::isnan(snone.vmax_hz));
    EXPECT_EQ(snone.pearson_errors, 0u);
    EXPECT_EQ(snone.decode_errors, snone.detector_errors + snone.range_ambiguous);
    EXPECT_EQ(snone.rmse_m, sall.rmse_m);
    EXPECT_EQ(sp.u_min, sall.u_min);
    EXPECT_EQ(set.td_max_s, sall.td_max_s);
    EXPECT_EQ(set.energy_min, sall.energy_min);
  }
}

TEST(SceneMetrics, BadMetricsListsNameTheEntryAndTheValidNames) {
  auto has = [](const std::string& yaml, const std::string& what) {
    const std::string e = error_of(yaml);
    EXPECT_NE(e.find(what), std::string::npos) << "error: '" << e << "' for:\n" << yaml;
  };
  has(kMinimal + "receiver:\n  metrics: [pearson, rho]\n",
      "s.yaml:4: receiver.metrics: metrics[1]: 'rho' is not valid; valid: pearson, energy, td");
  has(kMinimal + "receiver:\n  metrics: [td, td]\n", "receiver.metrics: metrics[1]: 'td' is listed twice");
  has(kMinimal + "receiver:\n  metrics: pearson\n", "receiver.metrics: expected a list");
}

TEST(SceneMetrics, SimulateMarksWhatItDidNotComputeAndEvaluateRefusesIt) {
  const testing_support::ScratchDir scratch("sim_metrics", ::testing::TempDir());
  const std::string dir = scratch.file("out");  // made by simulate (and dir + "_t" beside it)
  const std::string scene = std::string(RANGING_SOURCE_DIR) + "/scenes/default.yaml";
  const ToolRun r = run_tool("simulate " + scene + " --set 'receiver.metrics=[td]' --json --quiet --out " + dir);
  ASSERT_EQ(r.status, 0);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["metrics"], nlohmann::json::array({"td"}));
  EXPECT_GT(j["samples_simulated"].get<std::uint64_t>(), 100000u);
  const auto& f = j["families"][0];
  EXPECT_TRUE(f["pearson"].is_null());
  EXPECT_TRUE(f["u_min"].is_null());
  EXPECT_TRUE(f["energy_min_v2"].is_null());
  EXPECT_TRUE(f["td_max_s"].is_number());
  std::ifstream csv(dir + "/measurements.csv");
  std::string header, line;
  std::getline(csv, header);
  std::getline(csv, line);
  EXPECT_EQ(line.find(",,,,"), line.find(",,"));  // rho_max, rho_submax, u, energy_v2 empty
  EXPECT_NE(line.find(",,,,"), std::string::npos) << line;
  const ToolRun text = run_tool("simulate " + scene + " --set 'receiver.metrics=[]' --quiet --out " + dir + "_t");
  ASSERT_EQ(text.status, 0);
  EXPECT_NE(text.out.find("not computed (receiver.metrics): pearson, energy, td"), std::string::npos) << text.out;
  const ToolRun ev = run_tool("evaluate " + scene + " --set 'receiver.metrics=[]' --out " + dir + "_e");
  EXPECT_EQ(ev.status, 2);
  EXPECT_TRUE(ev.out.empty());
}

// simulate --timing: summary.json carries the seconds per stage (each >= 0; the default scene
// spends time in all three), and only when asked (the summary is otherwise reproducible).
TEST(SimulateCli, TimingRecordsTheSecondsPerStageOnlyWhenAsked) {
  const testing_support::ScratchDir scratch("sim_timing", ::testing::TempDir());
  const std::string dir = scratch.file("out");  // made by simulate
  const std::string scene = std::string(RANGING_SOURCE_DIR) + "/scenes/default.yaml";
  const ToolRun t = run_tool("simulate " + scene + " --quiet --timing --out " + dir);
  ASSERT_EQ(t.status, 0) << t.out;
  {
    std::ifstream js(dir + "/summary.json");
    const auto j = nlohmann::json::parse(js);
    ASSERT_TRUE(j.contains("stage_seconds"));
    for (const char* k : {"channel", "receiver", "metrics"}) {
      ASSERT_TRUE(j["stage_seconds"].contains(k)) << k;
      EXPECT_GT(j["stage_seconds"][k].get<double>(), 0.0) << k;
    }
  }
  const ToolRun n = run_tool("simulate " + scene + " --quiet --out " + dir);
  ASSERT_EQ(n.status, 0) << n.out;
  std::ifstream js(dir + "/summary.json");
  EXPECT_FALSE(nlohmann::json::parse(js).contains("stage_seconds"));
}
