#include "model/sim/moving_channel.hpp"

#include <cmath>
#include <numbers>

#include "model/base/error.hpp"
#include "model/sim/channel.hpp"

namespace ranging {

namespace {

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 scale(const Vec3& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

// f(t_e) = |R - T(t_e) - u (t_r - t_e)| - c (t_r - t_e) for a fixed reception point R:
// increasing in t_e, slope c - n.(v_T - u) > 0.
double residual_e(const MovingLink& L, const Vec3& r, double t_r, double t_e, double* slope) {
  const double tau = t_r - t_e;
  const Vec3 d = sub(sub(r, L.tx.position(t_e)), scale(L.wind, tau));
  const double dist = norm(d);
  if (slope) {
    const Vec3 n = dist > 0 ? scale(d, 1.0 / dist) : Vec3{0, 0, 0};
    *slope = L.c - dot(n, sub(L.tx.velocity(t_e), L.wind));
  }
  return dist - L.c * tau;
}

// g(t_r) = |R(t_r) - T - u (t_r - t_e)| - c (t_r - t_e) for a fixed emission point T:
// decreasing in t_r, slope n.(v_R - u) - c < 0.
double residual_r(const MovingLink& L, const Vec3& t, double t_e, double t_r, double* slope) {
  const double tau = t_r - t_e;
  const Vec3 d = sub(sub(L.rx.position(t_r), t), scale(L.wind, tau));
  const double dist = norm(d);
  if (slope) {
    const Vec3 n = dist > 0 ? scale(d, 1.0 / dist) : Vec3{0, 0, 0};
    *slope = dot(n, sub(L.rx.velocity(t_r), L.wind)) - L.c;
  }
  return dist - L.c * tau;
}

// Newton on a monotonic function with a bracketing fallback. sign = +1 increasing.
template <class F>
double solve_monotonic(F f, double x0, double hi_bound, int sign) {
  // Bracket: the root is below hi_bound (tau = 0 side); walk down for the other end.
  double x = std::min(x0, hi_bound);
  double lo = 0, hi = hi_bound;
  bool have_lo = false;
  for (int it = 0; it < 60; ++it) {
    double s = 0;
    const double v = f(x, &s) * sign;
    if (std::abs(v) < 1e-13 * 340.0) return x;
    if (v < 0) {
      lo = x;
      have_lo = true;
    } else {
      hi = x;
    }
    double nx = x - v / (s * sign);
    if (!std::isfinite(nx) || nx >= hi || (have_lo && nx <= lo)) {
      nx = have_lo ? 0.5 * (lo + hi) : x - 2.0 * (hi_bound - x + 1e-6);
    }
    if (std::abs(nx - x) < 1e-16 * std::max(1.0, std::abs(x))) return nx;
    x = nx;
  }
  return x;
}

struct SincTable {
  static constexpr int kSteps = 4096;
  std::vector<double> taps;  // kSteps x kDelayTaps
  SincTable() : taps(static_cast<std::size_t>(kSteps) * kDelayTaps) {
    for (int s = 0; s < kSteps; ++s) {
      const auto t = fractional_delay_taps(static_cast<double>(s) / kSteps);
      for (int i = 0; i < kDelayTaps; ++i) taps[static_cast<std::size_t>(s * kDelayTaps + i)] = t[static_cast<std::size_t>(i)];
    }
  }
  static const SincTable& get() {
    static const SincTable t;
    return t;
  }
};

}  // namespace

double piston_ka(double beam_angle_deg) {
  constexpr double x3db = 1.6163399561827614;
  return x3db / std::sin(beam_angle_deg / 2.0 * std::numbers::pi / 180.0);
}

double piston_pattern(double x) {
  if (std::abs(x) < 1e-9) return 1.0;
  return std::abs(2.0 * std::cyl_bessel_j(1.0, x) / x);
}

double emission_time(const MovingLink& L, double t_r, double guess) {
  const Vec3 r = L.rx.position(t_r);
  return solve_monotonic([&](double te, double* s) { return residual_e(L, r, t_r, te, s); }, guess, t_r, +1);
}

double reception_time(const MovingLink& L, double t_e, double guess) {
  const Vec3 t = L.tx.position(t_e);
  // g is decreasing in t_r: g(-x) is increasing in x = -t_r, with the root below x = -t_e.
  const double x = solve_monotonic(
      [&](double mtr, double* s) {
        double sl = 0;
        const double v = residual_r(L, t, t_e, -mtr, &sl);
        if (s) *s = -sl;  // d g(-x)/dx = -g'(t_r) > 0
        return v;
      },
      -std::max(guess, t_e), -t_e, +1);
  return -x;
}

Ray ray_at(const MovingLink& L, double t_r, double guess) {
  Ray ry;
  ry.t_e = emission_time(L, t_r, guess);
  ry.tau = t_r - ry.t_e;
  const Vec3 d = sub(sub(L.rx.position(t_r), L.tx.position(ry.t_e)), scale(L.wind, ry.tau));
  const double dist = norm(d);
  ry.n = dist > 0 ? scale(d, 1.0 / dist) : Vec3{0, 0, 0};
  const double den = 1.0 - dot(ry.n, sub(L.tx.velocity(ry.t_e), L.wind)) / L.c;
  ry.doppler = (1.0 - dot(ry.n, sub(L.rx.velocity(t_r), L.wind)) / L.c) / den;
  double a = L.gain * kReferenceDistance / std::max(dist, 1e-6);
  if (L.ka > 0) {
    const double ct = std::clamp(dot(ry.n, L.tx_axis), -1.0, 1.0);
    const double cr = std::clamp(-dot(ry.n, L.rx_axis), -1.0, 1.0);
    const double k_eff = L.ka / den;
    const double xt = k_eff * std::sqrt(1.0 - ct * ct);
    const double xr = k_eff * std::sqrt(1.0 - cr * cr);
    ry.x_tx = xt;
    // Behind a transducer (ray on the wrong side of its face) nothing is radiated/received.
    a *= (ct > 0 ? piston_pattern(xt) : 0.0) * (cr > 0 ? piston_pattern(xr) : 0.0);
  }
  if (L.absorption_db_per_m > 0) a *= std::pow(10.0, -L.absorption_db_per_m * dist / 20.0);
  ry.amplitude = a;
  return ry;
}

double interpolate(std::span<const double> x, double p) {
  // z(p) = sum_i h_i(mu) x[A - (i - (N/2 - 1))], A = ceil(p), mu = A - p (channel.hpp's convention).
  const SincTable& T = SincTable::get();
  const double A = std::ceil(p);
  int s = static_cast<int>(std::lround((A - p) * SincTable::kSteps));
  long Ai = static_cast<long>(A);
  if (s == SincTable::kSteps) {  // mu rounds to 1: the same as mu = 0 one sample earlier
    s = 0;
    Ai -= 1;
  }
  const double* h = T.taps.data() + static_cast<std::size_t>(s) * kDelayTaps;
  double acc = 0;
  const long n = static_cast<long>(x.size());
  for (int i = 0; i < kDelayTaps; ++i) {
    const long k = Ai - (i - (kDelayTaps / 2 - 1));
    if (k >= 0 && k < n) acc += h[i] * x[static_cast<std::size_t>(k)];
  }
  return acc;
}

std::vector<double> render_moving(const MovingLink& L, std::span<const double> emitted, long e0, long r0,
                                  std::size_t n_out, double fs, std::vector<Ray>* rays) {
  if (!(L.c > 0)) throw InputError("moving channel: speed of sound must be positive");
  std::vector<double> y(n_out, 0.0);
  if (rays) rays->resize(n_out);
  double guess = static_cast<double>(r0) / fs - 1e-3;
  bool first = true;
  for (std::size_t m = 0; m < n_out; ++m) {
    const double t_r = static_cast<double>(r0 + static_cast<long>(m)) / fs;
    const Ray ry = ray_at(L, t_r, first ? guess : guess + 1.0 / fs);
    first = false;
    guess = ry.t_e;
    if (rays) (*rays)[m] = ry;
    const double p = ry.t_e * fs - static_cast<double>(e0);
    if (p < -kDelayTaps || p > static_cast<double>(emitted.size()) + kDelayTaps || ry.amplitude == 0.0) continue;
    y[m] = ry.amplitude * interpolate(emitted, p);
  }
  return y;
}

}  // namespace ranging
