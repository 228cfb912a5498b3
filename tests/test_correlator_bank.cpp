// The parallel correlator bank and the peak detector on coded templates, float and fixed.
#include <gtest/gtest.h>

#include <cmath>

#include "model/dsp/correlator_bank.hpp"
#include "model/base/error.hpp"
#include "model/dsp/peak_detector.hpp"
#include "model/dsp/receiver.hpp"

using namespace ranging;

namespace {

ReceiverDesign design(const char* family, const char* reference = "received") {
  ReceiverConfig cfg;
  cfg.family = family;
  cfg.reference = reference;
  return design_receiver(cfg);
}

// Code templates (the bank's own references) at the given offsets, scaled to peak `amp`.
std::vector<double> stream(const ReceiverDesign& d, const std::vector<std::pair<int, int>>& bursts,
                           double amp, std::size_t total) {
  std::vector<double> x(total, 0.0);
  for (auto [code, start] : bursts) {
    const auto& t = d.templates[code - 1];
    double peak = 0;
    for (double v : t) peak = std::max(peak, std::abs(v));
    for (std::size_t k = 0; k < t.size() && start + k < total; ++k) x[start + k] += amp * t[k] / peak;
  }
  return x;
}

std::int64_t to_raw(double v, int frac) { return std::llround(std::ldexp(v, frac)); }

}  // namespace

TEST(CorrelatorBank, EachTemplateIsDecodedAsItsOwnCodeWithRho2One) {
  for (const char* fam : {"M1", "M2", "M3", "Gold1", "Gold3", "Gold7"}) {
    for (const char* mode : {"received", "ideal"}) {
      const ReceiverDesign d = design(fam, mode);
      for (int j = 1; j <= d.family.eta(); ++j) {
        CorrelatorBankFloat bank(d.reference);
        double best = -1, best_rho2 = 0;
        int best_code = 0;
        for (double v : stream(d, {{j, 40}}, 0.5, d.templates[0].size() + 200)) {
          if (!bank.execute(v)) continue;
          for (int c = 0; c < bank.codes(); ++c) {
            if (bank.rho2(c) > best) {
              best = bank.rho2(c);
              best_code = c + 1;
              best_rho2 = bank.rho2(c);
            }
          }
        }
        EXPECT_EQ(best_code, j) << fam << " " << mode;
        // Cauchy-Schwarz: 1 at the own template (up to the decimation grid).
        EXPECT_NEAR(best_rho2, 1.0, 0.02) << fam << " " << mode << " code " << j;
      }
    }
  }
}

TEST(CorrelatorBank, FixedScoreTracksFloatRho2) {
  const ReceiverDesign d = design("Gold4");
  CorrelatorBankFloat fb(d.reference);
  CorrelatorBankFixed xb(d.reference, d.config.correlator);
  const int frac = d.config.correlator.data_frac;
  double max_err = 0;
  int outputs = 0;
  for (double v : stream(d, {{5, 17}}, 0.4, 2000)) {
    const std::int64_t y = to_raw(v, frac);
    const bool a = fb.execute(std::ldexp(static_cast<double>(y), -frac));
    const bool b = xb.execute(y);
    ASSERT_EQ(a, b);
    if (!a || fb.energy() < 1e-3) continue;
    ++outputs;
    for (int c = 0; c < fb.codes(); ++c) {
      const double s = std::ldexp(static_cast<double>(xb.score(c)), -d.config.correlator.score_bits);
      max_err = std::max(max_err, std::abs(s - std::min(fb.rho2(c), 1.0)));
    }
  }
  ASSERT_GT(outputs, 50);  // decimated outputs with signal: ~97 at D = 20
  // Quantization of C (16 bits at 0.4 FS: ~13 significant bits), of the weights (16 bits) and
  // the truncated norm keep the score within 1 % of rho^2.
  EXPECT_LT(max_err, 0.01);
  EXPECT_EQ(xb.overflow_events().total(), 0u);
}

TEST(CorrelatorBank, FullScaleTemplatePeaksBetweenAQuarterAndAHalfOfTheWords) {
  for (const char* fam : {"M1", "M3", "Gold7"}) {
    const ReceiverDesign d = design(fam);
    const auto& cfg = d.config.correlator;
    std::int64_t max_f = 0, max_c = 0;
    for (int j = 1; j <= d.family.eta(); ++j) {
      CorrelatorBankFixed xb(d.reference, cfg);
      for (double v : stream(d, {{j, 3}}, 1.0, d.templates[0].size() + 100)) {
        if (!xb.execute(to_raw(v, cfg.data_frac))) continue;
        max_f = std::max({max_f, std::abs(xb.chip_re()), std::abs(xb.chip_im())});
        for (int c = 0; c < xb.codes(); ++c) {
          max_c = std::max({max_c, std::abs(xb.corr_re()[c]), std::abs(xb.corr_im()[c])});
        }
      }
      EXPECT_EQ(xb.overflow_events().total(), 0u) << fam << " code " << j;
    }
    EXPECT_GE(max_f, std::int64_t{1} << (cfg.chip_bits - 3)) << fam;
    EXPECT_LE(max_f, std::int64_t{1} << (cfg.chip_bits - 2)) << fam;
    EXPECT_GE(max_c, std::int64_t{1} << (cfg.corr_bits - 4)) << fam;  // |C| <= sqrt(2) max part
    EXPECT_LE(max_c, std::int64_t{1} << (cfg.corr_bits - 2)) << fam;
  }
}

TEST(CorrelatorBank, ImpossibleConfigurationsAreRefused) {
  const ReceiverDesign d = design("M1");
  CorrelatorFixedConfig cfg = d.config.correlator;
  cfg.mix_bits = 40;  // more fraction bits than data x LO has
  EXPECT_THROW(resolve_correlator_layout(d.reference, cfg), InputError);
  cfg = d.config.correlator;
  cfg.corr_bits = 1;
  EXPECT_THROW(resolve_correlator_layout(d.reference, cfg), InputError);
  cfg = d.config.correlator;
  cfg.energy_shift = 0;  // weights would not fit weight_bits
  EXPECT_THROW(resolve_correlator_layout(d.reference, cfg), InputError);
  CorrelatorReference r = d.reference;
  r.decimation = 7;  // does not divide 100
  EXPECT_THROW(resolve_correlator_layout(r, d.config.correlator), InputError);
  r = d.reference;
  r.code_gain.pop_back();
  EXPECT_THROW(CorrelatorBankFloat{r}, InputError);
}

TEST(CorrelatorBank, ResetRestoresTheInitialState) {
  const ReceiverDesign d = design("M2");
  CorrelatorBankFixed xb(d.reference, d.config.correlator);
  const auto x = stream(d, {{2, 3}}, 0.5, 1500);
  auto run = [&] {
    std::vector<std::uint64_t> out;
    for (double v : x) {
      if (xb.execute(to_raw(v, 14))) out.push_back(xb.weighted_power()[1]);
    }
    return out;
  };
  const auto a = run();
  xb.reset();
  EXPECT_EQ(run(), a);
}

TEST(PeakDetector, ParabolicFractionRule) {
  EXPECT_EQ(parabolic_fraction(10, 20, 10, 8), 0);
  EXPECT_GT(parabolic_fraction(10, 20, 15, 8), 0);  // peak leans right
  EXPECT_LT(parabolic_fraction(15, 20, 10, 8), 0);
  EXPECT_EQ(parabolic_fraction(0, 20, 20, 8), 128);  // +1/2, clamped
  EXPECT_EQ(parabolic_fraction(20, 20, 0, 8), -128);
  EXPECT_EQ(parabolic_fraction(20, 20, 20, 8), 0);  // flat: no curvature
  // (15-10) * 256 / (2 * (40 - 25)) = 42.67 -> 42 (toward zero)
  EXPECT_EQ(parabolic_fraction(10, 20, 15, 8), 42);
}

// Two bursts, each arrival shifted by a fraction of the decimation: the events move with them.
TEST(PeakDetector, EventsFollowTheBurstsToASubSample) {
  const ReceiverDesign d = design("Gold4");
  const auto& cc = d.config.correlator;
  const int spacing = 2 * d.reference.window;
  auto events = [&](int start) {
    const auto x = stream(d, {{4, start}, {9, start + spacing}}, 0.4, start + 3 * spacing);
    CorrelatorBankFloat fb(d.reference);
    CorrelatorBankFixed xb(d.reference, cc);
    PeakDetectorFloat fd(d.config.detector, d.reference);
    PeakDetectorFixed xd(d.config.detector, xb.layout(), cc);
    std::vector<Event> fe, xe;
    for (double v : x) {
      const std::int64_t y = to_raw(v, cc.data_frac);
      if (fb.execute(std::ldexp(static_cast<double>(y), -cc.data_frac))) {
        if (auto e = fd.execute(fb)) fe.push_back(*e);
      }
      if (xb.execute(y)) {
        if (auto e = xd.execute(xb)) xe.push_back(e->to_float(d.config.detector.frac_bits, cc.score_bits));
      }
    }
    if (auto e = fd.flush()) fe.push_back(*e);
    if (auto e = xd.flush()) xe.push_back(e->to_float(d.config.detector.frac_bits, cc.score_bits));
    return std::make_pair(fe, xe);
  };
  const auto [f0, x0] = events(100);
  ASSERT_EQ(f0.size(), 2u);
  ASSERT_EQ(x0.size(), 2u);
  EXPECT_EQ(f0[0].code, 4);
  EXPECT_EQ(f0[1].code, 9);
  EXPECT_EQ(x0[0].code, 4);
  EXPECT_EQ(x0[1].code, 9);
  EXPECT_NEAR(f0[1].arrival - f0[0].arrival, spacing, 0.5);
  for (int shift = 1; shift < d.reference.decimation; ++shift) {
    const auto [f, x] = events(100 + shift);
    ASSERT_EQ(f.size(), 2u);
    ASSERT_EQ(x.size(), 2u);
    for (int i = 0; i < 2; ++i) {
      EXPECT_NEAR(f[i].arrival - f0[i].arrival, shift, 0.5) << "float, shift " << shift;
      EXPECT_NEAR(x[i].arrival - x0[i].arrival, shift, 0.5) << "fixed, shift " << shift;
      EXPECT_NEAR(x[i].score, f[i].score, 0.01);
      EXPECT_GT(f[i].margin, 0.05);
    }
  }
}

TEST(PeakDetector, QuietInputGivesNoEvent) {
  const ReceiverDesign d = design("M1");
  const auto& cc = d.config.correlator;
  CorrelatorBankFixed xb(d.reference, cc);
  PeakDetectorFixed xd(d.config.detector, xb.layout(), cc);
  int events = 0;
  for (int n = 0; n < 5000; ++n) {
    if (xb.execute((n % 7) - 3)) events += xd.execute(xb).has_value();  // a few LSB of junk
  }
  events += xd.flush().has_value();
  EXPECT_EQ(events, 0);
}
