// The paper's metrics and system equations (eq. 1, 3, 4, 9, 12; Tables 4-6).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "model/base/error.hpp"
#include "model/sim/metrics.hpp"

using namespace ranging;

TEST(Pearson, HandCases) {
  const std::vector<double> a = {1, 2, 3, 4, 5};
  std::vector<double> neg, shifted, scaled;
  for (double v : a) {
    neg.push_back(-v);
    shifted.push_back(v + 1000.0);
    scaled.push_back(3.0 * v - 7.0);
  }
  EXPECT_DOUBLE_EQ(pearson(a, a), 1.0);
  EXPECT_DOUBLE_EQ(pearson(a, neg), -1.0);
  EXPECT_NEAR(pearson(a, shifted), 1.0, 1e-15);  // invariant to a constant offset
  EXPECT_NEAR(pearson(a, scaled), 1.0, 1e-15);
  // By hand: x = [1,2,3], y = [1,3,2]: dx = [-1,0,1], dy = [-1,1,0] -> 1/(sqrt2*sqrt2) = 0.5.
  EXPECT_NEAR(pearson(std::vector<double>{1, 2, 3}, std::vector<double>{1, 3, 2}), 0.5, 1e-15);
  // Orthogonal after mean removal: [1,-1,1,-1] vs [1,1,-1,-1] -> 0.
  EXPECT_NEAR(pearson(std::vector<double>{1, -1, 1, -1}, std::vector<double>{1, 1, -1, -1}), 0.0, 1e-15);
  // Offset invariance of the second argument too, with a large offset.
  const std::vector<double> x = {0.3, -1.2, 2.5, 0.7, -0.4}, y = {1.1, 0.2, -0.9, 2.0, 0.5};
  std::vector<double> y_off;
  for (double v : y) y_off.push_back(v + 1e6);
  EXPECT_NEAR(pearson(x, y_off), pearson(x, y), 1e-9);
  EXPECT_EQ(pearson(a, std::vector<double>(5, 2.0)), 0.0);  // zero variance
  EXPECT_THROW(pearson(a, std::vector<double>{1, 2}), InputError);
  EXPECT_THROW(pearson(std::vector<double>{}, std::vector<double>{}), InputError);
}

TEST(Distinguishability, ArgmaxAndMargin) {
  const std::vector<double> rhos = {0.2, 0.35, 0.9, -0.1, 0.71, 0.3, 0.05};
  const auto d = distinguishability(rhos);
  EXPECT_EQ(d.best_code, 3);
  EXPECT_DOUBLE_EQ(d.rho_max, 0.9);
  EXPECT_DOUBLE_EQ(d.rho_submax, 0.71);
  EXPECT_NEAR(d.u, 0.19, 1e-15);
  // Best code first or last; ties give u = 0 and the lowest index.
  EXPECT_EQ(distinguishability(std::vector<double>{0.8, 0.1}).best_code, 1);
  EXPECT_EQ(distinguishability(std::vector<double>{0.1, 0.8}).best_code, 2);
  const auto tie = distinguishability(std::vector<double>{0.5, 0.7, 0.7});
  EXPECT_EQ(tie.best_code, 2);
  EXPECT_EQ(tie.u, 0.0);
  // All negative correlations still decode to the largest.
  const auto negd = distinguishability(std::vector<double>{-0.5, -0.2, -0.9});
  EXPECT_EQ(negd.best_code, 2);
  EXPECT_NEAR(negd.u, 0.3, 1e-15);
  EXPECT_THROW(distinguishability(std::vector<double>{0.5}), InputError);
  EXPECT_THROW(distinguishability(std::vector<double>{0.5, NAN}), InputError);
}

TEST(Energy, SumOfSquares) {
  EXPECT_EQ(energy(std::vector<double>{}), 0.0);
  EXPECT_DOUBLE_EQ(energy(std::vector<double>{3, -4, 1}), 26.0);
  // A sine of amplitude A over an integer number of periods has energy N*A^2/2.
  std::vector<double> s(1000);
  for (std::size_t i = 0; i < s.size(); ++i) s[i] = 2.0 * std::sin(2 * M_PI * 0.04 * i);
  EXPECT_NEAR(energy(s), 1000 * 4.0 / 2, 1e-9);
}

TEST(DurationTd, SyntheticBursts) {
  // Zeros, then a burst from sample 100 to 299 whose edges sit exactly at the threshold.
  std::vector<double> x(500, 0.0);
  for (std::size_t i = 100; i < 300; ++i) x[i] = (i % 2 ? 1.0 : -1.0) * 0.5;
  x[200] = -2.0;  // peak b = 2, a = 0.2
  x[90] = 0.2;    // exactly a: not above
  x[95] = -0.21;  // just above: the start
  x[320] = 0.19;  // below
  x[310] = 0.25;  // the end
  const auto d = duration_td(x, 5e6);
  EXPECT_EQ(d.first, 95u);
  EXPECT_EQ(d.last, 310u);
  EXPECT_DOUBLE_EQ(d.seconds, 215 / 5e6);
  // Dips below threshold inside the burst do not end it (first to last above a).
  std::vector<double> y(100, 0.0);
  y[10] = 1.0;
  y[50] = -1.0;
  const auto e = duration_td(y, 1e3);
  EXPECT_EQ(e.first, 10u);
  EXPECT_EQ(e.last, 50u);
  EXPECT_DOUBLE_EQ(e.seconds, 0.04);
  // Decaying exponential burst: |x| > b/10 until exp(-n/tau) = 0.1 -> n = tau*ln 10.
  std::vector<double> z(2000, 0.0);
  const double tau = 100.0;
  for (std::size_t i = 0; i < 1500; ++i) z[300 + i] = std::exp(-static_cast<double>(i) / tau);
  const auto f = duration_td(z, 1.0);
  EXPECT_EQ(f.first, 300u);
  EXPECT_EQ(f.last, 300u + static_cast<std::size_t>(std::floor(tau * std::log(10.0))));
  EXPECT_THROW(duration_td(std::vector<double>(10, 0.0), 5e6), InputError);
  EXPECT_THROW(duration_td(std::vector<double>{}, 5e6), InputError);
  EXPECT_THROW(duration_td(std::vector<double>{1.0}, 0.0), InputError);
}

TEST(EtaRequired, Equation3) {
  EXPECT_EQ(eta_required(1.0, 0.49e-3, 340.0), 7);  // "greater than six" (section 2.2)
  // Exactly at an integer ratio no extra code is demanded, despite rounding in T.
  EXPECT_EQ(eta_required(1.0, 1.0 / (7.0 * 340.0), 340.0), 7);
  EXPECT_EQ(eta_required(1.0, 1.0 / (9.0 * 340.0), 340.0), 9);
  EXPECT_EQ(eta_required(1.0, 0.99 / (9.0 * 340.0), 340.0), 10);
  EXPECT_EQ(eta_required(0.1, 1e-3, 340.0), 1);
  EXPECT_THROW(eta_required(1.0, 0.0, 340.0), InputError);
  EXPECT_THROW(eta_required(-1.0, 1e-3, 340.0), InputError);
}

TEST(Vmax, ReproducesTable6FromTable5) {
  // M1: min(1/(1.5*182.2 us) = 3659 Hz, 7*340/1 = 2380 Hz).
  EXPECT_NEAR(1.0 / (1.5 * 182.2e-6), 3659.0, 0.5);
  EXPECT_DOUBLE_EQ(vmax(182.2e-6, 7, 340.0, 1.0), 2380.0);
  EXPECT_DOUBLE_EQ(vmax(184.8e-6, 7, 340.0, 1.0), 2380.0);  // M2
  // Gold: eta 9 -> 3060 Hz for every family of Table 5 (T_d 176.0 .. 189.2 us).
  for (double td : {176.0, 185.8, 189.2, 183.0, 185.6, 180.8, 183.0}) {
    EXPECT_DOUBLE_EQ(vmax(td * 1e-6, 9, 340.0, 1.0), 3060.0) << td;
  }
  // When the duration limits: T_d = 400 us -> 1/(600 us).
  EXPECT_NEAR(vmax(400e-6, 9, 340.0, 1.0), 1666.6666666666667, 1e-9);
  EXPECT_THROW(vmax(0.0, 7, 340.0, 1.0), InputError);
  EXPECT_THROW(vmax(1e-4, 0, 340.0, 1.0), InputError);
}

TEST(Heron, VerticalDistance) {
  // Right triangle 3-4-5 with s = 5: altitude onto the hypotenuse = 3*4/5.
  EXPECT_NEAR(heron_vertical_distance(3.0, 4.0, 5.0), 2.4, 1e-14);
  // Same triangle, s = 3 (a leg): altitude onto it is the other leg, 4.
  EXPECT_NEAR(heron_vertical_distance(4.0, 5.0, 3.0), 4.0, 1e-14);
  // Equilateral side 0.5 m: sqrt(3)/2 * 0.5.
  EXPECT_NEAR(heron_vertical_distance(0.5, 0.5, 0.5), std::sqrt(3.0) / 4.0, 1e-15);
  // Symmetric blade crossing: slant 0.5 m each, tips moved s = 0.6 m -> sqrt(0.25 - 0.09) = 0.4.
  EXPECT_NEAR(heron_vertical_distance(0.5, 0.5, 0.6), 0.4, 1e-14);
  // Thin triangle (h = 0.1 mm from sides ~0.5 m); the tolerance is the input's own
  // conditioning: slant carries ~5e-17 rounding, i.e. ~3e-13 on h.
  const double h = 1e-4, half = 0.5;
  const double slant = std::sqrt(half * half + h * h);
  EXPECT_NEAR(heron_vertical_distance(slant, slant, 1.0), h, 1e-12);
  EXPECT_EQ(heron_vertical_distance(1.0, 1.0, 2.0), 0.0);  // degenerate: flat
  EXPECT_THROW(heron_vertical_distance(1.0, 1.0, 3.0), InputError);
  EXPECT_THROW(heron_vertical_distance(1.0, 5.0, 1.0), InputError);
  EXPECT_THROW(heron_vertical_distance(0.0, 1.0, 1.0), InputError);
  EXPECT_THROW(heron_vertical_distance(1.0, 1.0, -1.0), InputError);
}
