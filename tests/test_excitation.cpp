// Coded BPSK excitation (eq. 5/6) and the H-bridge drive derived from it.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <cstdint>
#include <numbers>
#include <vector>

#include "model/base/error.hpp"
#include "model/dsp/excitation.hpp"

using namespace ranging;

namespace {
const std::vector<std::uint8_t> kM1_1 = {1, 0, 1, 1, 1, 0, 0};  // paper: s_M1-1

// Energy of x in the band [f_lo, f_hi] (both signs of frequency) over its total energy, by DFT.
double band_energy_fraction(const std::vector<double>& x, double fs, double f_lo, double f_hi) {
  const std::size_t n = x.size();
  double in_band = 0, total = 0;
  for (std::size_t k = 0; k < n; ++k) {
    std::complex<double> acc = 0;
    for (std::size_t i = 0; i < n; ++i) {
      acc += x[i] * std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>((k * i) % n) / n);
    }
    const double p = std::norm(acc);
    total += p;
    double f = static_cast<double>(k) * fs / static_cast<double>(n);
    if (f > fs / 2) f = fs - f;
    if (f >= f_lo && f <= f_hi) in_band += p;
  }
  return in_band / total;
}
}  // namespace

TEST(Excitation, SamplesPerChip) {
  EXPECT_EQ(samples_per_chip(ExcitationParams{}), 100);
  ExcitationParams p;
  p.cycles_per_chip = 2;
  EXPECT_EQ(samples_per_chip(p), 50);
}

TEST(Excitation, RefusesBadParameters) {
  ExcitationParams p;
  p.carrier_hz = 300e3;  // 4*5e6/3e5 = 66.67 samples per chip
  try {
    validate(p);
    FAIL() << "non-integer samples per chip accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("integer"), std::string::npos) << e.what();
  }
  p = {};
  p.cycles_per_chip = 0;
  EXPECT_THROW(validate(p), InputError);
  p = {};
  p.carrier_hz = 3e6;  // above Nyquist
  EXPECT_THROW(validate(p), InputError);
  p = {};
  p.amplitude = -1;
  EXPECT_THROW(validate(p), InputError);
  const std::vector<std::uint8_t> bad = {1, 2, 0};
  EXPECT_THROW(bpsk_excitation(bad, ExcitationParams{}), InputError);
  EXPECT_THROW(hbridge_drive(std::vector<std::uint8_t>{}, ExcitationParams{}), InputError);
}

TEST(Excitation, MatchesEquation5SampleBySample) {
  for (int q : {4, 2}) {
    ExcitationParams p;
    p.cycles_per_chip = q;
    p.amplitude = 2.5;
    const auto e = bpsk_excitation(kM1_1, p);
    const std::size_t spc = static_cast<std::size_t>(q) * 25;  // q*fs/f at 200 kHz, 5 MS/s
    ASSERT_EQ(e.size(), kM1_1.size() * spc);
    for (std::size_t m = 0; m < kM1_1.size(); ++m) {
      for (std::size_t n = 0; n < spc; ++n) {
        // Eq. 5 literally: U*sin(2*pi*f*n/fs + (s(m)+1)*pi), delayed by (fs/f)*q*(m-1) (1-based m).
        const double ref = 2.5 * std::sin(2.0 * std::numbers::pi * 200e3 * static_cast<double>(n) / 5e6 +
                                          (kM1_1[m] + 1.0) * std::numbers::pi);
        ASSERT_NEAR(e[m * spc + n], ref, 1e-12) << "q=" << q << " chip " << m << " n " << n;
      }
    }
  }
}

TEST(Excitation, SignFlipsExactlyAtChipBoundaries) {
  const auto e = bpsk_excitation(kM1_1, ExcitationParams{});
  const std::size_t spc = 100;
  for (std::size_t m = 1; m < kM1_1.size(); ++m) {
    // The first samples of chip m continue the carrier of chip m-1 iff the chips agree.
    const double before = e[m * spc - 1];               // last sample of previous chip
    const double prev_cont = -std::sin(2.0 * std::numbers::pi * 4.0 / 100.0) * (kM1_1[m - 1] ? 1 : -1);
    EXPECT_NEAR(before, prev_cont, 1e-12);
    const double after = e[m * spc + 1];
    const double continued = std::sin(2.0 * std::numbers::pi * 4.0 / 100.0) * (kM1_1[m - 1] ? 1 : -1);
    if (kM1_1[m] == kM1_1[m - 1]) {
      EXPECT_NEAR(after, continued, 1e-12) << "chip " << m;
    } else {
      EXPECT_NEAR(after, -continued, 1e-12) << "chip " << m;
    }
    EXPECT_EQ(e[m * spc], 0.0);  // each chip starts at an exact zero of its carrier
  }
}

TEST(Excitation, HBridgeIsSignOfCarrier) {
  const auto e = bpsk_excitation(kM1_1, ExcitationParams{});
  const auto d = hbridge_drive(kM1_1, ExcitationParams{});
  ASSERT_EQ(d.size(), e.size());
  int zero_crossings = 0;
  for (std::size_t i = 0; i < e.size(); ++i) {
    ASSERT_TRUE(d[i] == 1 || d[i] == -1) << i;
    if (std::abs(e[i]) < 1e-9) {
      ++zero_crossings;
      continue;
    }
    ASSERT_EQ(d[i], e[i] > 0 ? 1 : -1) << "sample " << i;
  }
  // 4 cycles of 25 samples: phase 0 and pi are not both on the grid; only phase 0 is.
  EXPECT_EQ(zero_crossings, 7 * 4);
  // At the exact zeros the sign follows the phase convention: +1 entering [0, pi).
  for (std::size_t m = 0; m < kM1_1.size(); ++m) EXPECT_EQ(d[m * 100], kM1_1[m] ? 1 : -1);
}

TEST(Excitation, HBridgeChipZeroIsNegatedChipOne) {
  const std::vector<std::uint8_t> one = {1}, zero = {0};
  const auto d1 = hbridge_drive(one, ExcitationParams{});
  const auto d0 = hbridge_drive(zero, ExcitationParams{});
  ASSERT_EQ(d1.size(), 100u);
  int sum = 0;
  for (std::size_t i = 0; i < d1.size(); ++i) {
    EXPECT_EQ(d0[i], -d1[i]) << i;
    sum += d1[i];
  }
  // Odd 25-sample period: each cycle has 13 samples at +1 and 12 at -1 (a sampled 50% square).
  EXPECT_EQ(sum, 4);
}

TEST(Excitation, CarrierDominatesSpectrum) {
  // All-ones code: a pure tone, the DFT peak is exactly the 200 kHz bin.
  const std::vector<std::uint8_t> ones(7, 1);
  const auto tone = bpsk_excitation(ones, ExcitationParams{});
  EXPECT_GT(band_energy_fraction(tone, 5e6, 199e3, 201e3), 0.999);
  // Coded: the BPSK main lobe f +- chip rate (150-250 kHz) holds most of the energy.
  const auto coded = bpsk_excitation(kM1_1, ExcitationParams{});
  EXPECT_GT(band_energy_fraction(coded, 5e6, 150e3, 250e3), 0.8);
  EXPECT_LT(band_energy_fraction(coded, 5e6, 0, 100e3), 0.05);
}
