// model/sim/fft.hpp: the linear convolution, direct and through FFTW, against a plain sum.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <mutex>
#include <random>
#include <thread>
#include <vector>

#include "model/base/aligned.hpp"
#include "model/base/error.hpp"
#include "model/sim/fft.hpp"

using namespace ranging;

namespace {
std::vector<double> plain(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> c(a.size() + b.size() - 1, 0.0);
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) c[i + j] += a[i] * b[j];
  }
  return c;
}
std::vector<double> random_vector(std::size_t n, std::mt19937_64& rng) {
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> v(n);
  for (double& x : v) x = g(rng);
  return v;
}
}  // namespace

TEST(Convolve, DirectBelowTheThresholdIsThePlainSumBitForBit) {
  std::mt19937_64 rng(1);
  for (std::size_t nb : {1u, 2u, 17u, 64u}) {
    auto a = random_vector(1000, rng);
    a[10] = 0.0;  // zeros are skipped, not summed
    const auto b = random_vector(nb, rng);
    EXPECT_EQ(convolve(a, b), plain(a, b)) << nb;
    EXPECT_EQ(convolve(b, a).size(), a.size() + nb - 1);
  }
  EXPECT_TRUE(convolve(std::vector<double>{}, std::vector<double>{1.0}).empty());
}

TEST(Convolve, FftAboveTheThresholdMatchesThePlainSumToRounding) {
  std::mt19937_64 rng(2);
  for (auto [na, nb] : {std::pair{65u, 65u}, std::pair{2500u, 363u}, std::pair{300u, 4000u}, std::pair{1024u, 1025u}}) {
    const auto a = random_vector(na, rng), b = random_vector(nb, rng);
    const auto want = plain(a, b), got = convolve(a, b);
    ASSERT_EQ(got.size(), want.size());
    double peak = 0, err = 0;
    for (std::size_t k = 0; k < want.size(); ++k) {
      peak = std::max(peak, std::abs(want[k]));
      err = std::max(err, std::abs(got[k] - want[k]));
    }
    EXPECT_LT(err, 1e-13 * peak) << na << " x " << nb;
    EXPECT_GT(err, 0.0) << "the FFT path was not taken";  // the direct sum would be exact
  }
}

TEST(Convolve, ThreadsMayConvolveAtOnce) {
  std::mt19937_64 rng(3);
  const auto a = random_vector(3000, rng), b = random_vector(500, rng);
  const auto want = convolve(a, b);
  std::vector<std::vector<double>> got(4);
  std::vector<std::thread> t;
  for (std::size_t i = 0; i < got.size(); ++i) {
    t.emplace_back([&, i] {
      for (int r = 0; r < 20; ++r) got[i] = convolve(a, b);
    });
  }
  for (auto& th : t) th.join();
  for (const auto& g : got) EXPECT_EQ(g, want);
}

// fft_size: the smallest 2^a 3^b 5^c 7^d >= n, checked against a brute-force scan.
TEST(FftSize, IsTheSmallestSevenSmoothNumberAtLeastN) {
  auto smooth = [](std::size_t v) {
    for (std::size_t p : {2u, 3u, 5u, 7u}) {
      while (v % p == 0) v /= p;
    }
    return v == 1;
  };
  std::size_t expect = 1;
  for (std::size_t n = 1; n <= 5000; ++n) {
    if (expect < n) {
      expect = n;
      while (!smooth(expect)) ++expect;
    }
    ASSERT_EQ(fft_size(n), expect) << n;
  }
  EXPECT_EQ(fft_size(0), 1u);
  EXPECT_EQ(fft_size(1043), 1050u);  // 2 3 5^2 7: the decode's Pearson window of 1043 samples
  EXPECT_EQ(fft_size(std::size_t{1} << 40), std::size_t{1} << 40);
  EXPECT_THROW(fft_size((std::size_t{1} << 40) + 1), InputError);
}

// correlation_fft_size: up to 16384 the smallest of 2^a, 3 2^a, 5 2^a >= n (brute force), then
// fft_size.
TEST(FftSize, CorrelationSizeIsTheSmallestTwoThreeOrFiveTimesAPowerOfTwo) {
  auto form = [](std::size_t v) {
    while (v % 2 == 0) v /= 2;
    return v == 1 || v == 3 || v == 5;
  };
  std::size_t expect = 1;
  for (std::size_t n = 1; n <= 16384; ++n) {
    if (expect < n) {
      expect = n;
      while (!form(expect)) ++expect;
    }
    ASSERT_EQ(correlation_fft_size(n), expect) << n;
    ASSERT_LE(3 * correlation_fft_size(n), 4 * n + 2) << n;  // at most 4/3 n (n > 2)
  }
  EXPECT_EQ(correlation_fft_size(2400), 2560u);  // the decode's Gold Pearson window
  for (std::size_t n : {16385u, 25000u, 307000u}) EXPECT_EQ(correlation_fft_size(n), fft_size(n)) << n;
}

// plan_correlation: the wisdom's measured plans for every size PearsonBank can ask for when the
// wisdom imports here (and estimates otherwise), each computing the circular correlation
// PearsonBank needs; the wisdom is gone after, so the process's other plans (convolve's) are
// the ones they were before, bit for bit.
TEST(CorrelationPlans, EverySizeIsPlannedAndCorrelatesAndOtherPlansDoNotChange) {
  std::mt19937_64 rng(7);
  // convolve() sizes the wisdom also covers (its transforms: 1024, 2048, 4096 points)
  std::vector<std::pair<std::vector<double>, std::vector<double>>> ops;
  for (std::size_t n : {700u, 1500u, 3000u}) ops.emplace_back(random_vector(n, rng), random_vector(300, rng));
  std::vector<std::vector<double>> before;
  for (const auto& [a, b] : ops) before.push_back(convolve(a, b));

  const bool applies = correlation_wisdom_applies();
  std::vector<std::size_t> sizes;
  for (std::size_t n = 1; n <= kCorrelationWisdomPoints; ++n) {
    const std::size_t s = std::max<std::size_t>(64, correlation_fft_size(n));
    if (sizes.empty() || sizes.back() != s) sizes.push_back(s);
  }
  EXPECT_EQ(sizes.front(), 64u);
  EXPECT_EQ(sizes.back(), kCorrelationWisdomPoints);
  for (std::size_t nfft : sizes) {
    const std::size_t nc = nfft / 2 + 1;
    AlignedVector<double> in(nfft), out(nfft);  // as PearsonBank's (the wisdom's alignment)
    AlignedVector<std::complex<double>> spec(nc), prod(nc);
    auto* sp = reinterpret_cast<fftw_complex*>(spec.data());
    auto* pp = reinterpret_cast<fftw_complex*>(prod.data());
    const CorrelationPlans p = plan_correlation(nfft, in.data(), sp, pp, out.data());
    ASSERT_NE(p.fwd, nullptr);
    ASSERT_NE(p.inv, nullptr);
    EXPECT_EQ(p.measured, applies) << nfft;
    // x . t over the first lags (no wrap: t is short), against the plain sum
    const std::size_t nt = std::min<std::size_t>(32, nfft / 4);
    const auto x = random_vector(nfft - nt, rng), t = random_vector(nt, rng);
    std::fill(in.begin(), in.end(), 0.0);
    std::copy(t.begin(), t.end(), in.begin());
    fftw_execute(p.fwd);
    const AlignedVector<std::complex<double>> tspec = spec;
    std::fill(in.begin(), in.end(), 0.0);
    std::copy(x.begin(), x.end(), in.begin());
    fftw_execute(p.fwd);
    for (std::size_t k = 0; k < nc; ++k) prod[k] = spec[k] * std::conj(tspec[k]);
    fftw_execute(p.inv);
    for (std::size_t lag = 0; lag + nt <= x.size(); lag += std::max<std::size_t>(1, x.size() / 50)) {
      double direct = 0;
      for (std::size_t i = 0; i < nt; ++i) direct += x[lag + i] * t[i];
      EXPECT_NEAR(out[lag] / static_cast<double>(nfft), direct, 1e-10) << nfft << " lag " << lag;
    }
    const std::lock_guard<std::mutex> lock(fftw_planner_mutex());
    fftw_destroy_plan(p.fwd);
    fftw_destroy_plan(p.inv);
  }
  for (std::size_t i = 0; i < ops.size(); ++i) {
    EXPECT_EQ(convolve(ops[i].first, ops[i].second), before[i]) << i;
  }
  EXPECT_THROW(plan_correlation(0, nullptr, nullptr, nullptr, nullptr), InputError);
}
