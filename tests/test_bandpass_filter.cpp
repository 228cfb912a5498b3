// The bandpass SOS cascade in both precisions (model/dsp/bandpass_filter.hpp) on the paper's
// design (design_bandpass defaults: Butterworth order 5, 150-250 kHz at 5 MS/s).
//
// Bounds used below (docs/fixed-point.md derives them):
//   * fixed vs the float cascade with the SAME quantized coefficients on the SAME quantized
//     input: the difference is exactly the response to the section quantizers' errors, each
//     |e| <= LSB/2 (RoundHalfUp), so |diff| <= sum_j LSB/2 * ||g_j||_1 = noise_bound (as long
//     as nothing saturates). Rigorous, so the test fails on any kernel error above it.
//   * zero-input tail: the float response decays like r^n (r = largest pole radius); after
//     N = 2 * ceil(ln 2^-data_bits / ln r) samples it is below LSB/2, so the fixed output is
//     within +-floor(noise_bound/LSB + 1/2) LSB (bounded limit cycle) from then on.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "model/dsp/bandpass_filter.hpp"
#include "model/base/error.hpp"
#include "model/dsp/filter_design.hpp"
#include "model/dsp/fixed_point.hpp"

namespace ranging {
namespace {

constexpr double kFs = 5e6;
constexpr double kCarrier = 200e3;

SosFilter paper_design() { return design_bandpass(BandpassSpec{}, FilterType::Butterworth); }

double lsb(const BandpassFixedConfig& c) { return std::ldexp(1.0, -c.data_frac); }

// Full-scale raw input codes of the default 12-bit word.
std::int64_t in_max(const BandpassFixed& f) { return fx_max_raw(f.input_format()); }
std::int64_t in_min(const BandpassFixed& f) { return fx_min_raw(f.input_format()); }

std::vector<std::int64_t> sine_burst(const BandpassFixed& f, double amplitude, int length) {
  std::vector<std::int64_t> x;
  const double full = std::ldexp(1.0, f.config().input_bits - 1);
  for (int n = 0; n < length; ++n) {
    x.push_back(std::llround(amplitude * full * std::sin(2 * std::numbers::pi * kCarrier * n / kFs)));
  }
  return x;
}

// BPSK at 200 kHz, 4 carrier cycles (100 samples) per chip, random chips, full scale.
std::vector<std::int64_t> bpsk_burst(const BandpassFixed& f, int chips, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<std::int64_t> x;
  const double full = static_cast<double>(in_max(f));
  for (int c = 0; c < chips; ++c) {
    const double sign = (rng() & 1) ? 1.0 : -1.0;
    for (int n = 0; n < 100; ++n) {
      x.push_back(std::llround(sign * full * std::sin(2 * std::numbers::pi * kCarrier * n / kFs)));
    }
  }
  return x;
}

// Impulse response of node k (output of section k) of a float cascade.
std::vector<double> node_impulse_response(const SosFilter& filter, std::size_t k, int length) {
  BandpassFloat f(filter);
  std::vector<double> h;
  for (int n = 0; n < length; ++n) {
    f.execute(n == 0 ? 1.0 : 0.0);
    h.push_back(f.section_outputs()[k]);
  }
  return h;
}

// The input that maximizes node k at the last sample: full-scale codes with the signs of
// node k's impulse response, time reversed.
std::vector<std::int64_t> worst_case_input(const BandpassFixed& f, std::size_t k, int length) {
  const auto h = node_impulse_response(f.quantized_filter(), k, length);
  std::vector<std::int64_t> x(length);
  for (int n = 0; n < length; ++n) x[n] = h[length - 1 - n] >= 0 ? in_max(f) : in_min(f);
  return x;
}

double max_pole_radius(const SosFilter& filter) {
  double r = 0;
  for (const Biquad& s : filter.sections) r = std::max(r, pole_radius(s));
  return r;
}

// Float twin on the fixed filter's exact input values.
double float_input(const BandpassFixed& f, std::int64_t raw) {
  return std::ldexp(static_cast<double>(raw), -(f.config().input_bits - 1));
}

TEST(BandpassFixed, DefaultConfigIsValidAndHeadroomClaimsNoOverflow) {
  const SosFilter design = paper_design();
  const BandpassFixedConfig cfg;
  EXPECT_NO_THROW(validate(cfg, design));
  const BandpassHeadroom h = bandpass_headroom(cfg, design);
  ASSERT_EQ(h.peak_bound.size(), design.sections.size());
  EXPECT_TRUE(h.no_overflow);
  // The design is L-inf scaled (peak |H| = 1 per node), so the worst-case (L1) gain exceeds 1
  // somewhere: the data word needs the second integer bit the default gives it.
  double max_gain = 0;
  for (double g : h.signal_gain) max_gain = std::max(max_gain, g);
  EXPECT_GT(max_gain, 1.0);
  EXPECT_LT(max_gain, 2.0);
  std::printf("  node gains (L1):");
  for (double g : h.signal_gain) std::printf(" %.4f", g);
  std::printf("\n  rounding-noise bound at the output: %.2f LSB; min acc bits %d\n",
              h.noise_bound.back() / lsb(cfg), bandpass_min_acc_bits(cfg, design));
  // Independent check of the model's L1 evaluation for the output node.
  const BandpassFixed f(design, cfg);
  const auto hq = node_impulse_response(f.quantized_filter(), design.sections.size() - 1, 20000);
  double l1 = 0;
  for (double v : hq) l1 += std::abs(v);
  EXPECT_NEAR(h.signal_gain.back(), l1, 1e-9);
}

TEST(BandpassFixed, TracksFloatOn200kHzBurstWithinRoundingBound) {
  const SosFilter design = paper_design();
  const BandpassFixedConfig cfg;
  BandpassFixed fixed(design, cfg);
  BandpassFloat twin(fixed.quantized_filter());  // same coefficients
  BandpassFloat ideal(design);                   // designed coefficients, unquantized input
  const BandpassHeadroom h = bandpass_headroom(cfg, design);

  // ||h - h_q||_1: the most the coefficient quantization can move the output (|x| <= 1).
  const auto hq = node_impulse_response(fixed.quantized_filter(), design.sections.size() - 1, 20000);
  const auto hd = node_impulse_response(design, design.sections.size() - 1, 20000);
  double coef_effect = 0, gain = 0;
  for (std::size_t n = 0; n < hq.size(); ++n) {
    coef_effect += std::abs(hq[n] - hd[n]);
    gain += std::abs(hd[n]);
  }
  const double input_lsb = std::ldexp(1.0, -(cfg.input_bits - 1));

  const double amplitude = 0.9;
  auto x = sine_burst(fixed, amplitude, 2500);  // 100 carrier cycles
  x.resize(6000, 0);
  double worst_twin = 0, worst_ideal = 0, peak = 0;
  for (std::size_t n = 0; n < x.size(); ++n) {
    const double y = std::ldexp(static_cast<double>(fixed.execute_raw(x[n])), -cfg.data_frac);
    const double yt = twin.execute(float_input(fixed, x[n]));
    const double analog = n < 2500 ? amplitude * std::sin(2 * std::numbers::pi * kCarrier * n / kFs) : 0.0;
    const double yi = ideal.execute(analog);
    worst_twin = std::max(worst_twin, std::abs(y - yt));
    worst_ideal = std::max(worst_ideal, std::abs(y - yi));
    peak = std::max(peak, std::abs(y));
  }
  EXPECT_EQ(fixed.overflow_events().total(), 0u);
  EXPECT_GT(peak, 0.85 * amplitude);  // 200 kHz is in the passband
  EXPECT_LE(worst_twin, h.noise_bound.back());
  // Against the ideal design: + coefficient effect + input rounding (LSB/2 through the gain).
  const double ideal_bound = h.noise_bound.back() + coef_effect * amplitude + gain * input_lsb / 2;
  EXPECT_LE(worst_ideal, ideal_bound);
  std::printf("  |fixed - float(same coefs)| max %.2f LSB (bound %.2f LSB); |fixed - ideal| max %.2f LSB "
              "(bound %.2f LSB)\n",
              worst_twin / lsb(cfg), h.noise_bound.back() / lsb(cfg), worst_ideal / lsb(cfg), ideal_bound / lsb(cfg));
}

// Independent reference of the documented node rules, written with the Fixed value type:
// exact products and sums (FixedWide aligns the input word by itself), one fixed_cast per
// section, b1 never skipped.
struct ReferenceCascade {
  std::vector<std::vector<Fixed>> coef;
  std::vector<std::vector<Fixed>> state;  // x1, x2, y1, y2
  FixedFormat data;

  explicit ReferenceCascade(const BandpassFixed& f) : data(f.data_format()) {
    const FixedFormat cf{f.config().coef_bits, f.config().coef_frac};
    for (const auto& row : f.coefficients()) {
      std::vector<Fixed> c;
      for (std::int64_t v : row) c.push_back(Fixed::from_raw(v, cf));
      coef.push_back(c);
      state.push_back(std::vector<Fixed>(4, Fixed::from_raw(0, data)));
    }
  }
  std::vector<std::int64_t> step(const Fixed& input) {
    std::vector<std::int64_t> outs;
    Fixed x = input;
    for (std::size_t k = 0; k < coef.size(); ++k) {
      auto& c = coef[k];
      auto& s = state[k];
      const FixedWide acc = c[0] * x + c[1] * s[0] + c[2] * s[1] - c[3] * s[2] - c[4] * s[3];
      const Fixed y = fixed_cast(acc, data);
      s[1] = s[0];
      s[0] = x;
      s[3] = s[2];
      s[2] = y;
      outs.push_back(y.raw());
      x = y;
    }
    return outs;
  }
};

void expect_matches_reference(const SosFilter& design, const BandpassFixedConfig& cfg, const char* name) {
  BandpassFixed f(design, cfg);
  ReferenceCascade ref(f);
  std::vector<std::int64_t> x = bpsk_burst(f, 10, 7);
  const auto wc = worst_case_input(f, design.sections.size() - 1, 3000);
  x.insert(x.end(), wc.begin(), wc.end());
  std::mt19937 rng(3);
  std::uniform_int_distribution<std::int64_t> any(in_min(f), in_max(f));
  for (int i = 0; i < 2000; ++i) x.push_back(any(rng));
  x.resize(x.size() + 3000, 0);
  for (std::size_t n = 0; n < x.size(); ++n) {
    const std::int64_t y = f.execute_raw(x[n]);
    const auto expected = ref.step(Fixed::from_raw(x[n], f.input_format()));
    ASSERT_EQ(f.section_outputs(), expected) << name << " sample " << n;
    ASSERT_EQ(y, expected.back());
  }
}

TEST(BandpassFixed, StageOutputsMatchIndependentFixedReferenceBitExact) {
  const SosFilter butter = paper_design();
  BandpassFixedConfig cfg;
  expect_matches_reference(butter, cfg, "butter default");
  // b1 == 0 here, so the kernel skips the multiplier; the reference never skips.
  const BandpassFixed plain(butter, cfg);
  for (const auto& row : plain.coefficients()) EXPECT_EQ(row[1], 0);

  // Elliptic: nonzero b1 (the multiplier is used); Truncate / Convergent rounding; a Q1.15
  // data word that does saturate, and wrapping.
  const SosFilter ellip = design_bandpass(BandpassSpec{}, FilterType::Elliptic);
  BandpassFixedConfig e;
  e.coef_frac = 13;
  e.rounding = Rounding::Truncate;
  bool any_b1 = false;
  const BandpassFixed elliptic(ellip, e);
  for (const auto& row : elliptic.coefficients()) any_b1 |= row[1] != 0;
  EXPECT_TRUE(any_b1);
  expect_matches_reference(ellip, e, "ellip truncate");
  BandpassFixedConfig sat = cfg;
  sat.data_frac = 15;
  sat.rounding = Rounding::Convergent;
  expect_matches_reference(butter, sat, "butter Q1.15 convergent saturate");
  sat.overflow = Overflow::Wrap;
  expect_matches_reference(butter, sat, "butter Q1.15 wrap");
}

TEST(BandpassFixed, StageOutputsFollowTheFloatStages) {
  const SosFilter design = paper_design();
  const BandpassFixedConfig cfg;
  BandpassFixed fixed(design, cfg);
  BandpassFloat twin(fixed.quantized_filter());
  const BandpassHeadroom h = bandpass_headroom(cfg, design);
  const auto x = bpsk_burst(fixed, 20, 11);
  std::vector<double> worst(design.sections.size(), 0.0);
  for (std::int64_t v : x) {
    fixed.execute_raw(v);
    twin.execute(float_input(fixed, v));
    for (std::size_t k = 0; k < worst.size(); ++k) {
      const double d = std::ldexp(static_cast<double>(fixed.section_outputs()[k]), -cfg.data_frac) - twin.section_outputs()[k];
      worst[k] = std::max(worst[k], std::abs(d));
    }
  }
  for (std::size_t k = 0; k < worst.size(); ++k) EXPECT_LE(worst[k], h.noise_bound[k]) << "node " << k;
  // The first node has one quantizer behind a single resonator: a handful of LSB at most.
  EXPECT_LE(worst[0], h.noise_bound[0]);
  EXPECT_GT(h.noise_bound.back(), h.noise_bound.front());
}

TEST(BandpassFixed, WorstCaseFullScaleInputNeverSaturatesWithDefaultHeadroom) {
  const SosFilter design = paper_design();
  const BandpassFixedConfig cfg;
  const BandpassHeadroom h = bandpass_headroom(cfg, design);
  ASSERT_TRUE(h.no_overflow);
  for (std::size_t k = 0; k < design.sections.size(); ++k) {
    for (int polarity : {1, -1}) {
      BandpassFixed f(design, cfg);
      auto x = worst_case_input(f, k, 3000);
      if (polarity < 0) {
        for (auto& v : x) v = (v == in_max(f)) ? in_min(f) : in_max(f);
      }
      double peak = 0;
      for (std::int64_t v : x) {
        f.execute_raw(v);
        peak = std::max(peak, std::abs(std::ldexp(static_cast<double>(f.section_outputs()[k]), -cfg.data_frac)));
      }
      EXPECT_EQ(f.overflow_events().total(), 0u) << "node " << k;
      // The input really is the worst case for node k (reaches its L1 gain) ...
      EXPECT_GT(peak, 0.995 * h.signal_gain[k]) << "node " << k;
      // ... and stays inside the headroom bound.
      EXPECT_LE(peak, h.peak_bound[k]) << "node " << k;
    }
  }
}

TEST(BandpassFixed, TooLittleHeadroomIsPredictedAndSaturationsAreCounted) {
  const SosFilter design = paper_design();
  BandpassFixedConfig cfg;
  cfg.data_frac = 15;  // Q1.15: [-1, 1), less than the ~1.9 worst-case gain
  const BandpassHeadroom h = bandpass_headroom(cfg, design);
  EXPECT_FALSE(h.no_overflow);
  std::size_t k = 0;  // a node whose gain exceeds the word
  while (h.signal_gain[k] <= h.limit) ++k;
  BandpassFixed f(design, cfg);
  for (std::int64_t v : worst_case_input(f, k, 3000)) f.execute_raw(v);
  EXPECT_GT(f.overflow_events().saturations, 0u);
  EXPECT_EQ(f.overflow_events().wraps, 0u);
}

void expect_settles(const std::vector<std::int64_t>& burst, const char* name) {
  const SosFilter design = paper_design();
  const BandpassFixedConfig cfg;
  BandpassFixed f(design, cfg);
  BandpassFloat twin(f.quantized_filter());
  const BandpassHeadroom h = bandpass_headroom(cfg, design);
  const double r = max_pole_radius(f.quantized_filter());
  ASSERT_LT(r, 1.0);
  const int settle = 2 * static_cast<int>(std::ceil(std::log(std::ldexp(1.0, -cfg.data_bits)) / std::log(r)));
  const auto k_lsb = static_cast<std::int64_t>(std::floor(h.noise_bound.back() / lsb(cfg) + 0.5));
  for (std::int64_t v : burst) {
    f.execute_raw(v);
    twin.execute(float_input(f, v));
  }
  EXPECT_EQ(f.overflow_events().total(), 0u) << name;
  std::int64_t worst_after = 0, worst_end = 0, last_nonzero = -1;
  const int tail = settle + 20000;
  for (int n = 0; n < tail; ++n) {
    const std::int64_t y = f.execute_raw(0);
    const double yt = twin.execute(0.0);
    if (n >= settle) {
      // The pole-radius settling time is long enough for the linear (float) response ...
      ASSERT_LT(std::abs(yt), lsb(cfg) / 2) << name << " n " << n;
      worst_after = std::max(worst_after, std::abs(y));
      if (n >= tail - 2000) worst_end = std::max(worst_end, std::abs(y));
    }
    if (y != 0) last_nonzero = n;
  }
  // ... and the fixed one stays within the limit-cycle bound.
  EXPECT_LE(worst_after, k_lsb) << name;
  std::printf("  %s: settle %d samples (r = %.5f); after it |y| <= %lld LSB (bound %lld), in the last 2000 "
              "of %d zero samples <= %lld LSB; last nonzero output at %lld\n",
              name, settle, r, static_cast<long long>(worst_after), static_cast<long long>(k_lsb), tail,
              static_cast<long long>(worst_end), static_cast<long long>(last_nonzero));
}

TEST(BandpassFixed, ReturnsToRestAfterFullScaleBursts) {
  const BandpassFixed f(paper_design(), BandpassFixedConfig{});
  expect_settles(worst_case_input(f, f.coefficients().size() - 1, 3000), "worst-case input");
  expect_settles(bpsk_burst(f, 31, 5), "BPSK burst");
}

TEST(BandpassFixed, ResetRestoresTheInitialState) {
  BandpassFixed f(paper_design(), BandpassFixedConfig{});
  BandpassFloat g(paper_design());
  std::vector<double> in(3000);
  for (std::size_t n = 0; n < in.size(); ++n) in[n] = (n < 1000) ? std::sin(2 * std::numbers::pi * kCarrier * n / kFs) : 0.0;
  in[5] = 1.5;  // saturates the input word: counted, then cleared by reset
  for (BandpassFilter* filter : {static_cast<BandpassFilter*>(&f), static_cast<BandpassFilter*>(&g)}) {
    std::vector<double> a(in.size()), b(in.size());
    filter->execute_block(in, a);
    filter->reset();
    filter->execute_block(in, b);
    EXPECT_EQ(a, b);
    EXPECT_NE(a[500], 0.0);
  }
  EXPECT_EQ(f.input_overflow_events().saturations, 1u);
  f.reset();
  EXPECT_EQ(f.input_overflow_events().total(), 0u);
  for (std::int64_t y : f.section_outputs()) EXPECT_EQ(y, 0);
  std::vector<double> out(2);
  EXPECT_THROW(f.execute_block(in, out), InputError);
}

TEST(BandpassFloat, MatchesTheDesignedResponse) {
  const SosFilter design = paper_design();
  for (double freq : {150e3, 200e3, 250e3, 50e3, 350e3}) {
    BandpassFloat f(design);
    // Amplitude by projection on sin/cos over whole periods (10000 samples) after settling.
    double in_phase = 0, quadrature = 0;
    for (int n = 0; n < 40000; ++n) {
      const double w = 2 * std::numbers::pi * freq * n / kFs;
      const double y = f.execute(std::sin(w));
      if (n >= 30000) {
        in_phase += y * std::sin(w) * 2 / 10000;
        quadrature += y * std::cos(w) * 2 / 10000;
      }
    }
    const double peak = std::hypot(in_phase, quadrature);
    EXPECT_NEAR(peak, std::abs(sos_response(design, freq)), 1e-6) << freq;
  }
}

std::string error_of(const BandpassFixedConfig& c, const SosFilter& s) {
  try {
    BandpassFixed f(s, c);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(BandpassFixed, InvalidConfigsAreRefusedNamingTheField) {
  const SosFilter design = paper_design();
  BandpassFixedConfig c;
  c.data_bits = 0;
  EXPECT_NE(error_of(c, design).find("data_bits"), std::string::npos);
  c = {};
  c.data_bits = 65;
  EXPECT_NE(error_of(c, design).find("data_bits"), std::string::npos);
  c = {};
  c.input_bits = 0;
  EXPECT_NE(error_of(c, design).find("input_bits"), std::string::npos);
  c = {};
  c.acc_bits = 65;
  EXPECT_NE(error_of(c, design).find("acc_bits"), std::string::npos);
  c = {};
  c.data_frac = 8;  // below input_bits - 1: the input word would lose bits
  EXPECT_NE(error_of(c, design).find("data_frac"), std::string::npos);
  // Accumulator too small: the message names acc_bits and the minimum.
  c = {};
  const int need = bandpass_min_acc_bits(c, design);
  EXPECT_GT(need, 30);
  c.acc_bits = need - 1;
  const std::string acc = error_of(c, design);
  EXPECT_NE(acc.find("acc_bits"), std::string::npos);
  EXPECT_NE(acc.find("[" + std::to_string(need) + ", 64]"), std::string::npos) << acc;
  c.acc_bits = need;
  EXPECT_EQ(error_of(c, design), "");
  // a1 ~ -1.9 does not fit Q1.15 coefficients.
  c = {};
  c.coef_frac = 15;
  EXPECT_NE(error_of(c, design).find("section 1 a1"), std::string::npos);
  // Empty filter, out-of-range raw input.
  EXPECT_THROW(BandpassFloat(SosFilter{}), InputError);
  BandpassFixed f(design, BandpassFixedConfig{});
  EXPECT_THROW(f.execute_raw(2048), InputError);
  EXPECT_NO_THROW(f.execute_raw(-2048));
}

}  // namespace
}  // namespace ranging
