#include "model/dsp/filter_design.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <sstream>

#include "model/base/error.hpp"
#include "model/base/memo.hpp"
#include "model/base/names.hpp"

namespace ranging {
namespace {

using cd = std::complex<double>;
constexpr double kPi = std::numbers::pi;

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(10);
  os << v;
  return os.str();
}

// ---------------------------------------------------------------- elliptic functions
// Complete elliptic integral of the first kind via the arithmetic-geometric mean:
// K(m) = pi / (2 AGM(1, sqrt(1 - m))). ellipkm1(p) = K(1 - p) takes p directly so that
// it stays accurate when p is tiny (scipy's ellipkm1).
double agm(double a, double b) {
  for (int i = 0; i < 64 && std::abs(a - b) > 1e-16 * a; ++i) {
    const double an = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = an;
  }
  return 0.5 * (a + b);
}
double ellipk(double m) { return kPi / (2.0 * agm(1.0, std::sqrt(1.0 - m))); }
double ellipkm1(double p) { return kPi / (2.0 * agm(1.0, std::sqrt(p))); }

struct Jacobi {
  double sn, cn, dn;
};

// Jacobi elliptic functions sn, cn, dn of u with parameter m (cephes ellpj, as in scipy):
// descending AGM, then backward recurrence on the amplitude.
Jacobi ellipj(double u, double m) {
  if (m < 1e-9) {
    const double t = std::sin(u), b = std::cos(u);
    const double ai = 0.25 * m * (u - t * b);
    return {t - ai * b, b + ai * t, 1.0 - 0.5 * m * t * t};
  }
  if (m >= 0.9999999999) {
    double ai = 0.25 * (1.0 - m);
    const double b = std::cosh(u), t = std::tanh(u), phi = 1.0 / b;
    const double twon = b * std::sinh(u);
    const double sn = t + ai * (twon - u) / (b * b);
    ai *= t * phi;
    return {sn, phi - ai * (twon - u), phi + ai * (twon + u)};
  }
  double a[10], c[10];
  a[0] = 1.0;
  double b = std::sqrt(1.0 - m);
  c[0] = std::sqrt(m);
  double twon = 1.0;
  int i = 0;
  while (std::abs(c[i] / a[i]) > 1.11022302462515654042e-16 && i < 8) {
    const double ai = a[i];
    ++i;
    c[i] = (ai - b) / 2.0;
    const double t = std::sqrt(ai * b);
    a[i] = (ai + b) / 2.0;
    b = t;
    twon *= 2.0;
  }
  double phi = twon * a[i] * u;
  double prev = phi;
  do {
    const double t = c[i] * std::sin(phi) / a[i];
    prev = phi;
    phi = (std::asin(t) + phi) / 2.0;
  } while (--i);
  const double sn = std::sin(phi), cn = std::cos(phi);
  const double dnfac = std::cos(phi - prev);
  const double dn = std::abs(dnfac) < 0.1 ? std::sqrt(1 - m * sn * sn) : cn / dnfac;
  return {sn, cn, dn};
}

// Solve n K(m)/K'(m) = K(m1)/K'(m1) for m with the nome series (Orfanidis eq. 49; scipy
// _ellipdeg with the same 7 terms).
double ellipdeg(int n, double m1) {
  const double q1 = std::exp(-kPi * ellipkm1(m1) / ellipk(m1));
  const double q = std::pow(q1, 1.0 / n);
  double num = 0, den = 0;
  for (int k = 0; k <= 7; ++k) num += std::pow(q, k * (k + 1));
  for (int k = 1; k <= 8; ++k) den += std::pow(q, k * k);
  den = 1 + 2 * den;
  return 16 * q * std::pow(num / den, 4);
}

// Imaginary part of the inverse Jacobi sn at the imaginary point i*w (scipy _arc_jac_sc1):
// the descending Landen sequence keeps i*w on the imaginary axis, and arcsin(i y) = i asinh(y).
double arc_jac_sc1(double w, double m) {
  auto complement = [](double kx) { return std::sqrt((1 - kx) * (1 + kx)); };
  std::vector<double> ks{std::sqrt(m)};
  for (int it = 0; ks.back() != 0; ++it) {
    if (it > 10) throw std::runtime_error("elliptic design: Landen transformation not converging");
    const double kp = complement(ks.back());
    ks.push_back((1 - kp) / (1 + kp));
  }
  double capk = kPi / 2;
  for (size_t i = 1; i < ks.size(); ++i) capk *= 1 + ks[i];
  double y = w;  // the point is i*y; |1 - (k i y)^2|^(1/2) = sqrt(1 + k^2 y^2)
  for (size_t i = 0; i + 1 < ks.size(); ++i) {
    y = 2 * y / ((1 + ks[i + 1]) * (1 + std::sqrt(1 + ks[i] * ks[i] * y * y)));
  }
  return capk * 2 / kPi * std::asinh(y);
}

double pow10m1(double x) { return std::expm1(std::numbers::ln10 * x); }

// ---------------------------------------------------------------- analog prototypes
struct AnalogZpk {
  std::vector<cd> z, p;
  double k = 1;
};

AnalogZpk buttap(int n) {
  AnalogZpk r;
  for (int m = -n + 1; m < n; m += 2) r.p.push_back(-std::exp(cd(0, kPi * m / (2.0 * n))));
  r.k = 1;
  return r;
}

AnalogZpk cheb1ap(int n, double rp) {
  AnalogZpk r;
  const double eps = std::sqrt(std::pow(10.0, 0.1 * rp) - 1.0);
  const double mu = 1.0 / n * std::asinh(1 / eps);
  cd prod = 1;
  for (int m = -n + 1; m < n; m += 2) {
    const double theta = kPi * m / (2.0 * n);
    r.p.push_back(-std::sinh(cd(mu, theta)));
    prod *= -r.p.back();
  }
  r.k = prod.real();
  if (n % 2 == 0) r.k /= std::sqrt(1 + eps * eps);
  return r;
}

AnalogZpk ellipap(int n, double rp, double rs) {
  AnalogZpk r;
  if (n == 1) {
    r.p.push_back(-std::sqrt(1.0 / pow10m1(0.1 * rp)));
    r.k = -r.p[0].real();
    return r;
  }
  const double eps_sq = pow10m1(0.1 * rp);
  const double eps = std::sqrt(eps_sq);
  const double ck1_sq = eps_sq / pow10m1(0.1 * rs);
  if (!(ck1_sq > 0)) throw InputError("rp_db, rs_db: cannot design an elliptic filter (rp_db too small against rs_db)");
  const double val0 = ellipk(ck1_sq);
  const double m = ellipdeg(n, ck1_sq);
  const double capk = ellipk(m);

  std::vector<Jacobi> sj;
  for (int j = 1 - n % 2; j < n; j += 2) sj.push_back(ellipj(j * capk / n, m));
  std::vector<cd> zs;
  for (const Jacobi& e : sj) {
    if (std::abs(e.sn) > 2e-16) zs.push_back(cd(0, 1.0 / (std::sqrt(m) * e.sn)));
  }
  for (const cd& z : zs) r.z.push_back(z);
  for (const cd& z : zs) r.z.push_back(std::conj(z));

  const double rr = arc_jac_sc1(1.0 / eps, ck1_sq);
  const double v0 = capk * rr / (n * val0);
  const Jacobi v = ellipj(v0, 1 - m);
  std::vector<cd> ps;
  for (const Jacobi& e : sj) {
    ps.push_back(-cd(e.cn * e.dn * v.sn * v.cn, e.sn * v.dn) / (1 - std::pow(e.dn * v.sn, 2.0)));
  }
  r.p = ps;
  if (n % 2) {
    double norm = 0;
    for (const cd& p : ps) norm += std::norm(p);
    norm = std::sqrt(norm);
    for (const cd& p : ps) {
      if (std::abs(p.imag()) > 2e-16 * norm) r.p.push_back(std::conj(p));
    }
  } else {
    for (const cd& p : ps) r.p.push_back(std::conj(p));
  }
  cd pp = 1, pz = 1;
  for (const cd& p : r.p) pp *= -p;
  for (const cd& z : r.z) pz *= -z;
  r.k = (pp / pz).real();
  if (n % 2 == 0) r.k /= std::sqrt(1 + eps_sq);
  return r;
}

// Prewarped band edges tan(pi f / fs) (scipy: tan(pi * wp / 2) with wp = 2 f / fs).
double prewarp(double f, double fs) { return std::tan(kPi * f / fs); }

// Selectivity of the equivalent lowpass prototype for a bandpass spec (scipy *ord, bandpass).
double bandpass_nat(const BandpassSpec& s) {
  const double p0 = prewarp(s.fp1, s.fs), p1 = prewarp(s.fp2, s.fs);
  double nat = std::numeric_limits<double>::infinity();
  for (double f : {s.fs1, s.fs2}) {
    const double st = prewarp(f, s.fs);
    nat = std::min(nat, std::abs((st * st - p0 * p1) / (st * (p0 - p1))));
  }
  return nat;
}

// Prewarped natural frequencies (analog, in units of tan(pi f / fs)).
std::pair<double, double> natural_warped(const BandpassSpec& s, FilterType type, int order) {
  const double p0 = prewarp(s.fp1, s.fs), p1 = prewarp(s.fp2, s.fs);
  if (type != FilterType::Butterworth) return {p0, p1};
  // Butterworth: the natural frequency giving exactly rp_db at the passband edges.
  const double gpass = std::pow(10.0, 0.1 * std::abs(s.rp_db));
  const double w0 = std::pow(gpass - 1.0, -1.0 / (2.0 * order));
  const double bw = p1 - p0;
  const double root = std::sqrt(w0 * w0 / 4.0 * bw * bw + p0 * p1);
  return {root - w0 * bw / 2.0, root + w0 * bw / 2.0};
}

void require_order(int order) {
  if (order < 1 || order > kMaxFilterOrder) {
    throw InputError("order: " + std::to_string(order) + " is out of range; valid range is [1, " +
                     std::to_string(kMaxFilterOrder) + "]");
  }
}

// ---------------------------------------------------------------- sectioning
struct Pair {
  cd a, b;
};

// Splits a conjugate-symmetric root set into pairs: (r, conj r) for complex roots, and
// real roots paired smallest with largest (so zeros at -1 and +1 share a section).
std::vector<Pair> conjugate_pairs(const std::vector<cd>& roots) {
  std::vector<cd> upper;
  std::vector<double> real;
  for (const cd& r : roots) {
    const double tol = 1e-10 * std::max(1.0, std::abs(r));
    if (std::abs(r.imag()) <= tol) {
      real.push_back(r.real());
    } else if (r.imag() > 0) {
      upper.push_back(r);
    }
  }
  std::vector<Pair> out;
  for (const cd& r : upper) out.push_back({r, std::conj(r)});
  std::sort(real.begin(), real.end());
  for (size_t i = 0, j = real.size(); i + 1 < j; ++i, --j) out.push_back({real[i], real[j - 1]});
  if (real.size() % 2) out.push_back({real[real.size() / 2], 0.0});
  return out;
}

double pair_radius(const Pair& p) { return std::max(std::abs(p.a), std::abs(p.b)); }

// Monic second-order polynomial 1 + c1 z^-1 + c2 z^-2 with roots a, b.
std::pair<double, double> monic(const Pair& r) {
  // Zeros at +1 and -1 (Butterworth / Chebyshev): b1 must be exactly 0, hardware skips it.
  if (r.a.imag() == 0 && r.b.imag() == 0 && r.a.real() == -r.b.real()) {
    return {0.0, -(r.a.real() * r.a.real())};
  }
  // Conjugate zeros on the unit circle (elliptic): b2 = b0 exactly, a symmetric numerator.
  if (r.a == std::conj(r.b) && std::abs(r.a) == 1.0) return {-2.0 * r.a.real(), 1.0};
  return {-(r.a + r.b).real(), (r.a * r.b).real()};
}

std::complex<double> biquad_response(const Biquad& s, cd z1) {
  return (s.b0 + s.b1 * z1 + s.b2 * z1 * z1) / (1.0 + s.a1 * z1 + s.a2 * z1 * z1);
}

// Peak of |prod_{i<=last} H_i(f)| over [0, fs/2]: dense grid, then golden-section refinement
// in the cells next to the grid maximum (peaks are narrower than fs/2, never than a cell).
double cascade_peak(const std::vector<Biquad>& s, size_t last, double fs) {
  auto mag = [&](double f) {
    const cd z1 = std::polar(1.0, -2.0 * kPi * f / fs);
    cd h = 1.0;
    for (size_t i = 0; i <= last; ++i) h *= biquad_response(s[i], z1);
    return std::abs(h);
  };
  constexpr int kGrid = 8192;
  const double df = fs / 2 / kGrid;
  int best = 0;
  double peak = -1;
  for (int i = 0; i <= kGrid; ++i) {
    const double m = mag(i * df);
    if (m > peak) peak = m, best = i;
  }
  double lo = std::max(0.0, (best - 1) * df), hi = std::min(fs / 2, (best + 1) * df);
  const double g = (std::sqrt(5.0) - 1) / 2;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  double m1 = mag(x1), m2 = mag(x2);
  for (int it = 0; it < 100 && hi - lo > 1e-9 * fs; ++it) {
    if (m1 < m2) {
      lo = x1, x1 = x2, m1 = m2, x2 = lo + g * (hi - lo), m2 = mag(x2);
    } else {
      hi = x2, x2 = x1, m2 = m1, x1 = hi - g * (hi - lo), m1 = mag(x1);
    }
  }
  return std::max({peak, m1, m2});
}

std::vector<Biquad> zpk_to_sections(const Zpk& d, double fs) {
  std::vector<Pair> poles = conjugate_pairs(d.p);
  std::vector<Pair> zeros = conjugate_pairs(d.z);
  // Pairing: poles closest to the unit circle choose first, each the nearest zero pair.
  std::stable_sort(poles.begin(), poles.end(),
                   [](const Pair& x, const Pair& y) { return pair_radius(x) > pair_radius(y); });
  std::vector<std::pair<Pair, std::optional<Pair>>> sec;
  for (const Pair& p : poles) {
    std::optional<Pair> zsel;
    if (!zeros.empty()) {
      const cd pu = p.a.imag() >= 0 ? p.a : p.b;
      size_t bi = 0;
      double bd = std::numeric_limits<double>::infinity();
      for (size_t i = 0; i < zeros.size(); ++i) {
        const double dz = std::min(std::abs(pu - zeros[i].a), std::abs(pu - zeros[i].b));
        if (dz < bd) bd = dz, bi = i;
      }
      zsel = zeros[bi];
      zeros.erase(zeros.begin() + static_cast<std::ptrdiff_t>(bi));
    }
    sec.emplace_back(p, zsel);
  }
  // Ordering: ascending pole radius, so the highest-Q section is last.
  std::reverse(sec.begin(), sec.end());
  std::vector<Biquad> out;
  for (const auto& [p, z] : sec) {
    Biquad b;
    auto [a1, a2] = monic(p);
    b.a1 = a1;
    b.a2 = a2;
    if (z) {
      auto [c1, c2] = monic(*z);
      b.b1 = c1;
      b.b2 = c2;
    } else {
      b.b1 = b.b2 = 0;
    }
    out.push_back(b);
  }
  // L-infinity scaling: each cumulative response but the last peaks at exactly 1.
  double carried = 1;
  for (size_t i = 0; i + 1 < out.size(); ++i) {
    const double g = 1.0 / cascade_peak(out, i, fs);
    out[i].b0 *= g, out[i].b1 *= g, out[i].b2 *= g;
    carried *= g;
  }
  Biquad& last = out.back();
  const double g = d.k / carried;
  last.b0 *= g, last.b1 *= g, last.b2 *= g;
  return out;
}

}  // namespace

void validate(const BandpassSpec& s) {
  require_finite("fs", s.fs);
  if (!(s.fs > 0)) throw InputError("fs: " + fmt(s.fs) + " Hz is out of range; need fs > 0");
  const double nyq = s.fs / 2;
  for (auto [name, v] : {std::pair{"fs1", s.fs1}, {"fp1", s.fp1}, {"fp2", s.fp2}, {"fs2", s.fs2}}) {
    require_finite(name, v);
  }
  const std::string rule = "; valid: 0 < fs1 < fp1 < fp2 < fs2 < fs/2 = " + fmt(nyq) + " Hz";
  if (!(s.fs1 > 0)) throw InputError("fs1: " + fmt(s.fs1) + " Hz must be > 0" + rule);
  // A violated pair names both fields: either one may be the wrong one.
  struct Edge {
    const char* name;
    double v;
  };
  const Edge e[] = {{"fs1", s.fs1}, {"fp1", s.fp1}, {"fp2", s.fp2}, {"fs2", s.fs2}, {"fs", nyq}};
  for (int i = 0; i < 4; ++i) {
    if (!(e[i].v < e[i + 1].v)) {
      const std::string upper = i < 3 ? e[i + 1].name : "fs/2";
      throw InputError(std::string(e[i].name) + ", " + e[i + 1].name + ": need " + e[i].name +
                       " < " + upper + ", got " + e[i].name + " = " + fmt(e[i].v) + " Hz, " +
                       upper + " = " + fmt(e[i + 1].v) + " Hz" + rule);
    }
  }
  require_finite("rp_db", s.rp_db);
  require_finite("rs_db", s.rs_db);
  if (!(s.rp_db > 0) || !(s.rp_db < s.rs_db)) {
    throw InputError("rp_db, rs_db: need 0 < rp_db < rs_db, got rp_db = " + fmt(s.rp_db) +
                     " dB, rs_db = " + fmt(s.rs_db) + " dB");
  }
}

int minimum_order(const BandpassSpec& s, FilterType type) {
  validate(s);
  const double nat = bandpass_nat(s);
  double n = 0;
  switch (type) {
    case FilterType::Butterworth: {
      const double gstop = std::pow(10.0, 0.1 * std::abs(s.rs_db));
      const double gpass = std::pow(10.0, 0.1 * std::abs(s.rp_db));
      n = std::log10((gstop - 1.0) / (gpass - 1.0)) / (2 * std::log10(nat));
      break;
    }
    case FilterType::Chebyshev1: {
      const double gstop = std::pow(10.0, 0.1 * std::abs(s.rs_db));
      const double gpass = std::pow(10.0, 0.1 * std::abs(s.rp_db));
      n = std::acosh(std::sqrt((gstop - 1.0) / (gpass - 1.0))) / std::acosh(nat);
      break;
    }
    case FilterType::Elliptic: {
      const double arg1_sq = pow10m1(0.1 * s.rp_db) / pow10m1(0.1 * s.rs_db);
      const double arg0 = 1.0 / nat;
      n = ellipk(arg0 * arg0) * ellipkm1(arg1_sq) / (ellipkm1(arg0 * arg0) * ellipk(arg1_sq));
      break;
    }
  }
  if (!std::isfinite(n)) throw InputError("bandpass spec: no finite filter order meets it");
  return std::max(1, static_cast<int>(std::ceil(std::min(n, 1e6))));
}

std::vector<double> natural_frequencies(const BandpassSpec& spec, FilterType type, int order) {
  validate(spec);
  require_order(order);
  auto [w0, w1] = natural_warped(spec, type, order);
  return {spec.fs / kPi * std::atan(w0), spec.fs / kPi * std::atan(w1)};
}

Zpk design_bandpass_zpk(const BandpassSpec& spec, FilterType type, int order) {
  validate(spec);
  require_order(order);
  AnalogZpk a;
  switch (type) {
    case FilterType::Butterworth: a = buttap(order); break;
    case FilterType::Chebyshev1: a = cheb1ap(order, spec.rp_db); break;
    case FilterType::Elliptic: a = ellipap(order, spec.rp_db, spec.rs_db); break;
  }
  // scipy designs with fs = 2: the analog edges are 2*fs*tan(pi*wn/fs) = 4*tan(pi f/fs_hz).
  auto [w0, w1] = natural_warped(spec, type, order);
  w0 *= 4, w1 *= 4;
  const double bw = w1 - w0, wo = std::sqrt(w0 * w1);
  // Lowpass -> bandpass: s -> (s^2 + wo^2) / (s bw).
  const int degree = static_cast<int>(a.p.size() - a.z.size());
  std::vector<cd> zb, pb;
  for (int sign : {1, -1}) {
    for (const cd& z : a.z) {
      const cd zl = z * bw / 2.0;
      zb.push_back(zl + static_cast<double>(sign) * std::sqrt(zl * zl - wo * wo));
    }
    for (const cd& p : a.p) {
      const cd pl = p * bw / 2.0;
      pb.push_back(pl + static_cast<double>(sign) * std::sqrt(pl * pl - wo * wo));
    }
  }
  for (int i = 0; i < degree; ++i) zb.push_back(0.0);
  const double kb = a.k * std::pow(bw, degree);
  // Bilinear transform, fs = 2 (fs2 = 4); zeros at infinity go to z = -1.
  constexpr double fs2 = 4.0;
  Zpk d;
  cd num = 1, den = 1;
  for (const cd& z : zb) {
    cd zz = (fs2 + z) / (fs2 - z);
    // Zeros on the j-axis map to the unit circle; remove the rounding of |z| there.
    if (z.real() == 0 && z.imag() != 0) zz /= std::abs(zz);
    d.z.push_back(zz);
    num *= fs2 - z;
  }
  for (int i = 0; i < static_cast<int>(pb.size() - zb.size()); ++i) d.z.push_back(-1.0);
  for (const cd& p : pb) {
    d.p.push_back((fs2 + p) / (fs2 - p));
    den *= fs2 - p;
  }
  d.k = kb * (num / den).real();
  return d;
}

std::complex<double> zpk_response(const Zpk& zpk, double f, double fs) {
  const cd z1 = std::polar(1.0, -2.0 * kPi * f / fs);
  cd h = zpk.k;
  for (const cd& z : zpk.z) h *= 1.0 - z * z1;
  for (const cd& p : zpk.p) h /= 1.0 - p * z1;
  return h;
}

SosFilter design_bandpass(const BandpassSpec& spec, FilterType type, int order) {
  // Pure and deterministic, and asked twice per run (scene loading checks the design, the
  // receiver builds it): kept by its arguments (model/base/memo.hpp), about 2 ms each.
  static Memo<SosFilter> memo;
  MemoKey key;
  key.add(spec).add(type).add(order);
  return memo.get(key, [&] {
    const Zpk d = design_bandpass_zpk(spec, type, order);
    SosFilter f;
    f.type = type;
    f.order = order;
    f.fs = spec.fs;
    f.sections = zpk_to_sections(d, spec.fs);
    return f;
  });
}

SosFilter design_bandpass(const BandpassSpec& spec, FilterType type) {
  const int order = minimum_order(spec, type);
  if (order > kMaxFilterOrder) {
    throw InputError("fs1, fp1, fp2, fs2, rp_db, rs_db: the spec needs a " + filter_type_name(type) +
                     " prototype of order " + std::to_string(order) + ", more than the maximum " +
                     std::to_string(kMaxFilterOrder) + "; widen the transition bands or relax rp/rs");
  }
  return design_bandpass(spec, type, order);
}

namespace {
constexpr NameTable<FilterType, 3> kFilterTypes{
    {{FilterType::Butterworth, "butter"}, {FilterType::Chebyshev1, "cheby1"}, {FilterType::Elliptic, "ellip"}}};
}  // namespace

FilterType parse_filter_type(std::string_view name) {
  if (const auto t = value_of(kFilterTypes, name)) return *t;
  throw InputError("filter type: '" + std::string(name) + "' is not one of " + names_list(kFilterTypes));
}

std::string filter_type_name(FilterType type) { return name_of(kFilterTypes, type); }

namespace {
// Modified Bessel function I0 by its power series (converges fast for the betas used).
double bessel_i0(double x) {
  double sum = 1.0, term = 1.0;
  const double q = x * x / 4.0;
  for (int k = 1; k < 300 && term > 1e-17 * sum; ++k) {
    term *= q / (static_cast<double>(k) * k);
    sum += term;
  }
  return sum;
}
}  // namespace

double kaiser_window(double r, double beta) {
  return bessel_i0(beta * std::sqrt(std::max(0.0, 1.0 - r * r))) / bessel_i0(beta);
}

double pole_radius(const Biquad& s) {
  const cd disc = std::sqrt(cd(s.a1 * s.a1 - 4 * s.a2, 0));
  return std::max(std::abs((-s.a1 + disc) / 2.0), std::abs((-s.a1 - disc) / 2.0));
}

double attenuation_db(const SosFilter& filter, double f) {
  return -20.0 * std::log10(std::abs(sos_response(filter, f)));
}

}  // namespace ranging
