#include "model/sim/rotor.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>

#include "model/base/error.hpp"
#include "model/config/yaml_reader.hpp"
#include "model/dsp/codes.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/transducer.hpp"
#include "model/sim/channel.hpp"
#include "model/sim/front_end.hpp"
#include "model/sim/medium.hpp"
#include "model/sim/metrics.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"

namespace ranging {

namespace {
constexpr double kPi = std::numbers::pi;
double deg(double r) { return r * 180.0 / kPi; }
double rad(double d) { return d * kPi / 180.0; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
std::string num(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}
}  // namespace

double RotorParams::omega_u() const { return rpm * 2.0 * kPi / 60.0; }
double RotorParams::omega_l() const { return (rpm_lower > 0 ? rpm_lower : rpm) * 2.0 * kPi / 60.0; }
double RotorParams::crossing_interval_s() const { return 2.0 * kPi / (blades * (omega_u() + omega_l())); }
double RotorParams::crossing_time_s(int i) const { return crossing_interval_s() * (0.5 + i); }
double RotorParams::h_of(int i) const {
  const auto ui = static_cast<std::size_t>(i);
  double h = h_m[ui % h_m.size()];
  if (!blade_offsets_m.empty()) h += blade_offsets_m[(ui % static_cast<std::size_t>(blades)) % blade_offsets_m.size()];
  h += flap_amplitude_m * std::cos(omega_u() * crossing_time_s(i) - rad(flap_phase_deg));
  return h;
}

void parse_rotor(yaml::Reader& r, RotorParams& p, double c) {
  r.get_range("radius_m", p.radius_m, 1e-3, 100.0);
  r.get_range("rpm", p.rpm, -1e9, 1e9);
  if (p.rpm <= 0) r.error("rpm", num(p.rpm) + " is not valid; the rotor speed must be > 0 RPM");
  if (r.get_range("rpm_lower", p.rpm_lower, -1e9, 1e9) && p.rpm_lower <= 0) {
    r.error("rpm_lower", num(p.rpm_lower) + " is not valid; the rotor speed must be > 0 RPM");
  }
  r.get_range("blades", p.blades, 1, 64);
  const bool frac = r.get_range("transducer_radius_fraction", p.transducer_radius_fraction, -1e9, 1e9);
  double tr = 0;
  if (r.get_range("transducer_radius_m", tr, -1e9, 1e9)) {
    if (frac) r.error("transducer_radius_m", "give transducer_radius_m or transducer_radius_fraction, not both");
    if (tr <= 0 || tr > p.radius_m) {
      r.error("transducer_radius_m", num(tr) + " m is not valid; valid range is (0, radius_m = " + num(p.radius_m) + "]");
    }
    p.transducer_radius_fraction = tr / p.radius_m;
  } else if (p.transducer_radius_fraction <= 0 || p.transducer_radius_fraction > 1) {
    r.error("transducer_radius_fraction", num(p.transducer_radius_fraction) +
                                              " is not valid; the transducer sits on the blade: valid range is (0, 1]");
  }
  if (r.has("h_m") && r.node("h_m").IsSequence()) {
    r.get_list("h_m", p.h_m);
    if (p.h_m.empty()) r.error("h_m", "give at least one vertical separation (metres)");
  } else {
    double h = p.h_m.front();
    if (r.get("h_m", h)) p.h_m = {h};
  }
  for (double h : p.h_m) {
    if (!(h > 0) || h > 20) r.error("h_m", num(h) + " m is not valid; the vertical separation must be in (0, 20] m");
  }
  r.get_list("blade_offsets_m", p.blade_offsets_m);
  r.get_range("flap_amplitude_m", p.flap_amplitude_m, 0, 20);
  r.get_range("flap_phase_deg", p.flap_phase_deg, -360, 360);
  std::vector<double> wind;
  if (r.get_list("wind_mps", wind)) {
    if (wind.size() != 3) r.error("wind_mps", "give three components [x, y, z] in m/s");
    p.wind_mps = {wind[0], wind[1], wind[2]};
  }
  r.get_range("crossings", p.crossings, 1, 1000000);
  r.get_range("window_angle_deg", p.window_angle_deg, 1, 85);
  r.get_range("accept_score", p.accept_score, 0, 1);
  r.get_range("chain_tolerance_m", p.chain_tolerance_m, 0, 10);
  const double tip = p.omega_u() * p.radius_m, tip_l = p.omega_l() * p.radius_m;
  const double w = norm(p.wind_mps);
  if (tip + w >= c) {
    r.error("rpm", "blade tip speed " + num(tip) + " m/s (radius_m x rpm) plus wind " + num(w) +
                       " m/s is at or above the speed of sound " + num(c) + " m/s");
  }
  if (tip_l + w >= c) {
    r.error("rpm_lower", "lower blade tip speed " + num(tip_l) + " m/s plus wind " + num(w) +
                             " m/s is at or above the speed of sound " + num(c) + " m/s");
  }
  for (int i = 0; i < std::min(p.crossings, 100000); ++i) {
    if (!(p.h_of(i) > 0)) {
      r.error(p.blade_offsets_m.empty() ? "flap_amplitude_m" : "blade_offsets_m",
              "the vertical separation at crossing " + std::to_string(i) + " is " + num(p.h_of(i)) +
                  " m; it must stay > 0 (the blades would collide)");
    }
  }
}

void check_rotor_scene(Scene& s) {
  const std::string at = s.origin + ": ";
  if (s.excitation.schedule.period_s <= 0) {
    throw InputError(at + "excitation.schedule.period_s: a rotor scene emits continuously; give the burst period");
  }
  if (s.excitation.families.size() != 1) throw InputError(at + "excitation.family: a rotor scene sends one family");
  if (!s.excitation.codes.empty()) {
    throw InputError(at + "excitation.codes: a rotor scene cycles every code of the family (the scheduler's rule)");
  }
  const RotorParams& rp = s.geometry.rotor;
  const double unambiguous = code_family(s.excitation.families.front()).eta() * s.excitation.schedule.period_s * s.speed();
  for (int i = 0; i < std::min(rp.crossings, 100000); ++i) {
    if (rp.h_of(i) >= unambiguous) {
      throw InputError(at + "geometry.h_m: the vertical separation at crossing " + std::to_string(i) + " (" +
                       num(rp.h_of(i)) + " m) is at or beyond the unambiguous range eta T c = " + num(unambiguous) +
                       " m of the schedule: its ToF would alias to a shorter distance");
    }
  }
  if (s.max_range_m <= 0) {
    const RotorParams& p = s.geometry.rotor;
    double l = 0;
    for (int i = 0; i < std::min(p.crossings, 100000); ++i) l = std::max(l, p.h_of(i));
    s.max_range_m = l / std::cos(rad(p.window_angle_deg));
  }
}

double static_window_m(double d, double half_angle_deg) { return 2.0 * d * std::tan(rad(half_angle_deg)); }

Trajectory rotor_tx(const RotorParams& p, double h) {
  const double r = p.r(), w = p.omega_u();
  return {[=](double t) { return Vec3{r * std::cos(w * t), r * std::sin(w * t), h}; },
          [=](double t) { return Vec3{-r * w * std::sin(w * t), r * w * std::cos(w * t), 0.0}; }};
}

Trajectory rotor_rx(const RotorParams& p, double t_c) {
  const double r = p.r(), wl = p.omega_l(), psi = p.omega_u() * t_c;
  return {[=](double t) {
            const double a = psi - wl * (t - t_c);
            return Vec3{r * std::cos(a), r * std::sin(a), 0.0};
          },
          [=](double t) {
            const double a = psi - wl * (t - t_c);
            return Vec3{r * wl * std::sin(a), -r * wl * std::cos(a), 0.0};
          }};
}

double estimate_h_paper(const std::vector<TofSample>& m, double c, double v_rel) {
  if (m.size() < 2) return std::numeric_limits<double>::quiet_NaN();
  std::vector<TofSample> s = m;
  std::sort(s.begin(), s.end(), [](const TofSample& a, const TofSample& b) { return a.tof_s < b.tof_s; });
  const double dm = c * s[0].tof_s, dn = c * s[1].tof_s;
  const double base = v_rel * std::abs(s[1].t_emit_s - s[0].t_emit_s);
  try {
    return heron_vertical_distance(dm, dn, base);
  } catch (const InputError&) {
    return std::numeric_limits<double>::quiet_NaN();
  }
}

double estimate_h_motion(const RotorParams& p, const std::vector<TofSample>& m, double c, double burst_s,
                         double* t_c_out) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (m.size() < 2) return nan;
  // Start: the shortest measurement; symmetric counter-rotation puts the crossing at the
  // midpoint of its emission and reception.
  const auto* best = &m.front();
  for (const auto& s : m) {
    if (s.tof_s < best->tof_s) best = &s;
  }
  double h = c * best->tof_s;
  double tc = best->t_emit_s + burst_s / 2 + best->tof_s / 2;
  const double r = p.r(), wu = p.omega_u(), wl = p.omega_l();
  const Vec3 u = p.wind_mps;
  auto res = [&](double hh, double tcc, const TofSample& s) {
    const double te = s.t_emit_s + burst_s / 2, tr = te + s.tof_s;
    const double a = wu * tcc - wl * (tr - tcc);
    const Vec3 d{r * std::cos(a) - r * std::cos(wu * te) - u[0] * s.tof_s,
                 r * std::sin(a) - r * std::sin(wu * te) - u[1] * s.tof_s, -hh - u[2] * s.tof_s};
    return norm(d) - c * s.tof_s;
  };
  // Normal equations of the 2-parameter Gauss-Newton step at (h, tc), numeric Jacobian.
  struct Normal {
    double a11 = 0, a12 = 0, a22 = 0, b1 = 0, b2 = 0;
    double det() const { return a11 * a22 - a12 * a12; }
  };
  auto normal = [&](double hh, double tt) {
    Normal ne;
    const double eh = 1e-7, et = 1e-9;
    for (const auto& s : m) {
      const double f = res(hh, tt, s);
      const double jh = (res(hh + eh, tt, s) - res(hh - eh, tt, s)) / (2 * eh);
      const double jt = (res(hh, tt + et, s) - res(hh, tt - et, s)) / (2 * et);
      ne.a11 += jh * jh;
      ne.a12 += jh * jt;
      ne.a22 += jt * jt;
      ne.b1 += jh * f;
      ne.b2 += jt * f;
    }
    return ne;
  };
  for (int it = 0; it < 50; ++it) {
    const Normal ne = normal(h, tc);
    const double det = ne.det();
    if (!(std::abs(det) > 0)) return nan;
    const double dh = (ne.a22 * ne.b1 - ne.a12 * ne.b2) / det, dt = (ne.a11 * ne.b2 - ne.a12 * ne.b1) / det;
    h -= dh;
    tc -= dt;
    h = std::abs(h);
    if (std::abs(dh) < 1e-10 && std::abs(dt) < 1e-13) break;
  }
  // Converged when a further step moves h by less than a nanometre.
  const Normal ne = normal(h, tc);
  const double det = ne.det();
  if (!(std::abs(det) > 0) || std::abs((ne.a22 * ne.b1 - ne.a12 * ne.b2) / det) > 1e-9 || !std::isfinite(h)) return nan;
  if (t_c_out) *t_c_out = tc;
  return h;
}

std::vector<TofSample> consistent_chain(std::vector<TofSample> m, double c, double v_rel, double tolerance_m) {
  std::sort(m.begin(), m.end(), [](const TofSample& a, const TofSample& b) { return a.t_emit_s < b.t_emit_s; });
  const std::size_t n = m.size();
  if (n < 2) return m;
  // Longest chain (by count, then by the smallest spread) in which successive measurements
  // change distance by at most v_rel |dt| + tolerance: the slant distance cannot change faster.
  std::vector<int> len(n, 1), prev(n, -1);
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      const double dd = std::abs(c * (m[j].tof_s - m[i].tof_s));
      const double dt = m[j].t_emit_s - m[i].t_emit_s;
      if (dt > 0 && dd <= v_rel * dt + tolerance_m && len[i] + 1 > len[j]) {
        len[j] = len[i] + 1;
        prev[j] = static_cast<int>(i);
      }
    }
  }
  std::size_t best = 0;
  for (std::size_t j = 1; j < n; ++j) {
    if (len[j] > len[best]) best = j;
  }
  std::vector<TofSample> out;
  for (int k = static_cast<int>(best); k >= 0; k = prev[static_cast<std::size_t>(k)]) out.push_back(m[static_cast<std::size_t>(k)]);
  std::reverse(out.begin(), out.end());
  return out;
}

namespace {

// What the rotor crossings and the Doppler points share: the scene's first family sent every
// period through the moving channel (model/sim/moving_channel.hpp).
struct MovingReception {
  std::vector<double> y;         // the ADC's output, volts
  long r0 = 0;                   // the sample of y[0]
  std::size_t adc_clipped = 0;   // samples the ADC clipped
};

struct MovingBursts {
  const Scene& s;
  std::string family;
  CodeFamily fam;
  int eta, q;
  double fs, c;
  long period, burst_len;
  long ring;  // 30 amplitude time constants Q/(pi f0) of the TX transducer's ring-down
  TransducerParams tp;
  ExcitationParams ex;

  explicit MovingBursts(const Scene& scene)
      : s(scene),
        family(s.excitation.families.front()),
        fam(code_family(family)),
        eta(fam.eta()),
        q(s.excitation.q_of(family)),
        fs(s.fs),
        c(s.speed()),
        period(std::lround(s.excitation.schedule.period_s * fs)),
        burst_len(static_cast<long>(fam.length) * q * std::lround(fs / s.excitation.carrier_hz)),
        ring(s.transducers.named
                 ? static_cast<long>(std::ceil(30.0 * s.transducers.q / (kPi * s.transducers.centre_hz) * fs))
                 : 0),
        tp{s.transducers.centre_hz, s.transducers.q, false},
        ex{s.excitation.carrier_hz, q, fs, s.excitation.amplitude()} {}

  std::vector<double> burst(int code) const {
    return bpsk_excitation(fam.codes[static_cast<std::size_t>(code - 1)], ex);
  }

  // The emission e (e[0] at sample e0) through the TX transducer, the moving link over the
  // reception window (from the first sample's earliest arrival to the last one's latest plus
  // tails; d: the distance the arrival search starts from), the RX transducer, the noise
  // (noise_v, or snr_db against the on-axis static burst at d, mean square a^2/2; drawn from
  // `seed`) and the ADC.
  MovingReception receive(const MovingLink& link, std::vector<double> e, long e0, double d, std::uint64_t seed) const {
    if (s.transducers.named) {
      Transducer tx(tp, fs);
      for (double& v : e) v = tx.execute(v);
    }
    const double t_first = static_cast<double>(e0) / fs;
    const double t_last = static_cast<double>(e0 + static_cast<long>(e.size())) / fs;
    MovingReception out;
    out.r0 = static_cast<long>(std::floor(reception_time(link, t_first, t_first + d / c) * fs)) - kDelayTaps;
    const long r1 = static_cast<long>(std::ceil(reception_time(link, t_last, t_last + d / c) * fs)) + 3 * burst_len + 2000;
    out.y = render_moving(link, e, e0, out.r0, static_cast<std::size_t>(r1 - out.r0), fs);
    std::vector<double>& y = out.y;
    if (s.transducers.named) {
      Transducer rx(tp, fs);
      for (double& v : y) v = rx.execute(v);
    }
    if (s.noise.named && (s.noise.snr_db || s.noise.noise_v)) {
      double sigma = s.noise.noise_v.value_or(0.0);
      if (s.noise.snr_db) {
        const double a = s.excitation.amplitude() * s.sensitivity * kReferenceDistance / d;
        sigma = std::sqrt(a * a / 2.0 / std::pow(10.0, *s.noise.snr_db / 10.0));
      }
      add_white_noise(y, sigma, seed);
    }
    if (s.noise.adc) out.adc_clipped = adc_quantize(y, *s.noise.adc, nullptr);
    return out;
  }
};

}  // namespace

std::size_t rotor_crossings(const Scene& s) { return static_cast<std::size_t>(s.geometry.rotor.crossings); }

RotorRun run_rotor(SceneSimulator& sim, const std::function<void()>& tick) {
  const Scene& s = sim.scene();
  const RotorParams& p = s.geometry.rotor;
  const MovingBursts mb(s);
  const std::string& family = mb.family;
  const int eta = mb.eta;
  const double fs = mb.fs, c = mb.c;
  const long period = mb.period, burst_len = mb.burst_len;
  RotorRun run;
  run.family = family;
  run.period_s = static_cast<double>(period) / fs;
  run.burst_s = static_cast<double>(burst_len) / fs;
  const double v_u = p.omega_u() * p.r(), v_l = p.omega_l() * p.r();
  run.v_rel = v_u + v_l;
  const double L = s.range_l();

  for (int i = 0; i < p.crossings; ++i) {
    const double tci = p.crossing_time_s(i), h = p.h_of(i);
    MovingLink link;
    link.tx = rotor_tx(p, h);
    link.rx = rotor_rx(p, tci);
    link.c = c;
    link.wind = p.wind_mps;
    link.ka = piston_ka(s.transducers.beam_angle_deg);
    link.gain = s.sensitivity;
    if (s.medium.air) link.absorption_db_per_m = absorption_db_per_m(s.excitation.carrier_hz, *s.medium.air);
    // Bursts emitted while the line of sight is within the window angle.
    const double tw = h * std::tan(rad(p.window_angle_deg)) / run.v_rel + run.burst_s;
    const long k0 = std::max<long>(0, static_cast<long>(std::ceil((tci - tw) * fs / static_cast<double>(period))));
    const long k1 = static_cast<long>(std::floor((tci + tw) * fs / static_cast<double>(period)));
    if (k1 < k0) {
      RotorCrossing rc;
      rc.index = i;
      rc.t_s = tci;
      rc.h_true_m = h;
      run.crossings.push_back(rc);
      if (tick) tick();
      continue;
    }
    const long e0 = k0 * period - kDelayTaps;
    const long e1 = k1 * period + burst_len + mb.ring + kDelayTaps;
    std::vector<double> e(static_cast<std::size_t>(e1 - e0), 0.0);
    for (long k = k0; k <= k1; ++k) {
      const int code = static_cast<int>(k % eta) + 1;
      const auto b = mb.burst(code);
      for (std::size_t n = 0; n < b.size(); ++n) e[static_cast<std::size_t>(k * period - e0) + n] += b[n];
    }
    const MovingReception rx =
        mb.receive(link, std::move(e), e0, h, s.noise.seed * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(i) + 1);
    const long r0 = rx.r0;
    const std::vector<double>& y = rx.y;
    std::uint64_t ov = 0;
    const auto dets = sim.receive_stream(family, y, static_cast<double>(r0) / fs, run.period_s, &ov);
    run.overflows += ov;
    run.adc_clipped += rx.adc_clipped;

    // Truth per burst.
    std::vector<RotorBurst> bursts;
    std::vector<double> arr_start;
    const double a_axis = s.sensitivity * kReferenceDistance / h;
    for (long k = k0; k <= k1; ++k) {
      RotorBurst b;
      b.crossing = i;
      b.burst = static_cast<int>(k);
      b.code = static_cast<int>(k % eta) + 1;
      b.t_emit_s = static_cast<double>(k * period) / fs;
      b.t_rel_s = b.t_emit_s - tci;
      const double tcen = b.t_emit_s + run.burst_s / 2;
      const double trc = reception_time(link, tcen, tcen + h / c);
      const Ray ry = ray_at(link, trc, tcen);
      b.angle_deg = deg(std::acos(std::clamp(-ry.n[2], -1.0, 1.0)));
      b.doppler = ry.doppler;
      b.los_speed_mps = c * (1.0 - 1.0 / ry.doppler);
      b.amplitude_rel = ry.amplitude / a_axis;
      arr_start.push_back(reception_time(link, b.t_emit_s, b.t_emit_s + h / c));
      bursts.push_back(b);
    }
    RotorCrossing rc;
    rc.index = i;
    rc.t_s = tci;
    rc.h_true_m = h;
    std::vector<int> taken(bursts.size(), -1);
    std::vector<TofSample> samples;
    const double match = std::min(run.burst_s, run.period_s / 2);
    for (const auto& d : dets) {
      RotorMeasurement m;
      m.crossing = i;
      m.code = d.code;
      m.tof_s = d.tof_s;
      m.t_emit_s = d.arrival_s - d.tof_s;
      m.distance_m = c * d.tof_s;
      m.score = d.score;
      int bi = -1;
      for (std::size_t j = 0; j < bursts.size(); ++j) {
        const double dt = std::abs(d.arrival_s - arr_start[j]);
        if (dt <= match && (bi < 0 || dt < std::abs(d.arrival_s - arr_start[static_cast<std::size_t>(bi)]))) {
          bi = static_cast<int>(j);
        }
      }
      if (bi >= 0) {
        const auto& b = bursts[static_cast<std::size_t>(bi)];
        m.burst = b.burst;
        m.correct = b.code == d.code;
        m.true_tof_start_s = arr_start[static_cast<std::size_t>(bi)] - b.t_emit_s;
        const double tcen = b.t_emit_s + run.burst_s / 2;
        m.true_tof_centre_s = reception_time(link, tcen, tcen + h / c) - tcen;
        if (m.correct && taken[static_cast<std::size_t>(bi)] < 0) {
          taken[static_cast<std::size_t>(bi)] = 1;
          auto& bb = bursts[static_cast<std::size_t>(bi)];
          bb.decoded = true;
          bb.tof_error_start_m = c * (m.tof_s - m.true_tof_start_s);
          bb.tof_error_centre_m = c * (m.tof_s - m.true_tof_centre_s);
        } else {
          ++run.misdecodes;
        }
      } else {
        ++run.false_alarms;
      }
      // What the system can check by itself: a send of the code precedes it, the ToF is in range.
      if (d.tof_from_send && m.tof_s > 0 && m.distance_m <= L && m.score >= p.accept_score) samples.push_back({m.t_emit_s, m.tof_s});
      rc.list.push_back(m);
    }
    samples = consistent_chain(samples, c, run.v_rel, p.chain_tolerance_m);
    rc.measurements = static_cast<int>(samples.size());
    rc.h_est_paper_m = estimate_h_paper(samples, c, run.v_rel);
    rc.h_est_m = estimate_h_motion(p, samples, c, run.burst_s);
    run.crossings.push_back(std::move(rc));
    run.bursts.insert(run.bursts.end(), bursts.begin(), bursts.end());
    if (tick) tick();
  }
  return run;
}

DopplerPoint doppler_point(SceneSimulator& sim, double d, double v_los, int repeats) {
  const Scene& s = sim.scene();
  const MovingBursts mb(s);
  const int eta = mb.eta;
  const double fs = mb.fs, c = mb.c;
  const long period = mb.period, burst_len = mb.burst_len;
  const double tb = static_cast<double>(burst_len) / fs, T = static_cast<double>(period) / fs;
  DopplerPoint out;
  out.los_speed_mps = v_los;
  double sum_s = 0, sum_c = 0, sum_d = 0, sum_d2 = 0;
  for (int k = 0; k < eta * repeats; ++k) {
    const int code = k % eta + 1;
    const double tk = k * T;
    const double tref = tk + tb / 2 + d / c;
    MovingLink link;
    link.tx = {[=](double) { return Vec3{0, 0, d}; }, [](double) { return Vec3{0, 0, 0}; }};
    link.rx = {[=](double t) { return Vec3{0, 0, v_los * (t - tref)}; }, [=](double) { return Vec3{0, 0, v_los}; }};
    link.c = c;
    link.gain = s.sensitivity;
    if (s.medium.air) link.absorption_db_per_m = absorption_db_per_m(s.excitation.carrier_hz, *s.medium.air);
    const long e0 = k * period - kDelayTaps;
    std::vector<double> e(static_cast<std::size_t>(burst_len + mb.ring + 2 * kDelayTaps), 0.0);
    const auto b = mb.burst(code);
    for (std::size_t n = 0; n < b.size(); ++n) e[static_cast<std::size_t>(kDelayTaps) + n] = b[n];
    const MovingReception rx =
        mb.receive(link, std::move(e), e0, d, s.noise.seed * 0x9E3779B97F4A7C15ull + 0x5151u + static_cast<std::uint64_t>(k));
    const long r0 = rx.r0;
    const std::vector<double>& y = rx.y;
    const auto dets = sim.receive_stream(mb.family, y, static_cast<double>(r0) / fs, T);
    out.adc_clipped += rx.adc_clipped;
    const double t_start = reception_time(link, tk, tk + d / c);
    const double tcen = tk + tb / 2;
    const double t_centre = reception_time(link, tcen, tcen + d / c);
    if (k == 0) out.doppler = ray_at(link, t_centre, tcen).doppler;
    ++out.bursts;
    const Detection* best = nullptr;
    for (const auto& det : dets) {
      if (std::abs(det.arrival_s - t_start) <= tb && (!best || det.score > best->score)) best = &det;
    }
    if (!best) {
      ++out.missed;
    } else if (best->code != code) {
      ++out.misdecoded;
    } else {
      ++out.decoded;
      const double dist = c * best->tof_s;
      sum_s += dist - c * (t_start - tk);
      sum_c += dist - c * (t_centre - tcen);
      sum_d += dist;
      sum_d2 += dist * dist;
    }
  }
  if (out.decoded > 0) {
    const double n = out.decoded;
    out.bias_start_m = sum_s / n;
    out.bias_centre_m = sum_c / n;
    out.std_m = std::sqrt(std::max(0.0, sum_d2 / n - (sum_d / n) * (sum_d / n)));
  }
  return out;
}

}  // namespace ranging
