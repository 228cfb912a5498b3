#include "model/dsp/stability.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "model/base/error.hpp"
#include "model/base/memo.hpp"
#include "model/dsp/fixed_point.hpp"
#include "model/dsp/quantize.hpp"
#include "model/dsp/receiver.hpp"

namespace ranging {

namespace {

const char* const kCoef[5] = {"b0", "b1", "b2", "a1", "a2"};

std::string fmt(const char* f, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}
std::string khz(double f) { return fmt("%.6g", f / 1e3) + " kHz"; }

// Worst attenuation over a band grid: the largest (passband) or the smallest (stopband).
void band_worst(const SosFilter& f, double lo, double hi, bool largest, double& db, double& at) {
  constexpr int kPoints = 257;
  for (int i = 0; i < kPoints; ++i) {
    const double fr = lo + (hi - lo) * i / (kPoints - 1);
    const double a = attenuation_db(f, fr);
    if (std::isnan(a)) continue;
    if (largest ? a > db : a < db) {
      db = a;
      at = fr;
    }
  }
}

struct SpecResult {
  double pass_db = -std::numeric_limits<double>::infinity(), pass_f = 0;
  double stop_db = std::numeric_limits<double>::infinity(), stop_f = 0;
};
SpecResult spec_result(const SosFilter& f, const BandpassSpec& spec) {
  SpecResult r;
  band_worst(f, spec.fp1, spec.fp2, true, r.pass_db, r.pass_f);
  // The lower stopband starts just above DC (a bandpass has its zero there).
  band_worst(f, spec.fs1 / 256, spec.fs1, false, r.stop_db, r.stop_f);
  band_worst(f, spec.fs2, spec.fs / 2, false, r.stop_db, r.stop_f);
  return r;
}

void spec_failures(const SpecResult& r, const BandpassSpec& spec, double tol, std::vector<std::string>& out) {
  if (!(r.pass_db <= spec.rp_db + tol)) {
    out.push_back("passband " + khz(r.pass_f) + ": " + fmt("%.2f", r.pass_db) + " dB > rp_db " +
                  fmt("%g", spec.rp_db) + " + " + fmt("%g", tol));
  }
  if (!(r.stop_db >= spec.rs_db - tol)) {
    out.push_back("stopband " + khz(r.stop_f) + ": " + fmt("%.2f", r.stop_db) + " dB < rs_db " +
                  fmt("%g", spec.rs_db) + " - " + fmt("%g", tol));
  }
}

// ||h_k||_1 from the input to every section output, long double, the quantized cascade.
std::vector<double> node_l1(const QuantizedSos& q, long double rmax) {
  const std::size_t n_sec = q.sections.size();
  if (!(rmax < 1)) return std::vector<double>(n_sec, std::numeric_limits<double>::infinity());
  const long double s = std::ldexp(1.0L, -q.frac);
  // A repeated pole decays like n^m r^n; three times the 1e-15 decay length covers it.
  const long double n_decay = std::log(1e-15L) / std::log(std::max(rmax, 0.5L));
  const auto length = static_cast<std::size_t>(std::min(3.0L * n_decay + 256.0L, 4e6L));
  struct St {
    long double x1 = 0, x2 = 0, y1 = 0, y2 = 0;
  };
  std::vector<St> st(n_sec);
  std::vector<long double> sum(n_sec, 0);
  for (std::size_t n = 0; n < length; ++n) {
    long double x = n == 0 ? 1 : 0;
    for (std::size_t k = 0; k < n_sec; ++k) {
      const auto& c = q.sections[k];
      St& z = st[k];
      const long double y = s * (c[0] * x + c[1] * z.x1 + c[2] * z.x2 - c[3] * z.y1 - c[4] * z.y2);
      z.x2 = z.x1;
      z.x1 = x;
      z.y2 = z.y1;
      z.y1 = y;
      sum[k] += std::abs(y);
      x = y;
    }
  }
  return std::vector<double>(sum.begin(), sum.end());
}

}  // namespace

QuantizedSos quantize_sos(const SosFilter& filter, int bits, int frac, const std::string& field) {
  QuantizedSos q;
  q.frac = frac;
  for (std::size_t k = 0; k < filter.sections.size(); ++k) {
    const Biquad& s = filter.sections[k];
    const double v[5] = {s.b0, s.b1, s.b2, s.a1, s.a2};
    std::vector<std::int64_t> row(5);
    for (int i = 0; i < 5; ++i) {
      row[i] = quantize_coefficient(v[i], bits, frac, field + "section " + std::to_string(k + 1) + " " + kCoef[i]);
    }
    q.sections.push_back(std::move(row));
  }
  return q;
}

SosFilter quantized_sos_filter(const QuantizedSos& q, const SosFilter& like) {
  SosFilter f = like;
  f.sections.clear();
  const double s = std::ldexp(1.0, -q.frac);
  for (const auto& c : q.sections) f.sections.push_back(Biquad{c[0] * s, c[1] * s, c[2] * s, c[3] * s, c[4] * s});
  return f;
}

SectionPoles quantized_section_poles(std::int64_t a1, std::int64_t a2, int frac) {
  if (frac < 0 || frac > 62) throw InputError("coef_frac: " + std::to_string(frac) + " is out of range; valid range is [0, 62]");
  const int128_t one = static_cast<int128_t>(1) << frac;
  const int128_t A1 = a1, A2 = a2;
  SectionPoles p;
  // Jury: both roots of z^2 + a1 z + a2 strictly inside |z| = 1 iff |a2| < 1 and |a1| < 1 + a2.
  const int128_t abs_a1 = A1 < 0 ? -A1 : A1;
  const int128_t abs_a2 = A2 < 0 ? -A2 : A2;
  p.stable = abs_a2 < one && abs_a1 < one + A2;
  const int128_t d = A1 * A1 - 4 * A2 * one;  // |A1^2| < 2^126, |4 A2 2^F| <= 2^126: no overflow
  const long double scale = std::ldexp(1.0L, -(frac + 1));
  if (d < 0) {
    p.complex_pair = true;
    const long double re = -static_cast<long double>(A1) * scale;
    const long double im = std::sqrt(-static_cast<long double>(d)) * scale;
    p.p1 = {re, im};
    p.p2 = {re, -im};
    p.radius = std::sqrt(static_cast<long double>(A2) * std::ldexp(1.0L, -frac));
  } else {
    const long double sq = std::sqrt(static_cast<long double>(d));
    const long double r1 = (-static_cast<long double>(A1) + sq) * scale;
    const long double r2 = (-static_cast<long double>(A1) - sq) * scale;
    p.p1 = std::abs(r1) >= std::abs(r2) ? r1 : r2;
    p.p2 = std::abs(r1) >= std::abs(r2) ? r2 : r1;
    p.radius = std::max(std::abs(r1), std::abs(r2));
  }
  return p;
}

double DesignGuard::max_quantized_radius() const {
  long double r = 0;
  for (const auto& p : quantized_poles) r = std::max(r, p.radius);
  return static_cast<double>(r);
}

namespace {
DesignGuard check_quantized_design_uncached(const SosFilter& filter, const QuantizedSos& q, const BandpassSpec& spec,
                                            int coef_bits, double tolerance_db) {
  if (q.sections.size() != filter.sections.size()) {
    throw InputError("stability guard: " + std::to_string(q.sections.size()) + " quantized sections for " +
                     std::to_string(filter.sections.size()) + " designed; they must match");
  }
  DesignGuard g;
  g.spec = spec;
  g.tolerance_db = tolerance_db;
  g.coef_bits = coef_bits;
  g.coef_frac = q.frac;
  const SosFilter fq = quantized_sos_filter(q, filter);

  g.float_stable = true;
  for (const Biquad& s : filter.sections) {
    g.float_radius.push_back(pole_radius(s));
    if (!(g.float_radius.back() < 1)) g.float_stable = false;
  }
  g.stable = true;
  long double rmax = 0;
  for (std::size_t k = 0; k < q.sections.size(); ++k) {
    const SectionPoles p = quantized_section_poles(q.sections[k][3], q.sections[k][4], q.frac);
    g.quantized_poles.push_back(p);
    rmax = std::max(rmax, p.radius);
    if (!p.stable) {
      g.stable = false;
      g.failures.push_back("section " + std::to_string(k + 1) + " quantized pole radius " +
                           fmt("%.3f", static_cast<double>(p.radius)) + " >= 1");
    }
  }
  for (std::size_t k = 0; k < filter.sections.size(); ++k) {
    if (!(g.float_radius[k] < 1)) {
      g.float_failures.push_back("section " + std::to_string(k + 1) + " pole radius " + fmt("%.3f", g.float_radius[k]) + " >= 1");
    }
  }

  const std::pair<const char*, double> edges[] = {{"fs1", spec.fs1}, {"fp1", spec.fp1}, {"fp2", spec.fp2}, {"fs2", spec.fs2}};
  for (const auto& [name, f] : edges) {
    g.edges.push_back(EdgeAttenuation{name, f, attenuation_db(filter, f), attenuation_db(fq, f)});
  }
  const SpecResult rf = spec_result(filter, spec), rq = spec_result(fq, spec);
  g.passband = BandCheck{rf.pass_db, rf.pass_f, rq.pass_db, rq.pass_f};
  g.stopband = BandCheck{rf.stop_db, rf.stop_f, rq.stop_db, rq.stop_f};
  // An unstable filter has no frequency response to speak of; only its poles are reported.
  if (g.float_stable) spec_failures(rf, spec, tolerance_db, g.float_failures);
  g.float_within_spec = g.float_stable && g.float_failures.empty();
  const std::size_t before = g.failures.size();
  if (g.stable) spec_failures(rq, spec, tolerance_db, g.failures);
  g.within_spec = g.stable && g.failures.size() == before;
  g.l1_gain = node_l1(q, rmax);
  return g;
}

}  // namespace

// Pure and deterministic, and asked twice per run (scene loading, then the receiver's design):
// kept by its arguments (model/base/memo.hpp); the check's node gains and responses cost ms.
DesignGuard check_quantized_design(const SosFilter& filter, const QuantizedSos& q, const BandpassSpec& spec,
                                   int coef_bits, double tolerance_db) {
  static Memo<DesignGuard> memo;
  MemoKey key;
  key.add(filter.type).add(filter.order).add(filter.fs).add(filter.sections);
  key.add(q.frac).add(q.sections);
  key.add(spec).add(coef_bits).add(tolerance_db);
  return memo.get(key, [&] { return check_quantized_design_uncached(filter, q, spec, coef_bits, tolerance_db); });
}

DesignGuard check_quantized_design(const ReceiverConfig& cfg_in) {
  BandpassSpec spec = cfg_in.filter;
  spec.fs = cfg_in.fs;
  const SosFilter filter = cfg_in.filter_order > 0 ? design_bandpass(spec, cfg_in.filter_type, cfg_in.filter_order)
                                                   : design_bandpass(spec, cfg_in.filter_type);
  const auto& b = cfg_in.bandpass;
  const QuantizedSos q = quantize_sos(filter, b.coef_bits, b.coef_frac, "bandpass_fixed.coef_bits: ");
  return check_quantized_design(filter, q, spec, b.coef_bits);
}

DesignGuard check_quantized_design(const ReceiverDesign& d) {
  const auto& b = d.config.bandpass;
  const QuantizedSos q = quantize_sos(d.filter, b.coef_bits, b.coef_frac, "bandpass_fixed.coef_bits: ");
  return check_quantized_design(d.filter, q, d.config.filter, b.coef_bits);
}

std::string guard_message(const DesignGuard& g, int filter_order) {
  if (g.ok()) return "";
  auto join = [](const std::vector<std::string>& v) {
    std::string s;
    for (const auto& f : v) s += (s.empty() ? "" : "; ") + f;
    return s;
  };
  if (!g.float_within_spec) {
    return "filter.order: " + (filter_order > 0 ? std::to_string(filter_order) : std::string("minimum")) +
           ": the unquantized design misses the spec: " + join(g.float_failures);
  }
  return "bandpass_fixed.coef_bits: " + std::to_string(g.coef_bits) + ", coef_frac: " + std::to_string(g.coef_frac) +
         ": " + join(g.failures);
}

void enforce_quantized_design(const DesignGuard& g, const ReceiverConfig& cfg) {
  if (g.ok() || cfg.allow_out_of_spec) return;
  throw InputError(guard_message(g, cfg.filter_order) + " (tolerance " + fmt("%g", g.tolerance_db) + " dB; " +
                   (g.float_within_spec ? "more coefficient bits" : "a higher order") +
                   ", or --allow-out-of-spec to study it anyway)");
}

void enforce_quantized_design(const ReceiverConfig& cfg) {
  if (cfg.allow_out_of_spec) return;
  enforce_quantized_design(check_quantized_design(cfg), cfg);
}

// ------------------------------------------------------------------ filter structures

FilterStructure parse_filter_structure(const std::string& name) {
  if (name == "sos") return FilterStructure::Sos;
  if (name == "direct") return FilterStructure::Direct;
  throw InputError("'" + name + "' is not a filter structure; valid: sos, direct");
}
std::string filter_structure_name(FilterStructure s) { return s == FilterStructure::Sos ? "sos" : "direct"; }

namespace {
std::vector<long double> poly_mul(const std::vector<long double>& p, const std::vector<long double>& q) {
  std::vector<long double> r(p.size() + q.size() - 1, 0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::size_t j = 0; j < q.size(); ++j) r[i + j] += p[i] * q[j];
  }
  return r;
}
using cld = std::complex<long double>;
// p(z) and p'(z) by Horner, c[0] the leading coefficient.
void horner(const std::vector<long double>& c, cld z, cld& p, cld& dp) {
  p = c[0];
  dp = 0;
  for (std::size_t k = 1; k < c.size(); ++k) {
    dp = dp * z + p;
    p = p * z + c[k];
  }
}
}  // namespace

DirectForm direct_form(const SosFilter& filter) {
  DirectForm d{{1.0L}, {1.0L}};
  for (const Biquad& s : filter.sections) {
    d.b = poly_mul(d.b, {s.b0, s.b1, s.b2});
    d.a = poly_mul(d.a, {1.0L, s.a1, s.a2});
  }
  return d;
}

std::vector<cld> polynomial_roots(const std::vector<long double>& c_in) {
  std::vector<long double> c = c_in;
  while (c.size() > 1 && c.back() == 0) c.pop_back();  // roots at z = 0 handled below
  const std::size_t zeros_at_origin = c_in.size() - c.size();
  if (c.empty() || c[0] == 0) throw InputError("polynomial_roots: the leading coefficient is 0");
  const std::size_t n = c.size() - 1;
  std::vector<cld> z(n);
  if (n > 0) {
    const long double r0 = std::pow(std::abs(c[n] / c[0]), 1.0L / static_cast<long double>(n));
    for (std::size_t i = 0; i < n; ++i) {
      z[i] = std::polar(r0, 2 * std::numbers::pi_v<long double> * static_cast<long double>(i) / n + 0.4L);
    }
    bool converged = false;
    for (int it = 0; it < 2000 && !converged; ++it) {
      converged = true;
      for (std::size_t i = 0; i < n; ++i) {
        cld p, dp;
        horner(c, z[i], p, dp);
        if (p == cld(0)) continue;
        const cld ratio = p / dp;
        cld sum = 0;
        for (std::size_t j = 0; j < n; ++j) {
          if (j != i) sum += 1.0L / (z[i] - z[j]);
        }
        const cld w = ratio / (1.0L - ratio * sum);
        z[i] -= w;
        // The evaluation of p near a cluster of roots limits the accuracy: for the 10th-order
        // bandpass the corrections stagnate at ~1e-10 in long double.
        if (std::abs(w) > 1e-9L * std::max(1.0L, std::abs(z[i]))) converged = false;
      }
    }
    if (!converged) throw InputError("polynomial_roots: the Aberth iteration did not converge (degree " + std::to_string(n) + ")");

  }
  for (std::size_t i = 0; i < zeros_at_origin; ++i) z.emplace_back(0);
  return z;
}

namespace {
// Most fraction bits that let max |v| fit a signed `bits` word after rounding.
int block_frac(const std::vector<long double>& v, int bits) {
  long double m = 0;
  for (long double x : v) m = std::max(m, std::abs(x));
  int frac = 62;
  while (frac > -62 && std::round(m * std::ldexp(1.0L, frac)) > std::ldexp(1.0L, bits - 1) - 1) --frac;
  return frac;
}
std::vector<long double> quantize_block(const std::vector<long double>& v, int frac) {
  std::vector<long double> q;
  for (long double x : v) q.push_back(std::round(x * std::ldexp(1.0L, frac)) * std::ldexp(1.0L, -frac));
  return q;
}
long double poly_attenuation(const std::vector<long double>& b, const std::vector<long double>& a, double f, double fs) {
  const cld zi = std::polar(1.0L, -2 * std::numbers::pi_v<long double> * f / fs);  // z^-1
  cld nb = 0, na = 0, zk = 1;
  for (std::size_t k = 0; k < std::max(b.size(), a.size()); ++k) {
    if (k < b.size()) nb += b[k] * zk;
    if (k < a.size()) na += a[k] * zk;
    zk *= zi;
  }
  return -20 * std::log10(std::abs(nb / na));
}
}  // namespace

StructurePoint evaluate_structure(const SosFilter& filter, const BandpassSpec& spec, FilterStructure s, int bits,
                                  double tolerance_db) {
  if (bits < 3 || bits > 60) throw InputError("coefficient bits: " + std::to_string(bits) + " is out of range; valid range is [3, 60]");
  StructurePoint pt;
  pt.bits = bits;
  if (s == FilterStructure::Sos) {
    const QuantizedSos q = quantize_sos(filter, bits, bits - 2, "");
    const DesignGuard g = check_quantized_design(filter, q, spec, bits, tolerance_db);
    pt.frac_a = pt.frac_b = bits - 2;
    pt.max_radius = g.max_quantized_radius();
    pt.stable = g.stable;
    pt.within_spec = g.within_spec;
    pt.passband_db = g.passband.quantized_db;
    pt.stopband_db = g.stopband.quantized_db;
    return pt;
  }
  const DirectForm d = direct_form(filter);
  pt.frac_a = block_frac(d.a, bits);
  pt.frac_b = block_frac(d.b, bits);
  std::vector<long double> a = quantize_block(d.a, pt.frac_a);
  const std::vector<long double> b = quantize_block(d.b, pt.frac_b);
  a[0] = 1;  // implicit in the recursion y = sum b x - sum_{k>=1} a_k y[n-k]: never rounded
  long double r = 0;
  for (const cld& p : polynomial_roots(a)) r = std::max(r, std::abs(p));
  pt.max_radius = static_cast<double>(r);
  pt.stable = r < 1 - 1e-9L;
  pt.passband_db = -1e300;
  pt.stopband_db = 1e300;
  constexpr int kPoints = 257;
  for (int i = 0; i < kPoints; ++i) {
    const double t = static_cast<double>(i) / (kPoints - 1);
    pt.passband_db = std::max(pt.passband_db, static_cast<double>(poly_attenuation(b, a, spec.fp1 + (spec.fp2 - spec.fp1) * t, spec.fs)));
    pt.stopband_db = std::min(pt.stopband_db, static_cast<double>(poly_attenuation(b, a, spec.fs1 / 256 + (spec.fs1 - spec.fs1 / 256) * t, spec.fs)));
    pt.stopband_db = std::min(pt.stopband_db, static_cast<double>(poly_attenuation(b, a, spec.fs2 + (spec.fs / 2 - spec.fs2) * t, spec.fs)));
  }
  pt.within_spec = pt.stable && pt.passband_db <= spec.rp_db + tolerance_db && pt.stopband_db >= spec.rs_db - tolerance_db;
  return pt;
}

int minimum_coefficient_bits(const SosFilter& filter, const BandpassSpec& spec, FilterStructure s, int max_bits,
                             bool every_wider) {
  auto ok = [&](int bits) {
    try {
      return evaluate_structure(filter, spec, s, bits).ok();
    } catch (const InputError&) {
      return false;  // a coefficient does not fit at this width
    }
  };
  if (!every_wider) {
    for (int bits = 3; bits <= max_bits; ++bits) {
      if (ok(bits)) return bits;
    }
    return -1;
  }
  int from = -1;
  for (int bits = max_bits; bits >= 3 && ok(bits); --bits) from = bits;
  return from;
}

// ------------------------------------------------------------------ limit cycles

std::string excitation_name(Excitation e) {
  switch (e) {
    case Excitation::Impulse: return "impulse";
    case Excitation::Step: return "step";
    case Excitation::WorstCase: return "worst-case";
    case Excitation::Random: return "random";
  }
  return "?";
}

std::vector<std::int64_t> excitation_codes(Excitation e, const SosFilter& quantized, int input_bits, int length,
                                           std::uint64_t seed) {
  const std::int64_t lo = -(std::int64_t{1} << (input_bits - 1)), hi = -lo - 1;
  std::vector<std::int64_t> x(static_cast<std::size_t>(length), 0);
  if (x.empty()) return x;
  switch (e) {
    case Excitation::Impulse:
      x[0] = lo;
      break;
    case Excitation::Step:
      for (auto& v : x) v = lo;
      break;
    case Excitation::WorstCase: {
      BandpassFloat f(quantized);
      std::vector<double> h(x.size());
      for (std::size_t n = 0; n < h.size(); ++n) h[n] = f.execute(n == 0 ? 1.0 : 0.0);
      // y[N-1] = sum h[k] x[N-1-k] is largest in magnitude with x[N-1-k] = -sign(h[k]) * full scale.
      for (std::size_t k = 0; k < h.size(); ++k) x[h.size() - 1 - k] = h[k] >= 0 ? lo : hi;
      break;
    }
    case Excitation::Random: {
      std::uint64_t st = seed * 0x9E3779B97F4A7C15ULL + 1;
      for (auto& v : x) {
        st ^= st << 13;
        st ^= st >> 7;
        st ^= st << 17;
        v = lo + static_cast<std::int64_t>(st % static_cast<std::uint64_t>(hi - lo + 1));
      }
      break;
    }
  }
  return x;
}

LimitCycle measure_limit_cycle(const SosFilter& filter, const BandpassFixedConfig& cfg,
                               const std::vector<std::int64_t>& excitation, int settle, int observe) {
  BandpassFixed f(filter, cfg);
  if (settle < 0) {
    long double r = 0;
    for (const Biquad& b : f.quantized_filter().sections) r = std::max<long double>(r, pole_radius(b));
    const double n = (r < 1 && r > 0) ? std::ceil(std::log(std::ldexp(1.0, -cfg.data_bits)) / std::log(static_cast<double>(r))) : 0;
    settle = static_cast<int>(std::min(2 * n + 2000, 2e6));
  }
  for (std::int64_t x : excitation) f.execute_raw(x);
  for (int n = 0; n < settle; ++n) f.execute_raw(0);
  std::vector<std::int64_t> y(static_cast<std::size_t>(observe));
  LimitCycle lc;
  for (auto& v : y) {
    v = f.execute_raw(0);
    lc.amplitude_lsb = std::max(lc.amplitude_lsb, std::abs(static_cast<double>(v)));
  }
  lc.overflows = f.overflow_events().total();
  for (int p = 1; p <= observe / 2; ++p) {
    bool same = true;
    for (std::size_t n = 0; n + static_cast<std::size_t>(p) < y.size() && same; ++n) same = y[n] == y[n + static_cast<std::size_t>(p)];
    if (same) {
      lc.period = p;
      break;
    }
  }
  return lc;
}

}  // namespace ranging
