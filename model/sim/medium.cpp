#include "model/sim/medium.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "model/base/error.hpp"
#include "model/dsp/filter_design.hpp"

namespace ranging {

void validate(const AirConditions& a) {
  require_in_range("medium.temperature_c", a.temperature_c, -40.0, 60.0);
  require_in_range("medium.relative_humidity", a.relative_humidity, 0.0, 100.0);
  require_in_range("medium.pressure_kpa", a.pressure_kpa, 50.0, 120.0);
}

namespace {

double kelvin(const AirConditions& a) { return a.temperature_c + 273.15; }

// Mole fraction of water vapour (Cramer 1993 / Davis 1992).
double water_mole_fraction(const AirConditions& a) {
  const double T = kelvin(a), t = a.temperature_c, p = a.pressure_kpa * 1e3;
  const double psv = std::exp(1.2811805e-5 * T * T - 1.9509874e-2 * T + 34.04926034 - 6.3536311e3 / T);
  const double f = 1.00062 + 3.14e-8 * p + 5.6e-7 * t * t;
  return a.relative_humidity / 100.0 * f * psv / p;
}

}  // namespace

double speed_of_sound(const AirConditions& a) {
  validate(a);
  const double t = a.temperature_c, p = a.pressure_kpa * 1e3;
  const double xw = water_mole_fraction(a), xc = 400e-6;
  return 331.5024 + 0.603055 * t - 0.000528 * t * t +
         (51.471935 + 0.1495874 * t - 0.000782 * t * t) * xw +
         (-1.82e-7 + 3.73e-8 * t - 2.93e-10 * t * t) * p +
         (-85.20931 - 0.228525 * t + 5.91e-5 * t * t) * xc - 2.835149 * xw * xw -
         2.15e-13 * p * p + 29.179762 * xc * xc + 4.86e-4 * xw * p * xc;
}

double absorption_db_per_m(double f_hz, const AirConditions& a) {
  validate(a);
  require_in_range("absorption frequency", f_hz, 0.0, 1e8);
  constexpr double T0 = 293.15, T01 = 273.16, pr = 101.325;
  const double T = kelvin(a), pa = a.pressure_kpa;
  const double psat_over_pr = std::pow(10.0, -6.8346 * std::pow(T01 / T, 1.261) + 4.6151);
  const double h = a.relative_humidity * psat_over_pr / (pa / pr);  // molar concentration, %
  const double frO = (pa / pr) * (24.0 + 4.04e4 * h * (0.02 + h) / (0.391 + h));
  const double frN = (pa / pr) * std::pow(T / T0, -0.5) *
                     (9.0 + 280.0 * h * std::exp(-4.170 * (std::pow(T / T0, -1.0 / 3.0) - 1.0)));
  const double f2 = f_hz * f_hz;
  return 8.686 * f2 *
         (1.84e-11 / (pa / pr) * std::sqrt(T / T0) +
          std::pow(T / T0, -2.5) * (0.01275 * std::exp(-2239.1 / T) / (frO + f2 / frO) +
                                    0.1068 * std::exp(-3352.0 / T) / (frN + f2 / frN)));
}

std::vector<double> absorption_fir(const AirConditions& a, double distance_m, double fs) {
  validate(a);
  require_in_range("distance", distance_m, 0.0, 1000.0);
  require_in_range("fs", fs, 1e3, 1e9);
  constexpr int M = 4096;  // frequency grid over [0, fs)
  std::vector<double> H(M / 2 + 1);
  for (int k = 0; k <= M / 2; ++k) {
    const double f = fs * k / M;
    H[static_cast<std::size_t>(k)] = std::pow(10.0, -absorption_db_per_m(f, a) * distance_m / 20.0);
  }
  // The response is close to exp(-beta f^2) (the f^2 term dominates): a Gaussian of
  // sigma_t = sqrt(2 beta)/(2 pi); fit beta at fs/8 and keep +-8 sigma of it, at least 33 taps.
  const double f_fit = fs / 8.0;
  const double beta = absorption_db_per_m(f_fit, a) * distance_m / 8.686 / (f_fit * f_fit);
  const double sigma = std::sqrt(2.0 * std::max(beta, 0.0)) / (2.0 * std::numbers::pi) * fs;
  const int half = std::clamp(static_cast<int>(std::ceil(8.0 * sigma)) + 128, 16, M / 2 - 1);
  // The inverse DFT of the real, even H at tap n: cos(2 pi k n / M) = c[(k n) mod M], one
  // table of M cosines with the argument reduced exactly (the direct std::cos of 2 pi k n / M
  // took ~1 M libm calls per distance, most of a short scene's time). The taps are even in n,
  // so each value is computed once and mirrored.
  std::vector<double> c(M);
  for (int m = 0; m < M; ++m) c[static_cast<std::size_t>(m)] = std::cos(2.0 * std::numbers::pi * m / M);
  std::vector<double> h(static_cast<std::size_t>(2 * half + 1));
  for (int n = 0; n <= half; ++n) {
    double acc = H[0];
    std::size_t kn = 0;  // (k n) mod M
    for (int k = 1; k < M / 2; ++k) {
      kn += static_cast<std::size_t>(n);
      if (kn >= static_cast<std::size_t>(M)) kn -= M;
      acc += 2.0 * H[static_cast<std::size_t>(k)] * c[kn];
    }
    acc += H[M / 2] * (n % 2 ? -1.0 : 1.0);
    const double r = static_cast<double>(n) / (half + 1);
    const double w = kaiser_window(r, 8.0);
    h[static_cast<std::size_t>(half + n)] = h[static_cast<std::size_t>(half - n)] = acc / M * w;
  }
  return h;
}

}  // namespace ranging
