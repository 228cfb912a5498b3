// Rotor blade crossings (model/sim/rotor.hpp) and propagation between moving transducers
// (model/sim/moving_channel.hpp), each against an independent calculation.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "model/base/error.hpp"
#include "model/config/receiver_config.hpp"
#include "model/hw/realtime.hpp"
#include "model/sim/channel.hpp"
#include "model/sim/moving_channel.hpp"
#include "model/sim/rotor.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"

using namespace ranging;
using ranging::testing_support::run_tool;

namespace {

Trajectory line(Vec3 p0, Vec3 v) {
  return {[=](double t) { return Vec3{p0[0] + v[0] * t, p0[1] + v[1] * t, p0[2] + v[2] * t}; },
          [=](double) { return v; }};
}

double dotv(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// Closed form for straight-line constant-velocity motion: with D = R(t_r) - T0 - v t_r and
// w = v - u, |D + w tau| = c tau is the quadratic (w.w - c^2) tau^2 + 2 D.w tau + D.D = 0,
// whose positive root (|w| < c) is the flight time.
double tau_closed_form(const Vec3& R, const Vec3& T0, const Vec3& v, const Vec3& u, double c, double t_r) {
  const Vec3 D{R[0] - T0[0] - v[0] * t_r, R[1] - T0[1] - v[1] * t_r, R[2] - T0[2] - v[2] * t_r};
  const Vec3 w{v[0] - u[0], v[1] - u[1], v[2] - u[2]};
  const double a = dotv(w, w) - c * c, b = 2 * dotv(D, w), cc = dotv(D, D);
  return (-b - std::sqrt(b * b - 4 * a * cc)) / (2 * a);
}

const std::string kRotorScene =
    "medium: {speed_of_sound: 340}\n"
    "transducers: {beam_angle_deg: 14.5}\n"
    "geometry:\n"
    "  type: rotor\n"
    "  radius_m: 4.244\n"
    "  rpm: 450\n"
    "  h_m: 0.3\n"
    "excitation:\n"
    "  family: M1\n"
    "  schedule: {mode: periodic, period_s: 0.00042}\n";

std::string error_of(const std::string& yaml) {
  try {
    (void)parse_scene(yaml, "s.yaml");
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string replace(std::string s, const std::string& a, const std::string& b) {
  const auto p = s.find(a);
  EXPECT_NE(p, std::string::npos) << a;
  if (p != std::string::npos) s.replace(p, a.size(), b);
  return s;
}

}  // namespace

TEST(MovingChannel, EmissionTimeMatchesTheStraightLineQuadratic) {
  const double c = 340;
  const Vec3 T0{-0.4, 0.02, 0.3}, vt{170, 0, 0}, R0{0.4, 0, 0}, vr{-170, 0, 0};
  for (const Vec3 u : {Vec3{0, 0, 0}, Vec3{12, -5, 3}}) {
    MovingLink L;
    L.tx = line(T0, vt);
    L.rx = line(R0, vr);
    L.c = c;
    L.wind = u;
    for (double t_r = 0.0; t_r < 0.006; t_r += 0.00037) {
      const Vec3 R{R0[0] + vr[0] * t_r, R0[1], R0[2]};
      const double tau = tau_closed_form(R, T0, vt, u, c, t_r);
      const double te = emission_time(L, t_r, t_r - 0.01);
      EXPECT_NEAR(t_r - te, tau, 1e-12) << "t_r " << t_r;
      // The inverse problem returns the same reception time.
      EXPECT_NEAR(reception_time(L, te, te + 0.002), t_r, 1e-12);
    }
  }
}

TEST(MovingChannel, DopplerRatioIsTheDerivativeOfTheEmissionTime) {
  MovingLink L;
  L.tx = line({-0.4, 0, 0.3}, {170, 0, 0});
  L.rx = line({0.4, 0, 0}, {-170, 0, 0});
  L.wind = {5, 2, 0};
  for (double t_r : {0.0005, 0.002, 0.0035}) {
    const Ray ry = ray_at(L, t_r, t_r - 0.001);
    const double h = 1e-7;
    const double num = (emission_time(L, t_r + h, ry.t_e) - emission_time(L, t_r - h, ry.t_e)) / (2 * h);
    EXPECT_NEAR(ry.doppler, num, 1e-6);
  }
  // Approaching: compressed (ratio > 1); receding: stretched.
  EXPECT_GT(ray_at(L, 0.0005, 0).doppler, 1.2);
  EXPECT_LT(ray_at(L, 0.0045, 0).doppler, 0.8);
}

TEST(MovingChannel, StaticCaseEqualsTheStaticChannel) {
  const double fs = 5e6, c = 340, d = 0.3217;
  std::vector<double> x(400, 0.0);
  for (std::size_t n = 0; n < x.size(); ++n) x[n] = std::sin(2 * std::numbers::pi * 200e3 * n / fs) * std::exp(-1e-4 * (n - 200.0) * (n - 200.0));
  ChannelParams cp;
  cp.speed_of_sound = c;
  cp.distance_m = d;
  cp.gain = 0.7;
  cp.tx.bypass = cp.rx.bypass = true;
  const std::size_t n_out = 6000;
  const auto ref = propagate(x, cp, fs, n_out);
  MovingLink L;
  L.tx = line({0, 0, d}, {0, 0, 0});
  L.rx = line({0, 0, 0}, {0, 0, 0});
  L.c = c;
  L.gain = 0.7;
  const auto y = render_moving(L, x, 0, 0, n_out, fs);
  double peak = 0, err = 0;
  for (std::size_t n = 0; n < n_out; ++n) {
    peak = std::max(peak, std::abs(ref[n]));
    err = std::max(err, std::abs(y[n] - ref[n]));
  }
  EXPECT_GT(peak, 0.1);
  EXPECT_LT(err, 1e-3 * peak);  // the tabulated interpolator: 1/8192 sample of timing
}

TEST(MovingChannel, PistonDirectivityAtBothEndsOffAxis) {
  // Static, 10 degrees off both axes: amplitude = 0.1/d * D(10 deg)^2 (scene_simulator's piston).
  const double d = 0.5, a = 10.0 * std::numbers::pi / 180.0;
  MovingLink L;
  L.tx = line({0, 0, d * std::cos(a)}, {0, 0, 0});
  L.rx = line({d * std::sin(a), 0, 0}, {0, 0, 0});
  L.ka = piston_ka(14.5);
  const Ray ry = ray_at(L, 0.01, 0);
  EXPECT_NEAR(ry.amplitude, 0.1 / d * std::pow(piston_directivity(14.5, 10.0), 2), 1e-12);
  EXPECT_NEAR(piston_pattern(piston_ka(14.5) * std::sin(7.25 * std::numbers::pi / 180)), std::sqrt(0.5), 1e-8);
}

TEST(RotorGeometry, PaperNumbers) {
  const Scene s = parse_scene(kRotorScene, "s.yaml");
  const RotorParams& p = s.geometry.rotor;
  EXPECT_NEAR(p.omega_u() * p.r() + p.omega_l() * p.r(), 340.0, 0.1);  // V_R-Lover
  // Section 2.1: w(100 mm) = 320 mm needs tan(alpha) = 1.6; the 14.5 degree cone gives 25.4 mm.
  EXPECT_NEAR(static_window_m(0.1, 7.25), 0.02544, 1e-4);
  EXPECT_NEAR(2 * 340.0 / static_window_m(0.1, std::atan(1.6) * 180 / std::numbers::pi), 2125.0, 1e-6);
  // Crossings of one TX with the four lower blades: every 2 pi / (4 * 2 Omega).
  EXPECT_NEAR(p.crossing_interval_s(), 60.0 / 450 / 8, 1e-12);
}

TEST(RotorGeometry, StagesReplaceDelayAndGainByTheMovingChannel) {
  const auto st = scene_stages(parse_scene(kRotorScene, "s.yaml"));
  std::string names;
  for (const auto& x : st) names += x.name + " ";
  EXPECT_EQ(names, "transducers moving ");
}

TEST(RotorGeometry, BadGeometryNamesTheKey) {
  auto has = [](const std::string& yaml, const std::string& what) {
    const std::string e = error_of(yaml);
    EXPECT_NE(e.find(what), std::string::npos) << "error: '" << e << "'";
  };
  has(replace(kRotorScene, "  rpm: 450\n", "  rpm: 450\n  transducer_radius_m: 5\n"), "s.yaml:7: geometry.transducer_radius_m");
  has(replace(kRotorScene, "rpm: 450", "rpm: 0"), "s.yaml:6: geometry.rpm: 0 is not valid");
  has(replace(kRotorScene, "rpm: 450", "rpm: -3"), "geometry.rpm");
  has(replace(kRotorScene, "h_m: 0.3", "h_m: 0"), "s.yaml:7: geometry.h_m: 0 m is not valid");
  has(replace(kRotorScene, "h_m: 0.3", "h_m: [0.3, -0.1]"), "geometry.h_m");
  has(replace(kRotorScene, "rpm: 450", "rpm: 800"), "geometry.rpm: blade tip speed");
  has(replace(kRotorScene, "h_m: 0.3", "h_m: 1.2"), "unambiguous range");
  has(replace(kRotorScene, "  h_m: 0.3\n", "  h_m: 0.3\n  transducer_radius_fraction: 1.2\n"),
      "geometry.transducer_radius_fraction");
  has(replace(kRotorScene, "  schedule: {mode: periodic, period_s: 0.00042}\n", ""), "excitation.schedule.period_s");
  // Through the tool: exit 2, nothing on stdout, the key named.
  const testing_support::ScratchDir scratch("rotor_bad", ::testing::TempDir());
  const std::string path = scratch.file("rotor_bad.yaml");
  std::ofstream(path) << replace(kRotorScene, "rpm: 450", "rpm: 0");
  const auto r = run_tool("simulate " + path + " --out " + scratch.file("rotor_bad_out"));
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("geometry.rpm"), std::string::npos) << r.err;
}

// Noise-free ToFs computed here by bisection on the circular kinematics (independent of the
// Newton solver), for bursts emitted around the crossing.
namespace {
std::vector<TofSample> synthetic(const RotorParams& p, double h, double tc, double c, double burst_s,
                                 const std::vector<double>& t_emit, bool motion) {
  const double r = p.r(), wu = p.omega_u(), wl = p.omega_l();
  auto tx = [&](double t) { return Vec3{r * std::cos(wu * t), r * std::sin(wu * t), h}; };
  auto rx = [&](double t) {
    const double a = wu * tc - wl * (t - tc);
    return Vec3{r * std::cos(a), r * std::sin(a), 0};
  };
  std::vector<TofSample> out;
  for (double te0 : t_emit) {
    const double te = te0 + burst_s / 2;
    const Vec3 T = tx(te);
    double tau;
    if (motion) {
      double lo = 0, hi = 1;  // f(tau) = |R(te + tau) - T| - c tau: positive at 0, negative at 1 s
      for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        const Vec3 R = rx(te + mid);
        const double f = std::sqrt(std::pow(R[0] - T[0], 2) + std::pow(R[1] - T[1], 2) + std::pow(R[2] - T[2], 2)) - c * mid;
        (f > 0 ? lo : hi) = mid;
      }
      tau = 0.5 * (lo + hi);
    } else {
      const Vec3 R = rx(te);  // the paper's picture: both at one instant
      tau = std::sqrt(std::pow(R[0] - T[0], 2) + std::pow(R[1] - T[1], 2) + h * h) / c;
    }
    out.push_back({te0, tau});
  }
  return out;
}
}  // namespace

TEST(RotorEstimators, MotionAwareRecoversHFromExactToFs) {
  const Scene s = parse_scene(kRotorScene, "s.yaml");
  const RotorParams& p = s.geometry.rotor;
  const double c = 340, burst = 140e-6;
  for (double h : {0.1, 0.35, 0.8}) {
    const double tc = 0.0123;
    const auto m = synthetic(p, h, tc, c, burst, {tc - 0.0009, tc - 0.0005, tc - 0.0001}, true);
    double tc_est = 0;
    const double est = estimate_h_motion(p, m, c, burst, &tc_est);
    EXPECT_NEAR(est, h, 1e-6) << h;
    EXPECT_NEAR(tc_est, tc, 1e-8);
    // Two measurements suffice.
    EXPECT_NEAR(estimate_h_motion(p, {m[0], m[2]}, c, burst), h, 1e-6);
    // The paper's eq. 1 on the same ToFs is biased by the motion during flight.
    const double paper = estimate_h_paper(m, c, p.omega_u() * p.r() + p.omega_l() * p.r());
    EXPECT_GT(std::abs(paper - h), 1e-4) << h;
  }
  EXPECT_TRUE(std::isnan(estimate_h_motion(p, {{0.01, 0.001}}, c, burst)));
}

TEST(RotorEstimators, PaperHeronIsExactForInstantaneousStraightGeometry) {
  // Relative straight-line motion at v_rel, closest approach h: d(t) = sqrt(h^2 + (v t)^2).
  const double c = 340, v = 340, h = 0.25;
  const std::vector<TofSample> m{{-0.0004, std::hypot(h, v * 0.0004) / c}, {0.0002, std::hypot(h, v * 0.0002) / c},
                                 {0.0009, std::hypot(h, v * 0.0009) / c}};
  EXPECT_NEAR(estimate_h_paper(m, c, v), h, 1e-12);
  // On the rotor's circles (instantaneous distances) the chord curvature is all that is left.
  const Scene s = parse_scene(kRotorScene, "s.yaml");
  const RotorParams& p = s.geometry.rotor;
  const auto mi = synthetic(p, 0.3, 0.02, c, 0, {0.0197, 0.0202}, false);
  EXPECT_NEAR(estimate_h_paper(mi, c, p.omega_u() * p.r() * 2), 0.3, 1e-4);
  EXPECT_TRUE(std::isnan(estimate_h_paper({m[0]}, c, v)));
}

TEST(RotorEstimators, ConsistentChainDropsMisdecodes) {
  const double c = 340, v = 340;
  std::vector<TofSample> m;
  for (int k = 0; k < 5; ++k) m.push_back({k * 0.00042, std::hypot(0.5, v * (k - 2) * 0.00042) / c});
  m.push_back({0.0009, 0.03 / c});   // a wrong code: another burst's send time
  m.push_back({0.0013, 0.91 / c});
  const auto ch = consistent_chain(m, c, v, 0.005);
  ASSERT_EQ(ch.size(), 5u);
  for (const auto& s : ch) EXPECT_GT(s.tof_s * c, 0.4);
}

TEST(RotorScene, SlowCrossingEndToEnd) {
  // 60 RPM: tips at 23 m/s, several bursts inside the 14.5 degree beam; both estimators work.
  const testing_support::ScratchDir scratch("rotor_e2e", ::testing::TempDir());
  const std::string dir = scratch.file("out");  // made by simulate
  const std::string path = dir + ".yaml";
  std::ofstream(path) << "name: slow\nmedium: {speed_of_sound: 340}\n"
                         "transducers: {beam_angle_deg: 14.5, sensitivity: 0.165}\n"
                         "geometry: {type: rotor, radius_m: 4.244, rpm: 60, h_m: [0.3, 0.6], crossings: 2,"
                         " window_angle_deg: 20}\n"
                         "excitation: {family: M1, schedule: {mode: periodic, period_s: 0.00042}}\n"
                         "noise: {noise_v: 0.005, seed: 3, adc: {bits: 12, full_scale_v: 5.0}}\n"
                         "receiver: {precision: fixed}\n";
  const auto r = run_tool("simulate " + path + " --out " + dir + " --quiet");
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream in(dir + "/summary.json");
  const auto j = nlohmann::json::parse(in);
  ASSERT_EQ(j["crossings"].size(), 2u);
  const double hs[] = {0.3, 0.6};
  for (int i = 0; i < 2; ++i) {
    const auto& c = j["crossings"][static_cast<std::size_t>(i)];
    EXPECT_EQ(c["index"], i);
    EXPECT_NEAR(c["h_true_m"].get<double>(), hs[i], 1e-12);
    EXPECT_GE(c["measurements"].get<int>(), 2);
    ASSERT_FALSE(c["h_est_m"].is_null());
    ASSERT_FALSE(c["h_est_paper_m"].is_null());
    EXPECT_NEAR(c["h_est_m"].get<double>(), hs[i], 1e-3);
    EXPECT_NEAR(c["h_est_paper_m"].get<double>(), hs[i], 2e-3);
    EXPECT_GT(c["t_s"].get<double>(), 0);
  }
  EXPECT_TRUE(std::filesystem::exists(dir + "/bursts.csv"));
}

TEST(RotorDoppler, ConstantLineOfSightSpeed) {
  Scene s = parse_scene(
      "medium: {speed_of_sound: 340}\ntransducers: {sensitivity: 0.165}\ngeometry: {distances_m: [0.5]}\n"
      "excitation: {family: M1, schedule: {mode: periodic, period_s: 0.00042}}\nreceiver: {precision: fixed}\n",
      "s.yaml");
  SceneSimulator sim(s);
  const DopplerPoint still = doppler_point(sim, 0.5, 0.0, 1);
  EXPECT_EQ(still.bursts, 7);
  EXPECT_EQ(still.decoded, 7);
  EXPECT_LT(std::abs(still.bias_start_m), 1e-4);
  EXPECT_NEAR(still.doppler, 1.0, 1e-12);
  // A receiver closing on a fixed source at v hears (c + v)/c.
  const DopplerPoint moving = doppler_point(sim, 0.5, 17.0, 1);
  EXPECT_NEAR(moving.doppler, (340.0 + 17.0) / 340.0, 1e-9);
  EXPECT_EQ(moving.bursts, moving.decoded + moving.misdecoded + moving.missed);
}

TEST(RotorDoppler, TwoCyclesPerChipRemedyDoublesTheTolerance) {
  // The remedy of docs/results/blade-crossing.md, section 6: configs/doppler-q2.yaml (2 carrier
  // cycles per chip, decimation 25) decodes every burst at 6 m/s line-of-sight speed, where the
  // 4-cycle default decodes none; its bank stays real time at 30 MHz, and the 10-decimation
  // alternative is not.
  const std::string src = RANGING_SOURCE_DIR;
  const std::string link =
      "medium: {speed_of_sound: 340}\ntransducers: {sensitivity: 0.165}\ngeometry: {distances_m: [0.5]}\n"
      "noise: {noise_v: 0.005, seed: 7, adc: {bits: 12, full_scale_v: 5.0}}\n";
  Scene q2 = parse_scene(link + "excitation: {family: M1, cycles_per_chip: 2, schedule: {mode: periodic, "
                                "period_s: 0.00042}}\nreceiver: {precision: fixed, config: " +
                             src + "/configs/doppler-q2.yaml}\n",
                         "q2.yaml");
  Scene q4 = parse_scene(link + "excitation: {family: M1, schedule: {mode: periodic, period_s: 0.00042}}\n"
                                "receiver: {precision: fixed}\n",
                         "q4.yaml");
  SceneSimulator sim2(q2), sim4(q4);
  const DopplerPoint fast2 = doppler_point(sim2, 0.5, 6.0, 2);
  const DopplerPoint fast4 = doppler_point(sim4, 0.5, 6.0, 2);
  EXPECT_EQ(fast2.bursts, 14);
  EXPECT_EQ(fast2.decoded, fast2.bursts);
  EXPECT_LT(std::abs(fast2.bias_centre_m), 1e-3);
  EXPECT_EQ(fast4.bursts, 14);
  EXPECT_LT(fast4.decoded, fast4.bursts / 2);
  // Beyond the doubled tolerance the remedy fails too: the limit is real, not a broken check.
  const DopplerPoint faster2 = doppler_point(sim2, 0.5, 12.0, 2);
  EXPECT_LT(faster2.decoded, faster2.bursts);

  const auto cfg = load_receiver_config(src + "/configs/doppler-q2.yaml");
  EXPECT_EQ(cfg.cycles_per_chip, 2);
  const RealTimeBudget rt = realtime_budget(design_receiver(cfg));
  EXPECT_TRUE(rt.real_time) << rt.summary();
  const RealTimeBudget rt10 = realtime_budget(design_receiver(load_receiver_config(
      src + "/configs/doppler-q2.yaml", Overrides{{"correlator.decimation", "10"}})));
  EXPECT_FALSE(rt10.real_time) << rt10.summary();
}

// The rotor simulator's ADC is the scenes' (model/sim/front_end.hpp): a full scale far below
// the received bursts clips, and the run says how many samples (summary and text), where the
// rotor's own ADC used to clip silently; a DC offset fault moves what the ADC outputs.
TEST(RotorScene, AdcClippingIsCountedAndFaultsApply) {
  const testing_support::ScratchDir scratch("rotor_clip", ::testing::TempDir());
  const std::string dir = scratch.file("out");  // made by simulate
  auto scene = [&](const std::string& adc) {
    const std::string path = dir + ".yaml";
    std::ofstream(path) << "name: clip\nmedium: {speed_of_sound: 340}\n"
                           "transducers: {beam_angle_deg: 14.5, sensitivity: 0.165}\n"
                           "geometry: {type: rotor, radius_m: 4.244, rpm: 60, h_m: [0.3], crossings: 1,"
                           " window_angle_deg: 20}\n"
                           "excitation: {family: M1, schedule: {mode: periodic, period_s: 0.00042}}\n"
                           "noise: {noise_v: 0.005, seed: 3, adc: {" + adc + "}}\n";
    return path;
  };
  auto clipped = [&](const std::string& adc, std::string* text = nullptr) {
    const auto r = run_tool("simulate " + scene(adc) + " --out " + dir);
    EXPECT_EQ(r.status, 0) << r.err;
    if (text) *text = r.out;
    std::ifstream in(dir + "/summary.json");
    return nlohmann::json::parse(in)["adc_clipped"].get<std::uint64_t>();
  };
  EXPECT_EQ(clipped("bits: 12, full_scale_v: 5.0"), 0u);
  std::string text;
  const auto n = clipped("bits: 12, full_scale_v: 0.001", &text);
  EXPECT_GT(n, 100u);
  EXPECT_NE(text.find(std::to_string(n) + " ADC samples clipped"), std::string::npos) << text;
  // A DC offset of 2 full scales puts every sample on the top rail.
  EXPECT_GT(clipped("bits: 12, full_scale_v: 5.0, dc_offset_v: 10.0"), 1000u);
}
