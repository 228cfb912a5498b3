#include "model/sim/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "model/base/error.hpp"

namespace ranging {

double pearson(std::span<const double> a, std::span<const double> b) {
  if (a.size() != b.size() || a.empty()) {
    throw InputError("pearson: signals have lengths " + std::to_string(a.size()) + " and " +
                     std::to_string(b.size()) + "; they must be equal and non-zero");
  }
  const auto n = static_cast<double>(a.size());
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= n;
  mb /= n;
  // Two-pass: subtracting the mean first keeps the sums accurate for offset signals.
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double da = a[i] - ma, db = b[i] - mb;
    sab += da * db;
    saa += da * da;
    sbb += db * db;
  }
  if (saa == 0.0 || sbb == 0.0) return 0.0;
  return std::clamp(sab / (std::sqrt(saa) * std::sqrt(sbb)), -1.0, 1.0);
}

Distinguishability distinguishability(std::span<const double> rhos) {
  if (rhos.size() < 2) {
    throw InputError("rhos: " + std::to_string(rhos.size()) +
                     " correlation(s) given; distinguishability needs at least 2 codes");
  }
  std::size_t best = 0;
  for (std::size_t i = 0; i < rhos.size(); ++i) {
    require_finite("rhos[" + std::to_string(i) + "]", rhos[i]);
    if (rhos[i] > rhos[best]) best = i;
  }
  double sub = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < rhos.size(); ++i) {
    if (i != best) sub = std::max(sub, rhos[i]);
  }
  return {static_cast<int>(best) + 1, rhos[best], sub, rhos[best] - sub};
}

double energy(std::span<const double> x) {
  double e = 0;
  for (double v : x) e += v * v;
  return e;
}

Duration duration_td(std::span<const double> x, double fs) {
  require_in_range("fs", fs, 1e-9, 1e12);
  if (x.empty()) throw InputError("duration_td: signal is empty; need at least 1 sample");
  double b = 0;
  for (double v : x) b = std::max(b, std::abs(v));
  require_finite("duration_td: peak |x|", b);
  if (b == 0.0) throw InputError("duration_td: signal is all zero; T_d needs a non-zero peak");
  const double a = b / 10.0;
  std::size_t first = x.size(), last = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (std::abs(x[i]) > a) {
      if (first == x.size()) first = i;
      last = i;
    }
  }
  return {first, last, static_cast<double>(last - first) / fs};
}

int eta_required(double max_distance_m, double period_s, double c) {
  require_in_range("max_distance_m", max_distance_m, 1e-6, 1e6);
  require_in_range("period_s", period_s, 1e-12, 1e6);
  require_in_range("speed_of_sound", c, 1e-3, 1e6);
  const double r = max_distance_m / (period_s * c);
  if (r > 1e9) throw InputError("eta_required: L/(T*c) = " + std::to_string(r) + " exceeds 1e9 codes");
  const double eta = std::ceil(r * (1.0 - 1e-9));
  return std::max(1, static_cast<int>(eta));
}

double vmax(double td_max_s, int eta, double c, double max_distance_m) {
  require_in_range("td_max_s", td_max_s, 1e-12, 1e6);
  require_in_range("eta", eta, 1, 1e9);
  require_in_range("speed_of_sound", c, 1e-3, 1e6);
  require_in_range("max_distance_m", max_distance_m, 1e-6, 1e6);
  return std::min(1.0 / (1.5 * td_max_s), eta * c / max_distance_m);
}

double heron_vertical_distance(double h_m, double h_n, double s) {
  require_in_range("h_m", h_m, 0.0, 1e9);
  require_in_range("h_n", h_n, 0.0, 1e9);
  require_in_range("s", s, 0.0, 1e9);
  if (h_m <= 0 || h_n <= 0 || s <= 0) {
    throw InputError("h_m, h_n, s: every side must be > 0");
  }
  // Kahan: with a >= b >= c, 16*area^2 = (a+(b+c))(c-(a-b))(c+(a-b))(a+(b-c)).
  double side[3] = {h_m, h_n, s};
  std::sort(side, side + 3, [](double x, double y) { return x > y; });
  const double a = side[0], b = side[1], c = side[2];
  const double t = c - (a - b);  // 2*(p - a): negative iff a > b + c
  if (t < -1e-12 * a) {
    std::ostringstream os;
    os << "h_m, h_n, s: " << h_m << ", " << h_n << ", " << s
       << " do not form a triangle (the longest side must not exceed the sum of the others)";
    throw InputError(os.str());
  }
  const double prod = (a + (b + c)) * std::max(t, 0.0) * (c + (a - b)) * (a + (b - c));
  const double area = 0.25 * std::sqrt(prod);
  return 2.0 * area / s;
}

}  // namespace ranging
