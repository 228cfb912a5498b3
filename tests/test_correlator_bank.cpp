// The parallel correlator bank and the peak detector on ideal coded bursts, float and fixed.
#include <gtest/gtest.h>

#include <cmath>

#include "model/codes.hpp"
#include "model/correlator_bank.hpp"
#include "model/error.hpp"
#include "model/excitation.hpp"
#include "model/peak_detector.hpp"

using namespace ranging;

namespace {

constexpr int kPeriod = 25, kNc = 100;

std::vector<double> burst_stream(const CodeFamily& fam, const std::vector<int>& codes, int start,
                                 int spacing, double amp, std::size_t total) {
  std::vector<double> x(total, 0.0);
  ExcitationParams ex;
  ex.amplitude = amp;
  for (std::size_t i = 0; i < codes.size(); ++i) {
    const auto e = bpsk_excitation(fam.codes[codes[i] - 1], ex);
    for (std::size_t k = 0; k < e.size(); ++k) x[start + i * spacing + k] += e[k];
  }
  return x;
}

std::int64_t to_raw(double v, int frac) { return std::llround(std::ldexp(v, frac)); }

}  // namespace

TEST(CorrelatorBank, FloatPeakIsAtTheEndOfTheMatchedCode) {
  const CodeFamily fam = code_family("Gold4");
  for (int j = 1; j <= fam.eta(); ++j) {
    CorrelatorBankFloat bank(fam.codes, kPeriod, kNc);
    const int start = 37;  // not a multiple of the carrier period: phase independence
    const auto x = burst_stream(fam, {j}, start, 0, 0.5, 2000);
    double best_p = -1;
    int best_n = -1, best_code = -1;
    double best_rho2 = 0;
    for (int n = 0; n < static_cast<int>(x.size()); ++n) {
      bank.execute(x[n]);
      for (int c = 0; c < bank.codes(); ++c) {
        if (bank.power()[c] > best_p) {
          best_p = bank.power()[c];
          best_n = n;
          best_code = c + 1;
          best_rho2 = bank.rho2(c);
        }
      }
    }
    EXPECT_EQ(best_code, j);
    EXPECT_EQ(best_n, start + fam.length * kNc - 1);
    EXPECT_NEAR(best_rho2, 1.0, 1e-9) << "a clean matched burst has rho^2 = 1";
  }
}

TEST(CorrelatorBank, FixedTracksFloatWithinQuantization) {
  const CodeFamily fam = code_family("M1");
  CorrelatorFixedConfig cfg;
  CorrelatorBankFloat fb(fam.codes, kPeriod, kNc);
  CorrelatorBankFixed xb(fam.codes, kPeriod, kNc, cfg);
  const auto& l = xb.layout();
  const auto x = burst_stream(fam, {3}, 11, 0, 0.6, 1600);
  // P_fixed ~ P_float * 2^(2 (mix_frac + data_int - 1 - corr_shift)) (data_int = 1 here)
  const double k = std::exp2(2.0 * (l.mix_frac - l.corr_shift));
  double max_p = 0, max_err = 0;
  for (double v : x) {
    const std::int64_t y = to_raw(v, cfg.data_frac);
    fb.execute(std::ldexp(static_cast<double>(y), -cfg.data_frac));
    xb.execute(y);
    for (int c = 0; c < fb.codes(); ++c) {
      max_p = std::max(max_p, fb.power()[c] * k);
      max_err = std::max(max_err, std::abs(fb.power()[c] * k - static_cast<double>(xb.power()[c])));
    }
  }
  ASSERT_GT(max_p, 1e7);  // a burst well above the quantization floor
  // Per component, C carries <= 1/2 LSB from its own rounding plus the mixer's rounding summed
  // over L*Nc samples (700 * 2^-(mix_frac+1) = 350 mixer LSB = 0.17 LSB of C): |dC| <= 0.67,
  // so |dP| <= 2 (|Re C| + |Im C|) 0.67 + 2 * 0.67^2 <= 1.9 sqrt(P) + 1.
  EXPECT_LE(max_err, 1.9 * std::sqrt(max_p) + 1.0);
  EXPECT_EQ(xb.overflow_events().total(), 0u);
}

TEST(CorrelatorBank, ScoreMatchesFloatRho2AtThePeak) {
  const CodeFamily fam = code_family("Gold1");
  CorrelatorFixedConfig cfg;
  CorrelatorBankFloat fb(fam.codes, kPeriod, kNc);
  CorrelatorBankFixed xb(fam.codes, kPeriod, kNc, cfg);
  const int start = 5;
  const auto x = burst_stream(fam, {8}, start, 0, 0.3, 1000);
  const int peak = start + fam.length * kNc - 1;
  for (int n = 0; n <= peak; ++n) {
    const std::int64_t y = to_raw(x[n], cfg.data_frac);
    fb.execute(std::ldexp(static_cast<double>(y), -cfg.data_frac));
    xb.execute(y);
  }
  const double score = std::ldexp(static_cast<double>(xb.score(7)), -cfg.score_bits);
  EXPECT_NEAR(score, fb.rho2(7), 2e-3);
  EXPECT_GT(score, 0.99);
}

TEST(CorrelatorBank, FullScaleInputNeverOverflows) {
  for (const char* name : {"M1", "M3", "Gold7"}) {
    const CodeFamily fam = code_family(name);
    CorrelatorFixedConfig cfg;
    CorrelatorBankFixed xb(fam.codes, kPeriod, kNc, cfg);
    // Worst case for the mixer and combiner: a full-scale matched burst and a full-scale
    // square wave at the carrier (the sign of the LO), back to back.
    const auto x = burst_stream(fam, {1}, 0, 0, 1.0, 4000);
    // The data word's full range (Q2.14: [-2, 2)), not just the ADC's.
    const std::int64_t fs_max = (std::int64_t{1} << (cfg.data_bits - 1)) - 1;
    const double word_scale = std::ldexp(1.0, cfg.data_bits - 1 - cfg.data_frac);
    for (std::size_t n = 0; n < x.size(); ++n) {
      std::int64_t y = std::clamp(to_raw(word_scale * x[n], cfg.data_frac), -fs_max - 1, fs_max);
      if (n >= 2000) y = ((n / 12) % 2 == 0) ? fs_max : -fs_max - 1;
      xb.execute(y);
    }
    EXPECT_EQ(xb.overflow_events().total(), 0u) << name;
  }
}

TEST(CorrelatorBank, LayoutFollowsTheDocumentedBounds) {
  CorrelatorFixedConfig cfg;
  const auto l = resolve_correlator_layout(cfg, kPeriod, kNc, 7, 9);
  EXPECT_EQ(l.mix_frac, 16);
  EXPECT_EQ(l.mix_shift, 14 + 15 - 16);
  EXPECT_EQ(l.chip_bits, 18 + 7);
  EXPECT_EQ(l.comb_bits, 18 + 7 + 3);
  EXPECT_EQ(l.corr_shift, 11);
  EXPECT_GE(l.rho_scale, std::int64_t{1} << (cfg.score_bits - 1));
  EXPECT_LT(l.rho_scale, std::int64_t{1} << cfg.score_bits);
  ASSERT_EQ(l.lo_cos.size(), 25u);
  EXPECT_EQ(l.lo_cos[0], 32767);
  EXPECT_EQ(l.lo_sin[0], 0);
}

TEST(CorrelatorBank, ImpossibleConfigurationsAreRefused) {
  CorrelatorFixedConfig cfg;
  cfg.mix_bits = 40;  // more fraction bits than data x LO has
  EXPECT_THROW(resolve_correlator_layout(cfg, kPeriod, kNc, 7, 9), InputError);
  cfg = {};
  cfg.corr_bits = 1;
  EXPECT_THROW(resolve_correlator_layout(cfg, kPeriod, kNc, 7, 9), InputError);
  cfg = {};
  EXPECT_THROW(resolve_correlator_layout(cfg, kPeriod, 110, 7, 9), InputError);  // not whole cycles
  cfg.energy_shift = 0;  // score scale too large for score_bits
  EXPECT_THROW(resolve_correlator_layout(cfg, kPeriod, kNc, 7, 9), InputError);
}

TEST(CorrelatorBank, ResetRestoresTheInitialState) {
  const CodeFamily fam = code_family("M2");
  CorrelatorBankFixed xb(fam.codes, kPeriod, kNc, {});
  const auto x = burst_stream(fam, {2}, 3, 0, 0.5, 900);
  auto run = [&] {
    std::vector<std::int64_t> out;
    for (double v : x) {
      xb.execute(to_raw(v, 14));
      out.push_back(xb.power()[1]);
    }
    return out;
  };
  const auto a = run();
  xb.reset();
  EXPECT_EQ(run(), a);
}

TEST(PeakDetector, ParabolicFractionRule) {
  EXPECT_EQ(parabolic_fraction(10, 20, 10, 8), 0);
  EXPECT_GT(parabolic_fraction(10, 20, 15, 8), 0);    // peak leans right
  EXPECT_LT(parabolic_fraction(15, 20, 10, 8), 0);
  EXPECT_EQ(parabolic_fraction(0, 20, 20, 8), 128);   // +1/2, clamped
  EXPECT_EQ(parabolic_fraction(20, 20, 0, 8), -128);
  EXPECT_EQ(parabolic_fraction(20, 20, 20, 8), 0);    // flat: no curvature
  // (15-10) * 256 / (2 * (40 - 25)) = 42.67 -> 42 (toward zero)
  EXPECT_EQ(parabolic_fraction(10, 20, 15, 8), 42);
}

TEST(PeakDetector, TwoBurstsGiveTwoEventsFloatAndFixed) {
  const CodeFamily fam = code_family("Gold4");
  const int start = 123, spacing = 1500;
  const auto x = burst_stream(fam, {4, 9}, start, spacing, 0.4, 5000);
  DetectorConfig dc;
  CorrelatorFixedConfig cc;
  CorrelatorBankFloat fb(fam.codes, kPeriod, kNc);
  CorrelatorBankFixed xb(fam.codes, kPeriod, kNc, cc);
  PeakDetectorFloat fd(dc, fam.length * kNc);
  PeakDetectorFixed xd(dc, xb.layout(), cc);
  std::vector<Event> fe;
  std::vector<EventFixed> xe;
  for (double v : x) {
    const std::int64_t y = to_raw(v, cc.data_frac);
    fb.execute(std::ldexp(static_cast<double>(y), -cc.data_frac));
    xb.execute(y);
    if (auto e = fd.execute(fb)) fe.push_back(*e);
    if (auto e = xd.execute(xb)) xe.push_back(*e);
  }
  if (auto e = fd.flush()) fe.push_back(*e);
  if (auto e = xd.flush()) xe.push_back(*e);
  ASSERT_EQ(fe.size(), 2u);
  ASSERT_EQ(xe.size(), 2u);
  const int peaks[2] = {start + 7 * kNc - 1, start + spacing + 7 * kNc - 1};
  const int codes[2] = {4, 9};
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(fe[i].code, codes[i]);
    EXPECT_EQ(xe[i].code, codes[i]);
    EXPECT_NEAR(fe[i].arrival, peaks[i], 0.5);
    const Event xf = xe[i].to_float(dc.frac_bits, cc.score_bits);
    EXPECT_NEAR(xf.arrival, peaks[i], 0.5);
    EXPECT_NEAR(xf.score, fe[i].score, 2e-3);
    EXPECT_NEAR(xf.margin, fe[i].margin, 2e-3);
    EXPECT_GT(fe[i].margin, 0.1);
  }
}

TEST(PeakDetector, NoiseFreeSilenceGivesNoEvent) {
  const CodeFamily fam = code_family("M1");
  CorrelatorFixedConfig cc;
  CorrelatorBankFixed xb(fam.codes, kPeriod, kNc, cc);
  PeakDetectorFixed xd({}, xb.layout(), cc);
  int events = 0;
  for (int n = 0; n < 3000; ++n) {
    xb.execute((n % 7) - 3);  // a few LSB of junk, far below min_energy
    events += xd.execute(xb).has_value();
  }
  events += xd.flush().has_value();
  EXPECT_EQ(events, 0);
}
