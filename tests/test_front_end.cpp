// The analog front end of the simulators (model/sim/front_end.hpp): the ADC against a plain
// reference written from its equation, and the white-noise generator's statistics.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>

#include "model/base/error.hpp"
#include "model/sim/front_end.hpp"
#include "model/sim/scene.hpp"

using namespace ranging;

namespace {

// The ADC's equation as docs/scenes.md states it, one sample at a time, through std::round.
double adc_reference(double v, const SceneAdc& a, bool& clip) {
  const double q = a.full_scale_v / std::ldexp(1.0, a.bits - 1);
  const double top = std::ldexp(1.0, a.bits - 1);
  const double r = std::round((v + a.dc_offset_v) / q);
  clip = r < -top || r > top - 1;
  auto code = static_cast<std::int64_t>(std::clamp(r, -top, top - 1));
  if (a.stuck_bit >= 0) {
    const std::int64_t m = std::int64_t{1} << a.bits;
    std::int64_t u = ((code % m) + m) % m;  // the two's-complement pattern
    const std::int64_t bit = std::int64_t{1} << a.stuck_bit;
    u = a.stuck_value ? (u | bit) : (u & ~bit);
    code = u >= m / 2 ? u - m : u;
  }
  return static_cast<double>(code) * q;
}

// Inputs that hit the rounding ties, the rails and beyond, both signs, and random values.
std::vector<double> adc_inputs(const SceneAdc& a, std::uint64_t seed) {
  const double q = a.full_scale_v / std::ldexp(1.0, a.bits - 1);
  const double top = std::ldexp(1.0, a.bits - 1);
  std::vector<double> x;
  for (double k : {0.0, 1.0, 2.0, 3.0, top - 2, top - 1, top, top + 1, 3 * top}) {
    for (double f : {-0.5, -0.49999999, 0.0, 0.49999999, 0.5, 0.50000001}) {
      x.push_back((k + f) * q - a.dc_offset_v);
      x.push_back((-k + f) * q - a.dc_offset_v);
    }
  }
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.3 * a.full_scale_v, 1.3 * a.full_scale_v);
  for (int i = 0; i < 3000; ++i) x.push_back(u(rng));
  x.push_back(1e30);
  x.push_back(-1e30);
  x.push_back(0.0);
  x.push_back(-0.0);
  return x;
}

}  // namespace

TEST(FrontEnd, AdcEqualsItsEquationAtEveryWidthTieAndRail) {
  std::uint64_t seed = 1;
  for (int bits = 2; bits <= 24; ++bits) {
    for (double fs : {1.0, 2.0, 0.3}) {  // power-of-two and other steps
      for (double dc : {0.0, 0.013}) {
        for (int stuck : {-1, 0, bits - 1}) {
          SceneAdc a;
          a.bits = bits;
          a.full_scale_v = fs;
          a.dc_offset_v = dc;
          a.stuck_bit = stuck;
          a.stuck_value = (bits % 2);
          const auto in = adc_inputs(a, seed++);
          std::vector<double> y(in);
          std::vector<std::size_t> clipped;
          const std::size_t n = adc_quantize(y, a, &clipped);
          std::vector<std::size_t> want;
          for (std::size_t i = 0; i < in.size(); ++i) {
            bool clip = false;
            const double r = adc_reference(in[i], a, clip);
            ASSERT_EQ(r, y[i]) << "bits " << bits << " fs " << fs << " dc " << dc << " stuck " << stuck << " x "
                               << in[i];
            ASSERT_FALSE(std::signbit(y[i]) && y[i] == 0.0);
            if (clip) want.push_back(i);
          }
          ASSERT_EQ(clipped, want) << "bits " << bits;
          ASSERT_EQ(n, want.size());
          ASSERT_GT(n, 0u);  // the inputs go beyond full scale
        }
      }
    }
  }
}

TEST(FrontEnd, AdcCountsWithoutAListAndRefusesAWidthOutOfRange) {
  SceneAdc a;
  std::vector<double> y = {0.0, 5.0, -5.0, 0.5};
  EXPECT_EQ(adc_quantize(y, a, nullptr), 2u);
  EXPECT_EQ(y[1], (2048.0 - 1.0) / 2048.0);
  EXPECT_EQ(y[2], -1.0);
  a.bits = 25;
  EXPECT_THROW(adc_quantize(y, a, nullptr), InputError);
  a.bits = 1;
  EXPECT_THROW(adc_quantize(y, a, nullptr), InputError);
}

// A NaN sample (a broken channel stage) is never a silent code: it sits on the low rail and is
// counted as clipped, in the eight-at-a-time loop and in the rest.
TEST(FrontEnd, AdcPutsNaNOnTheLowRailAndCountsIt) {
  SceneAdc a;
  a.bits = 12;
  a.full_scale_v = 2.0;
  std::vector<double> y(11, std::numeric_limits<double>::quiet_NaN());
  y[3] = 0.5;
  std::vector<std::size_t> clipped;
  EXPECT_EQ(adc_quantize(y, a, &clipped), 10u);
  EXPECT_EQ(clipped, (std::vector<std::size_t>{0, 1, 2, 4, 5, 6, 7, 8, 9, 10}));
  for (std::size_t i = 0; i < y.size(); ++i) EXPECT_EQ(y[i], i == 3 ? 0.5 : -2.0) << i;
}

TEST(FrontEnd, WhiteNoiseIsDeterministicPerSeedAndAddsNothingAtZeroSigma) {
  std::vector<double> a(10000, 1.0), b(10000, 1.0), c(10000, 1.0);
  add_white_noise(a, 0.5, 42);
  add_white_noise(b, 0.5, 42);
  add_white_noise(c, 0.5, 43);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  std::vector<double> z(100, 1.0);
  add_white_noise(z, 0.0, 1);
  EXPECT_EQ(z, std::vector<double>(100, 1.0));
}

// add_white_noise is boost::random::normal_distribution<double>(0, 1) on mt19937_64, written
// out (front_end.cpp: eight draws at a time, the engine's twist eight words at a time): the same
// sums, bit for bit, over 3 x 2^21 draws (about 75 000 through the wedges' slow path, 3 800
// through the tail), on a signal of varied values, and a signed zero; and on lengths that end
// inside a group of eight and around the engine's 312-word refills.
TEST(FrontEnd, WhiteNoiseIsBoostsNormalDistributionBitForBit) {
  const std::vector<std::pair<std::uint64_t, std::size_t>> runs = {
      {0ull, std::size_t{1} << 21}, {42ull, (std::size_t{1} << 21) + 5}, {0x9E3779B97F4A7C15ull, std::size_t{1} << 21},
      {7ull, 1}, {7ull, 7}, {7ull, 9}, {8ull, 311}, {8ull, 313}, {9ull, 625}, {9ull, 4099}};
  for (const auto& [seed, n] : runs) {
    std::vector<double> x(n);
    for (std::size_t i = 0; i < n; ++i) x[i] = std::sin(0.001 * static_cast<double>(i)) * 3.0;
    x[0] = -0.0;
    std::vector<double> want = x;
    boost::random::mt19937_64 rng(seed);
    boost::random::normal_distribution<double> nd(0.0, 1.0);
    std::size_t tails = 0;
    for (double& v : want) {
      const double d = nd(rng);
      tails += std::abs(d) > boost::random::detail::normal_table<double>::table_x[1];
      v += 0.37 * d;
    }
    add_white_noise(x, 0.37, seed);
    ASSERT_EQ(std::memcmp(x.data(), want.data(), n * sizeof(double)), 0) << "seed " << seed << ", " << n << " samples";
    if (n > 1000000) {
      EXPECT_GT(tails, 500u);  // the tail path ran
    }
  }
}

// Gaussian, zero mean, the given sigma, white: moments, tails, a Kolmogorov-Smirnov distance
// and the lag-1 correlation over 2^20 draws (fixed seeds, so the test is deterministic; the
// bounds are 5 standard errors or more away from the true values).
TEST(FrontEnd, WhiteNoiseHasTheStatisticsOfGaussianWhiteNoise) {
  const std::size_t n = std::size_t{1} << 20;
  for (std::uint64_t seed : {1ull, 7ull, 0x9E3779B97F4A7C15ull}) {
    std::vector<double> x(n, 0.0);
    const double sigma = 0.002;
    add_white_noise(x, sigma, seed);
    double m = 0, m2 = 0, m4 = 0, lag1 = 0;
    std::size_t beyond3 = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double z = x[i] / sigma;
      m += z;
      m2 += z * z;
      m4 += z * z * z * z;
      beyond3 += std::abs(z) > 3.0;
      if (i) lag1 += z * x[i - 1] / sigma;
    }
    const double dn = static_cast<double>(n);
    m /= dn;
    m2 /= dn;
    m4 /= dn;
    lag1 /= dn;
    EXPECT_NEAR(m, 0.0, 5.0 / std::sqrt(dn)) << seed;
    EXPECT_NEAR(m2, 1.0, 5.0 * std::sqrt(2.0 / dn)) << seed;
    EXPECT_NEAR(m4, 3.0, 5.0 * std::sqrt(96.0 / dn)) << seed;  // kurtosis of a Gaussian
    EXPECT_NEAR(lag1, 0.0, 5.0 / std::sqrt(dn)) << seed;
    const double p3 = std::erfc(3.0 / std::sqrt(2.0));  // 0.0027
    EXPECT_NEAR(static_cast<double>(beyond3) / dn, p3, 5.0 * std::sqrt(p3 / dn)) << seed;
    std::sort(x.begin(), x.end());
    double d = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double cdf = 0.5 * std::erfc(-x[i] / sigma / std::sqrt(2.0));
      d = std::max({d, std::abs(cdf - static_cast<double>(i) / dn), std::abs(cdf - static_cast<double>(i + 1) / dn)});
    }
    EXPECT_LT(d, 1.63 / std::sqrt(dn)) << seed;  // KS at the 1 % level
  }
}
