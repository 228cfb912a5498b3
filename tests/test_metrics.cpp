// The paper's metrics and system equations (eq. 1, 3, 4, 9, 12; Tables 4-6).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <vector>

#include "tests/process.hpp"

#include "model/base/error.hpp"
#include "model/base/aligned.hpp"
#include "model/sim/fft.hpp"
#include "model/sim/metrics.hpp"

#include <fftw3.h>
#include <complex>
#include <cstring>

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
  // Exactly at an integer ratio d = L aliases to 0 (eta c T = L): one more code is demanded,
  // whatever the rounding in T.
  EXPECT_EQ(eta_required(1.0, 1.0 / (7.0 * 340.0), 340.0), 8);
  EXPECT_EQ(eta_required(1.0, 1.0 / (9.0 * 340.0), 340.0), 10);
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

// ---- The matched filter (eq. 9 over lags), eq. 10's u, T_d on a stream ----------------------

namespace {

std::vector<double> random_signal(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nd(0.0, 1.0);
  std::vector<double> v(n);
  for (double& x : v) x = nd(rng);
  return v;
}

// x = zeros(k), t, zeros(tail): the template shifted by k samples.
std::vector<double> shifted(const std::vector<double>& t, std::size_t k, std::size_t tail) {
  std::vector<double> x(k, 0.0);
  x.insert(x.end(), t.begin(), t.end());
  x.resize(x.size() + tail, 0.0);
  return x;
}

}  // namespace

TEST(PearsonOverLags, ShiftedTemplateGivesRhoOneAtItsLag) {
  const auto t = random_signal(64, 1);
  for (std::size_t k : {0u, 1u, 17u, 40u}) {
    const auto x = shifted(t, k, 50);
    const LagRho d = pearson_over_lags(x, t, -10, 200);
    EXPECT_NEAR(d.rho, 1.0, 1e-12) << k;
    EXPECT_EQ(d.lag, static_cast<long>(k));
    PearsonBank bank({t});
    const auto b = bank.search(x, -10, 200);
    ASSERT_EQ(b.size(), 1u);
    EXPECT_NEAR(b[0].rho, 1.0, 1e-12) << k;
    EXPECT_EQ(b[0].lag, static_cast<long>(k));
  }
  // A window that does not reach lag k finds less than 1.
  const auto x = shifted(t, 40, 50);
  EXPECT_LT(pearson_over_lags(x, t, 0, 30).rho, 0.9);
  // Scale and offset do not matter; an inverted copy gives its best positive rho elsewhere.
  std::vector<double> y = x;
  for (double& v : y) v = 3.0 * v + 2.0;
  EXPECT_NEAR(pearson_over_lags(y, t, 0, 80).rho, 1.0, 1e-12);
  // No lag of the window inside x: refused.
  EXPECT_THROW(pearson_over_lags(x, t, 200, 300), InputError);
  PearsonBank bank({t});
  EXPECT_THROW(bank.search(x, 200, 300), InputError);
  EXPECT_THROW(PearsonBank({t, std::vector<double>(10, 1.0)}), InputError);
  EXPECT_THROW(PearsonBank(std::vector<std::vector<double>>{}), InputError);
}

TEST(PearsonOverLags, FftBankEqualsTheDirectDefinition) {
  // Random references and a noisy signal with a scaled copy of one of them: the FFT bank's best
  // rho and lag per reference equal the direct search over the same window.
  std::vector<std::vector<double>> ts;
  for (std::uint64_t j = 0; j < 4; ++j) ts.push_back(random_signal(300, 10 + j));
  auto x = random_signal(1500, 99);
  for (std::size_t i = 0; i < 300; ++i) x[700 + i] += 4.0 * ts[2][i] + 0.5;
  PearsonBank bank(ts);
  for (auto [lo, hi] : {std::pair<long, long>{0, 1200}, {600, 800}, {-50, 100}, {1100, 5000}}) {
    const auto b = bank.search(x, lo, hi);
    for (std::size_t j = 0; j < ts.size(); ++j) {
      const LagRho d = pearson_over_lags(x, ts[j], lo, hi);
      EXPECT_NEAR(b[j].rho, d.rho, 1e-12) << j << " [" << lo << "," << hi << "]";
      EXPECT_EQ(b[j].lag, d.lag) << j;
    }
  }
  EXPECT_EQ(bank.search(x, 0, 1200)[2].lag, 700);
  // Zero variance segments give rho 0 (as pearson()).
  std::vector<double> flat(1000, 1.0);
  EXPECT_EQ(bank.search(flat, 0, 600)[0].rho, 0.0);
}

// A bank told the largest lag span (max_lags) runs every search of up to that many lags on that
// span's transform size, zero-padding the shorter windows at the signal's edges: the result is
// still the direct definition's, and a search of more lags than max_lags gets its own size.
TEST(PearsonOverLags, OneTransformSizeForEveryWindowEqualsTheDirectDefinition) {
  std::vector<std::vector<double>> ts;
  for (std::uint64_t j = 0; j < 3; ++j) ts.push_back(random_signal(300, 20 + j));
  auto x = random_signal(1500, 98);
  for (std::size_t i = 0; i < 300; ++i) x[40 + i] += 3.0 * ts[1][i];
  PearsonBank fixed(ts, 401), own(ts);
  // full span, both edges cut short, a narrow span, and more lags than max_lags
  for (auto [lo, hi] : {std::pair<long, long>{500, 900}, {-200, 200}, {1000, 1400}, {30, 50}, {0, 1200}}) {
    const auto b = fixed.search(x, lo, hi);
    const auto c = own.search(x, lo, hi);
    for (std::size_t j = 0; j < ts.size(); ++j) {
      const LagRho d = pearson_over_lags(x, ts[j], lo, hi);
      EXPECT_NEAR(b[j].rho, d.rho, 1e-12) << j << " [" << lo << "," << hi << "]";
      EXPECT_EQ(b[j].lag, d.lag) << j << " [" << lo << "," << hi << "]";
      EXPECT_NEAR(b[j].rho, c[j].rho, 1e-12) << j << " [" << lo << "," << hi << "]";
    }
  }
  EXPECT_EQ(fixed.search(x, -200, 200)[1].lag, 40);
}

// The bank screens the lags by out/den before it divides (metrics.cpp): its result must be the
// plain loop's (every lag's rho, the first of the largest) bit for bit, also where that rule is
// delicate: the template repeated (rho about 1 at several lags, some clamped at 1), flat windows
// (rho 0 everywhere: the first lag), a signal that only anticorrelates, tiny and huge amplitudes,
// and noise.
TEST(PearsonOverLags, ScreeningTheLagsGivesThePlainLoopsResultBitForBit) {
  std::vector<std::vector<double>> ts;
  for (std::uint64_t j = 0; j < 3; ++j) ts.push_back(random_signal(64, 3 + j));
  PearsonBank screened(ts), plain(ts);
  plain.set_screening(false);
  std::vector<std::vector<double>> xs;
  std::vector<double> rep;
  for (int r = 0; r < 6; ++r) {  // template 0 every 80 samples, 16 zeros between
    rep.insert(rep.end(), ts[0].begin(), ts[0].end());
    rep.insert(rep.end(), 16, 0.0);
  }
  xs.push_back(rep);
  xs.push_back(std::vector<double>(500, -2.5));  // flat
  std::vector<double> neg(500, 0.0);
  for (std::size_t i = 0; i < 64; ++i) neg[100 + i] = -ts[1][i];
  xs.push_back(neg);
  for (double scale : {1e-150, 1e-300, 1e150}) {
    std::vector<double> y = rep;
    for (double& v : y) v *= scale;
    xs.push_back(y);
  }
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    auto x = random_signal(600, 100 + seed);
    for (std::size_t i = 0; i < 64; ++i) x[200 + seed * 7 + i] += (seed % 5) * ts[seed % 3][i];
    xs.push_back(x);
  }
  std::size_t cases = 0;
  for (const auto& x : xs) {
    for (auto [lo, hi] : {std::pair<long, long>{-5, 600}, {3, 400}, {81, 200}, {90, 110}, {150, 151}}) {
      const auto a = screened.search(x, lo, hi), b = plain.search(x, lo, hi);
      ASSERT_EQ(a.size(), b.size());
      for (std::size_t j = 0; j < a.size(); ++j) {
        EXPECT_EQ(a[j].lag, b[j].lag) << cases << " " << j;
        EXPECT_EQ(a[j].rho, b[j].rho) << cases << " " << j;
      }
      ++cases;
    }
  }
  EXPECT_EQ(cases, xs.size() * 5);
  // and the cases are what they claim: rho 1 on the repeats, 0 when flat (at the first lag)
  EXPECT_NEAR(screened.search(rep, 3, 400)[0].rho, 1.0, 1e-12);
  EXPECT_EQ(screened.search(xs[1], 7, 300)[0].rho, 0.0);
  EXPECT_EQ(screened.search(xs[1], 7, 300)[0].lag, 7);
}

// The search's loops (centred sums, lag norms, spectrum product, screening) run in AVX-512 clones on a CPU
// that has them (metrics.cpp). Its results must be, bit for bit, this plain scalar computation
// of the same algorithm (this file is built for the baseline ISA without contraction): a clone
// that fused a product into a sum, or reordered a sum, fails it.
TEST(PearsonOverLags, TheVectorLoopsGiveTheScalarAlgorithmsBits) {
  std::vector<std::vector<double>> ts;
  for (std::uint64_t j = 0; j < 3; ++j) ts.push_back(random_signal(203, 40 + j));
  auto x = random_signal(1500, 9);
  for (std::size_t i = 0; i < 203; ++i) x[611 + i] += 1.5 * ts[2][i];
  PearsonBank bank(ts);
  std::size_t checked = 0;
  for (auto [lo, hi] : {std::pair<long, long>{0, 1297}, {400, 800}, {599, 627}, {3, 10}}) {
    const auto got = bank.search(x, lo, hi);
    // the same steps, scalar: centred window, prefix sums, per-lag norms, FFT correlation
    const std::size_t n = ts[0].size(), lags = static_cast<std::size_t>(hi - lo) + 1, w = lags + n - 1;
    const std::size_t nfft = std::max<std::size_t>(64, correlation_fft_size(w)), nc = nfft / 2 + 1;
    const double* xw = x.data() + lo;
    // the mean in eight lanes (lane u: the samples i = u mod 8), then the lanes in order
    double lane[8] = {};
    for (std::size_t i = 0; i < w; ++i) lane[i % 8] += xw[i];
    double mean = 0;
    for (double v : lane) mean += v;
    mean /= static_cast<double>(w);
    // prefix sums in eight chunks of ceil(w / 8) samples, then each chunk plus the ones before
    std::vector<double> s1(w + 1, 0.0), s2(w + 1, 0.0), den(lags);
    AlignedVector<double> in(nfft, 0.0), out(nfft);  // aligned as the bank's (the plans' alignment)
    const std::size_t len = (w + 7) / 8;
    double o1 = 0, o2 = 0;
    for (std::size_t c = 0; c * len < w; ++c) {
      double a1 = 0, a2 = 0;
      for (std::size_t i = c * len; i < std::min(w, (c + 1) * len); ++i) {
        const double v = xw[i] - mean;
        a1 += v;
        a2 += v * v;
        s1[i + 1] = c == 0 ? a1 : a1 + o1;
        s2[i + 1] = c == 0 ? a2 : a2 + o2;
        in[i] = v;
      }
      o1 += a1;
      o2 += a2;
    }
    double den_max = 0;
    for (std::size_t k = 0; k < lags; ++k) {
      const double m1 = s1[k + n] - s1[k];
      den[k] = std::max(0.0, (s2[k + n] - s2[k]) - m1 * m1 / static_cast<double>(n));
      den_max = std::max(den_max, den[k]);
    }
    for (double& d : den) d = d > 1e-24 * den_max && d > 0 ? std::sqrt(d) : 0.0;
    AlignedVector<std::complex<double>> xs(nc), prod(nc), tsp(nc);
    // the bank's plans (plan_correlation: the wisdom's where it applies)
    const CorrelationPlans plans = plan_correlation(nfft, in.data(), reinterpret_cast<fftw_complex*>(xs.data()),
                                                    reinterpret_cast<fftw_complex*>(prod.data()), out.data());
    const fftw_plan fwd = plans.fwd, inv = plans.inv;
    fftw_execute(fwd);
    const AlignedVector<std::complex<double>> xspec = xs;
    for (std::size_t j = 0; j < ts.size(); ++j) {
      double m = 0, ss = 0;
      for (double v : ts[j]) m += v;
      m /= static_cast<double>(n);
      std::fill(in.begin(), in.end(), 0.0);
      for (std::size_t i = 0; i < n; ++i) in[i] = ts[j][i] - m, ss += in[i] * in[i];
      fftw_execute(fwd);  // into xs
      for (std::size_t i = 0; i < nc; ++i) tsp[i] = std::conj(xs[i]);
      for (std::size_t i = 0; i < nc; ++i) {
        const double ar = xspec[i].real(), ai = xspec[i].imag(), br = tsp[i].real(), bi = tsp[i].imag();
        prod[i] = {ar * br - ai * bi, ar * bi + ai * br};
      }
      fftw_execute(inv);
      const double tn = std::sqrt(ss), inv_nfft = 1.0 / static_cast<double>(nfft);
      LagRho best{-2.0, lo};
      for (std::size_t k = 0; k < lags; ++k) {
        double r = 0;
        if (den[k] > 0 && tn > 0) r = std::clamp(out[k] * inv_nfft / (den[k] * tn), -1.0, 1.0);
        if (r > best.rho) best = {r, lo + static_cast<long>(k)};
      }
      EXPECT_EQ(got[j].lag, best.lag) << lo << " " << j;
      EXPECT_EQ(std::memcmp(&got[j].rho, &best.rho, sizeof(double)), 0) << lo << " " << j << ": " << got[j].rho << " vs "
                                                                         << best.rho;
      ++checked;
    }
    fftw_destroy_plan(fwd);
    fftw_destroy_plan(inv);
  }
  EXPECT_EQ(checked, 12u);
  EXPECT_EQ(bank.search(x, 400, 800)[2].lag, 611);  // and the embedded template is found
}

TEST(PearsonOverLags, AgreesWithNumpyOracle) {
  std::vector<std::vector<double>> ts;
  for (std::uint64_t j = 0; j < 3; ++j) ts.push_back(random_signal(120, 20 + j));
  auto x = random_signal(700, 7);
  for (std::size_t i = 0; i < 120; ++i) x[333 + i] += 2.0 * ts[1][i];
  const std::string path = ::testing::TempDir() + "/pearson_oracle_" + std::to_string(::getpid()) + ".json";
  std::ofstream(path) << nlohmann::json{{"x", x}, {"templates", ts}}.dump();
  const long lo = 100, hi = 500;
  const std::string cmd = std::string(RANGING_PYTHON) + " " + RANGING_SOURCE_DIR +
                          "/tests/oracle/pearson_lags_oracle.py " + path + " " + std::to_string(lo) + " " +
                          std::to_string(hi);
  const auto r = ranging::testing_support::run_command(cmd);
  std::filesystem::remove(path);
  ASSERT_EQ(r.status, 0) << cmd << "\n" << r.err;  // no numpy is a failure, not a skip
  const auto j = nlohmann::json::parse(r.out);
  PearsonBank bank(ts);
  const auto b = bank.search(x, lo, hi);
  ASSERT_EQ(j["best"].size(), ts.size());
  for (std::size_t k = 0; k < ts.size(); ++k) {
    EXPECT_NEAR(b[k].rho, j["best"][k]["rho"].get<double>(), 1e-12) << k;
    EXPECT_EQ(b[k].lag, j["best"][k]["lag"].get<long>()) << k;
  }
  EXPECT_EQ(b[1].lag, 333);
}

TEST(UForSent, Eq10DefinitionOnKnownCases) {
  // Three references: A, an exact copy of A, and B. The signal contains A.
  const auto A = random_signal(80, 3), B = random_signal(80, 4);
  PearsonBank bank({A, A, B});
  const auto x = shifted(A, 25, 40);
  std::vector<double> rhos;
  for (const auto& b : bank.search(x, 0, 200)) rhos.push_back(b.rho);
  // A sent code identical to another code: u = 0 (the decoder cannot tell them apart).
  EXPECT_NEAR(u_for_sent(rhos, 1), 0.0, 1e-12);
  EXPECT_NEAR(u_for_sent(rhos, 2), 0.0, 1e-12);
  // Sent B but A arrived: a misdecode, u = rho_B - rho_A < 0.
  EXPECT_LT(u_for_sent(rhos, 3), -0.5);
  EXPECT_NEAR(u_for_sent(rhos, 3), rhos[2] - 1.0, 1e-12);
  // Hand values: rho(sent) minus the best other, whatever the ranking.
  const std::vector<double> r = {0.2, 0.9, 0.71, 0.3};
  EXPECT_NEAR(u_for_sent(r, 2), 0.19, 1e-15);
  EXPECT_NEAR(u_for_sent(r, 3), -0.19, 1e-15);
  EXPECT_NEAR(u_for_sent(r, 1), -0.7, 1e-15);
  // The decoder's margin (eq. 12 without the code sent) is never negative.
  EXPECT_NEAR(distinguishability(r).u, 0.19, 1e-15);
  EXPECT_THROW(u_for_sent(r, 0), InputError);
  EXPECT_THROW(u_for_sent(r, 5), InputError);
  EXPECT_THROW(u_for_sent(std::vector<double>{0.5}, 1), InputError);
}

TEST(DurationStream, MeasuresUntilTheSignalEndsAndFlagsClipping) {
  constexpr double fs = 5e6;
  // A burst of alternating +-1 over [500, 1000) followed by a slow ring-down 0.999^n that
  // stays above b/10 for ln(10)/ln(1/0.999) = 2302 samples: far longer than any fixed window.
  std::vector<double> x(6000, 0.0);
  for (std::size_t i = 500; i < 1000; ++i) x[i] = (i % 2 ? 1.0 : -1.0);
  const std::size_t ring = 2301;  // 0.999^2301 > 0.1 > 0.999^2302
  for (std::size_t n = 0; n < 2400; ++n) x[1000 + n] = ((1000 + n) % 2 ? 1.0 : -1.0) * std::pow(0.999, n);
  StreamDuration d = duration_td_stream(x, 400, x.size(), 500, 1000, 100, fs);
  EXPECT_EQ(d.first, 500u);
  EXPECT_EQ(d.last, 1000u + ring);
  EXPECT_DOUBLE_EQ(d.seconds, static_cast<double>(ring + 500) / fs);
  EXPECT_FALSE(d.clipped);
  EXPECT_FALSE(d.noise_limited);
  EXPECT_EQ(d.noise_rms, 0.0);
  // The search ends inside the ring-down: flagged.
  d = duration_td_stream(x, 400, 2000, 500, 1000, 100, fs);
  EXPECT_TRUE(d.clipped);
  EXPECT_EQ(d.last, 1999u);
  // The search starts inside the burst: flagged.
  EXPECT_TRUE(duration_td_stream(x, 600, x.size(), 600, 1000, 100, fs).clipped);
  // Noise at 0.05 rms: the noise floor (4.5 sigma = 0.225) sets the threshold, estimated from
  // the samples before the burst; the ring-down is measured to where it sinks below it.
  std::vector<double> y = x;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> nd(0.0, 0.05);
  std::vector<double> noise(y.size());
  for (double& v : noise) v = nd(rng);
  for (std::size_t i = 0; i < y.size(); ++i) y[i] += noise[i];
  // Put the burst after 2000 samples of noise so the floor is estimated on 2000 samples.
  std::vector<double> z(2000, 0.0);
  for (std::size_t i = 0; i < 2000; ++i) z[i] = nd(rng);
  z.insert(z.end(), y.begin(), y.end());
  d = duration_td_stream(z, 2400, z.size(), 2500, 3000, 100, fs);
  EXPECT_TRUE(d.noise_limited);
  EXPECT_NEAR(d.noise_rms, 0.05, 0.005);
  EXPECT_NEAR(d.threshold, 4.5 * d.noise_rms, 1e-15);
  EXPECT_EQ(d.first, 2500u);
  // 0.999^n = 0.225 at n = 1485: the ring-down alone crosses up to there, ring-down plus noise
  // later (the last sample above a), and noise alone (after the ring ends at 5400) never.
  EXPECT_GE(d.last, 3000u + 1485u);
  EXPECT_LT(d.last, 5400u);
  EXPECT_FALSE(d.clipped);
  EXPECT_THROW(duration_td_stream(x, 10, 5, 500, 1000, 100, fs), InputError);
  EXPECT_THROW(duration_td_stream(std::vector<double>(100, 0.0), 0, 100, 0, 100, 10, fs), InputError);
}

// kth_smallest (T_d's noise median) gives std::nth_element's value for every k of arrays that
// take its bracketed pass (n >= 512) and its fallback: noise, many ties, sorted and reversed,
// all equal, zeros of both signs, and a sample that misses the rank (the sampled positions
// all hold the largest values).
TEST(KthSmallest, IsNthElementsValue) {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> noise(0, 1);
  auto check = [&](std::vector<double> v, const char* what) {
    std::vector<double> buf(v.size());
    for (std::size_t k : {std::size_t{0}, v.size() / 4, v.size() / 2, v.size() - 1, (v.size() * 7) / 9}) {
      std::vector<double> a = v, b = v;
      std::nth_element(a.begin(), a.begin() + static_cast<long>(k), a.end());
      const double got = kth_smallest(b.data(), b.size(), k, buf.data());
      ASSERT_EQ(got, a[k]) << what << " n " << v.size() << " k " << k;
    }
  };
  for (std::size_t n : {1u, 2u, 100u, 511u, 512u, 513u, 1999u, 2000u, 3001u}) {
    std::vector<double> v(n);
    for (double& x : v) x = std::abs(noise(rng));
    check(v, "noise");
    for (double& x : v) x = std::floor(4 * std::abs(noise(rng)));
    check(v, "ties");
    std::sort(v.begin(), v.end());
    check(v, "sorted");
    std::reverse(v.begin(), v.end());
    check(v, "reversed");
    check(std::vector<double>(n, 0.25), "equal");
    for (std::size_t i = 0; i < n; ++i) v[i] = i % 2 ? 0.0 : -0.0;
    check(v, "zeros");
    for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<double>(i);
    for (std::size_t i = 0; i < 128 && n >= 512; ++i) v[i * n / 128] = 1e9 + static_cast<double>(i);
    check(v, "missed bracket");
  }
}

TEST(Spearman, RanksWithTies) {
  // Monotone but non-linear: 1; reversed: -1.
  EXPECT_NEAR(spearman(std::vector<double>{1, 2, 3, 4}, std::vector<double>{1, 8, 27, 1000}), 1.0, 1e-15);
  EXPECT_NEAR(spearman(std::vector<double>{1, 2, 3, 4}, std::vector<double>{4, 3, 2, 1}), -1.0, 1e-15);
  // By hand: ranks a = [1,2,3,4,5], b = [2,1,4,3,5]: d^2 sum 4, 1 - 6*4/(5*24) = 0.8.
  EXPECT_NEAR(spearman(std::vector<double>{10, 20, 30, 40, 50}, std::vector<double>{0.2, 0.1, 0.4, 0.3, 0.5}), 0.8,
              1e-15);
  // Ties take the mean rank: a = [1,2,2,3] -> [1,2.5,2.5,4] against [1,2,3,4]: 0.9487 (scipy).
  EXPECT_NEAR(spearman(std::vector<double>{1, 2, 2, 3}, std::vector<double>{1, 2, 3, 4}), 0.9486832980505138, 1e-12);
  EXPECT_TRUE(std::isnan(spearman(std::vector<double>{1, 1, 1}, std::vector<double>{1, 2, 3})));
  EXPECT_THROW(spearman(std::vector<double>{1}, std::vector<double>{1}), InputError);
  EXPECT_THROW(spearman(std::vector<double>{1, 2}, std::vector<double>{1, 2, 3}), InputError);
}
