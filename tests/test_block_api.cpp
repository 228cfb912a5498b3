// The fast paths of the golden model against the reference rules they replace:
//   fx_quantize_fast<R, O>  vs fx_quantize (every rounding and overflow mode, every shift);
//   quantize_input (the ADC model's int64 path) vs quantize_input_wide (128-bit), values and
//     saturation counts, at the ties, beside them, at full scale and beyond;
//   BandpassFixed::execute_block  vs a DF1 cascade written here with fx_quantize, for every
//     mode, with overflows, section counts on both sides of the specialized kernels and
//     blocks of random length (the state carries across blocks);
//   ReceiverFixed::execute_block  vs execute_raw per sample (events, overflow counts, last
//     filtered sample), in chunks of random length.
// The RTL equivalence testbenches (tb/) then hold the model to the hardware bit for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "model/base/error.hpp"
#include "model/dsp/bandpass_filter.hpp"
#include "model/dsp/filter_design.hpp"
#include "model/dsp/fixed_point.hpp"
#include "model/dsp/quantize.hpp"
#include "model/dsp/receiver.hpp"

using namespace ranging;

namespace {

const Rounding kRoundings[] = {Rounding::Truncate, Rounding::RoundHalfUp, Rounding::Convergent};
const Overflow kOverflows[] = {Overflow::Wrap, Overflow::Saturate};

std::int64_t fast(Rounding r, Overflow o, std::int64_t raw, int shift, const FxRange& range, OverflowCounter& c) {
  return fx_dispatch(r, o, [&]<Rounding R, Overflow O>() { return fx_quantize_fast<R, O>(raw, shift, range, c); });
}

// Reference DF1 cascade: the header's equations with the generic quantizer.
std::vector<std::int64_t> reference_cascade(const BandpassFixed& f, const std::vector<std::int64_t>& x,
                                            OverflowCounter& events) {
  const auto& coef = f.coefficients();
  const BandpassFixedConfig& c = f.config();
  const FixedFormat data{c.data_bits, c.data_frac, true, c.rounding, c.overflow};
  std::vector<std::array<int128_t, 4>> st(coef.size(), {0, 0, 0, 0});
  std::vector<std::int64_t> out;
  for (std::int64_t v : x) {
    int128_t in = static_cast<int128_t>(v) << (c.data_frac - (c.input_bits - 1));
    for (std::size_t k = 0; k < coef.size(); ++k) {
      const auto& q = coef[k];
      auto& s = st[k];
      const int128_t acc = q[0] * in + q[1] * s[0] + q[2] * s[1] - q[3] * s[2] - q[4] * s[3];
      const std::int64_t y = fx_quantize(acc, c.coef_frac + c.data_frac, data, &events);
      s = {in, s[0], y, s[2]};
      in = y;
    }
    out.push_back(static_cast<std::int64_t>(in));
  }
  return out;
}

std::vector<std::int64_t> loud_input(int bits, std::size_t n, std::uint64_t seed) {
  // A full-scale 200 kHz square-ish burst plus noise: drives a narrow data word into overflow.
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int> noise(-200, 200);
  const std::int64_t top = (std::int64_t{1} << (bits - 1)) - 1, bottom = -(std::int64_t{1} << (bits - 1));
  std::vector<std::int64_t> x;
  for (std::size_t i = 0; i < n; ++i) {
    const double s = std::sin(2 * std::numbers::pi * 200e3 * static_cast<double>(i) / 5e6);
    const double v = std::clamp(1.5 * s * static_cast<double>(top) + noise(rng), static_cast<double>(bottom),
                                static_cast<double>(top));
    x.push_back(static_cast<std::int64_t>(v));
  }
  return x;
}

}  // namespace

TEST(FastQuantizer, MatchesFxQuantizeForEveryModeShiftAndFormat) {
  std::mt19937_64 rng(7);
  std::uint64_t checked = 0, overflows = 0;
  for (Rounding r : kRoundings) {
    for (Overflow o : kOverflows) {
      for (int width : {2, 5, 16, 33, 63, 64}) {
        for (bool is_signed : {true, false}) {
          if (!is_signed && width == 64) continue;
          const FixedFormat fmt{width, 3, is_signed, r, o};
          const FxRange range = fx_range(fmt);
          for (int shift = 0; shift <= 62; ++shift) {
            for (int i = 0; i < 60; ++i) {
              // Magnitudes of every size, ties included (low bits exactly half).
              std::int64_t raw = static_cast<std::int64_t>(rng() >> (rng() % 64));
              if (rng() & 1) raw = -raw;
              if (i % 5 == 0 && shift > 0) raw = (raw & ~((std::int64_t{1} << shift) - 1)) | (std::int64_t{1} << (shift - 1));
              OverflowCounter a, b;
              const std::int64_t want = fx_quantize(raw, fmt.frac + shift, fmt, &a);
              const std::int64_t got = fast(r, o, raw, shift, range, b);
              ASSERT_EQ(got, want) << "raw " << raw << " shift " << shift << " width " << width
                                   << (is_signed ? " signed" : " unsigned");
              ASSERT_EQ(a.saturations, b.saturations);
              ASSERT_EQ(a.wraps, b.wraps);
              overflows += a.total();
              ++checked;
            }
          }
        }
      }
    }
  }
  EXPECT_GT(overflows, checked / 10);  // the overflow branch was exercised, not only the fast path
}

TEST(FastQuantizer, AdcQuantizerMatchesTheWideReferenceAtTiesEdgesAndBeyondFullScale) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.2, 1.2);
  std::uniform_int_distribution<int> e(-1080, 8);
  int compared = 0;
  for (int bits : {2, 3, 8, 12, 16, 24, 32, 40, 41, 48}) {
    std::vector<double> xs = {0.0, -0.0, 1.0, -1.0, 4.0, -4.0, std::nextafter(4.0, 5.0), std::nextafter(-4.0, -5.0),
                              1e300, -1e300, 5e-324, -5e-324};
    const double lsb = std::ldexp(1.0, -(bits - 1));
    for (int k = -40; k <= 40; ++k) {  // the ties k + 1/2 LSB and the doubles beside them
      const double t = (k + 0.5) * lsb;
      for (double v : {t, std::nextafter(t, 1.0), std::nextafter(t, -1.0), k * lsb}) xs.push_back(v);
    }
    for (double top : {1.0 - 0.5 * lsb, -1.0 - 0.5 * lsb, 1.0, -1.0}) {  // the saturation thresholds
      for (double v : {top, std::nextafter(top, 2.0), std::nextafter(top, -2.0)}) xs.push_back(v);
    }
    for (int i = 0; i < 20000; ++i) xs.push_back(i % 2 ? u(rng) : std::ldexp(u(rng), e(rng)));
    OverflowCounter fast_count, wide_count;
    for (double x : xs) {
      ASSERT_EQ(quantize_input(x, bits, &fast_count), quantize_input_wide(x, bits, &wide_count))
          << "bits " << bits << " x " << x;
      ++compared;
    }
    EXPECT_EQ(fast_count.saturations, wide_count.saturations) << "bits " << bits;
    EXPECT_GT(wide_count.saturations, 0u) << "bits " << bits;  // the edges above do saturate
    EXPECT_EQ(fast_count.wraps, 0u);
  }
  EXPECT_GT(compared, 200000);
  EXPECT_THROW(quantize_input(std::numeric_limits<double>::infinity(), 12, nullptr), InputError);
}

// quantize_input_block (eight samples at a time) against the loop it replaces: codes, the
// saturation count and the clamped indices, at the ties, +-1 and beyond, -0.0, tiny values,
// for every word length of both paths, several gains (one negative) and lengths around the
// vector width, infinities (clamped to +-1 first, as the loop does); a NaN throws at the loop's
// sample with the codes before it written.
TEST(FastQuantizer, BlockQuantizerIsTheLoopBitForBit) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(-1.3, 1.3);
  std::uniform_int_distribution<int> e(-1080, 2);
  std::size_t compared = 0, saturated = 0, clamps = 0;
  for (int bits : {2, 3, 12, 16, 24, 40, 41, 52}) {
    const double lsb = std::ldexp(1.0, -(bits - 1));
    std::vector<double> base = {0.0, -0.0, 1.0, -1.0, std::nextafter(1.0, 2.0), std::nextafter(-1.0, -2.0),
                                1.0 - 0.5 * lsb, std::nextafter(1.0 - 0.5 * lsb, 0.0), 5e-324, -5e-324,
                                std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
    for (int k = -20; k <= 20; ++k) {
      const double t = (k + 0.5) * lsb;
      for (double v : {t, std::nextafter(t, 1.0), std::nextafter(t, -1.0), k * lsb}) base.push_back(v);
    }
    for (int i = 0; i < 4000; ++i) base.push_back(i % 3 ? u(rng) : std::ldexp(u(rng), e(rng)));
    std::shuffle(base.begin(), base.end(), rng);
    for (double gain : {1.0, 1.0 / (0.037 * 2048.0), -0.7, 3.0}) {
      for (std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, std::size_t{8}, std::size_t{9},
                            std::size_t{63}, std::size_t{64}, std::size_t{1001}, base.size()}) {
        const std::span<const double> x(base.data(), n);
        std::vector<std::int64_t> want(n), got(n);
        OverflowCounter cw, cg;
        std::vector<std::size_t> lw, lg;
        for (std::size_t i = 0; i < n; ++i) {
          const double v = x[i] * gain;
          if (std::abs(v) > 1.0) lw.push_back(100 + i);
          want[i] = quantize_input(std::clamp(v, -1.0, 1.0), bits, &cw);
        }
        quantize_input_block(x, gain, bits, got.data(), cg, &lg, 100);
        ASSERT_EQ(got, want) << "bits " << bits << " gain " << gain << " n " << n;
        EXPECT_EQ(cg.saturations, cw.saturations) << "bits " << bits << " gain " << gain << " n " << n;
        EXPECT_EQ(cg.wraps, 0u);
        EXPECT_EQ(lg, lw) << "bits " << bits << " gain " << gain << " n " << n;
        OverflowCounter c3;
        quantize_input_block(x, gain, bits, got.data(), c3, nullptr);  // no list: the same codes
        EXPECT_EQ(got, want);
        compared += n;
        saturated += cw.saturations;
        clamps += lw.size();
      }
    }
  }
  EXPECT_GT(compared, 100000u);
  EXPECT_GT(saturated, 0u);
  EXPECT_GT(clamps, 0u);
  // a NaN: InputError at that sample, the codes before it written
  for (double bad : {std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN()}) {
    for (std::size_t at : {std::size_t{0}, std::size_t{5}, std::size_t{8}, std::size_t{21}}) {
      std::vector<double> x(32, 0.25);
      x[at] = bad;
      std::vector<std::int64_t> got(32, -7);
      OverflowCounter c;
      EXPECT_THROW(quantize_input_block(x, 1.0, 12, got.data(), c, nullptr), InputError);
      for (std::size_t i = 0; i < at; ++i) EXPECT_EQ(got[i], 512) << "sample " << i << " before the bad one at " << at;
    }
  }
}

TEST(FastQuantizer, RoundHalfAwayIsStdRoundBitForBit) {
  std::vector<double> xs = {0.0, -0.0, 0.5, -0.5, 1.5, -1.5, 2.5, -2.5, 0.49999999999999994, -0.49999999999999994,
                            4503599627370495.5, -4503599627370495.5, 4503599627370496.0, 9007199254740993.0, 1e300,
                            -1e300, 5e-324, -5e-324, std::numeric_limits<double>::infinity(),
                            -std::numeric_limits<double>::infinity()};
  for (int k = -3000; k <= 3000; ++k) {
    const double t = k + 0.5;
    for (double v : {t, std::nextafter(t, 1e9), std::nextafter(t, -1e9), static_cast<double>(k)}) xs.push_back(v);
  }
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> e(-60, 60);
  for (int i = 0; i < 200000; ++i) xs.push_back(std::ldexp(u(rng), e(rng)));
  for (double v : xs) {
    const double want = std::round(v);
    const double got = round_half_away(v);
    ASSERT_EQ(std::signbit(got), std::signbit(want)) << v;
    ASSERT_EQ(got, want) << std::hexfloat << v;
  }
  EXPECT_TRUE(std::isnan(round_half_away(std::nan(""))));
}

TEST(BandpassBlock, MatchesReferenceCascadeInEveryModeWithOverflowsAndAnySectionCount) {
  std::mt19937_64 rng(11);
  // Butterworth: b0 [1, 0, -1] numerators (the one-multiply kernel); elliptic: general
  // numerators; 9 sections: beyond the specialized kernels.
  const std::pair<FilterType, int> designs[] = {
      {FilterType::Butterworth, 2}, {FilterType::Butterworth, 5}, {FilterType::Butterworth, 9},
      {FilterType::Elliptic, 3}};
  for (const auto& [type, order] : designs) {
    const SosFilter design = design_bandpass(BandpassSpec{}, type, order);
    bool symmetric = true;
    for (const Biquad& b : design.sections) symmetric = symmetric && b.b1 == 0;
    if (type == FilterType::Elliptic) {
      EXPECT_FALSE(symmetric) << "the elliptic design must exercise b1 != 0";
    }
    for (Rounding r : kRoundings) {
      for (Overflow o : kOverflows) {
        BandpassFixedConfig cfg;
        cfg.data_bits = 12;  // Q1.11 = [-1, 1): a clipped full-scale 200 kHz burst overflows it
        cfg.data_frac = 11;
        cfg.acc_bits = 48;
        cfg.rounding = r;
        cfg.overflow = o;
        BandpassFixed f(design, cfg);
        const auto x = loud_input(cfg.input_bits, 3000, rng());
        OverflowCounter ref_events;
        const auto want = reference_cascade(f, x, ref_events);
        std::vector<std::int64_t> got(x.size());
        for (std::size_t i = 0; i < x.size();) {
          const std::size_t n = std::min<std::size_t>(x.size() - i, 1 + rng() % 300);
          f.execute_block(std::span(x).subspan(i, n), std::span(got).subspan(i, n));
          i += n;
        }
        ASSERT_EQ(got, want) << "order " << order;
        EXPECT_EQ(f.overflow_events().saturations, ref_events.saturations);
        EXPECT_EQ(f.overflow_events().wraps, ref_events.wraps);
        EXPECT_GT(ref_events.total(), 0u) << "the input must drive the data word into overflow";
        EXPECT_EQ(f.section_outputs().back(), want.back());
      }
    }
  }
}

TEST(BandpassBlock, RefusesAnOutOfRangeSampleBeforeProcessingTheBlock) {
  BandpassFixed f(design_bandpass(BandpassSpec{}, FilterType::Butterworth), BandpassFixedConfig{});
  std::vector<std::int64_t> x(100, 1000), y(100);
  x[60] = 2048;  // 12-bit input: [-2048, 2047]
  EXPECT_THROW(f.execute_block(x, y), InputError);
  // State untouched: the next sample behaves as from rest.
  BandpassFixed g(design_bandpass(BandpassSpec{}, FilterType::Butterworth), BandpassFixedConfig{});
  EXPECT_EQ(f.execute_raw(1000), g.execute_raw(1000));
  std::vector<std::int64_t> short_out(99);
  EXPECT_THROW(f.execute_block(std::span<const std::int64_t>(x).first(100), short_out), InputError);
}

TEST(ReceiverBlock, MatchesPerSampleExecutionInChunksOfAnyLength) {
  for (const char* family : {"Gold4", "M3"}) {
    ReceiverConfig cfg;
    cfg.family = family;
    fit_decimation_to_chip(cfg);
    const ReceiverDesign d = design_receiver(cfg);
    // Every code of the family back to back, loud enough to clip the mixer/filter now and then.
    std::mt19937_64 rng(3);
    std::normal_distribution<double> noise(0.0, 0.01);
    std::vector<std::int64_t> x;
    for (int rep = 0; rep < 2; ++rep) {
      for (std::size_t j = 0; j < d.templates.size(); ++j) {
        double peak = 0;
        for (double v : d.templates[j]) peak = std::max(peak, std::abs(v));
        for (double v : d.templates[j]) {
          x.push_back(quantize_input(0.9 * v / peak + noise(rng), d.config.bandpass.input_bits, nullptr));
        }
      }
    }
    ReceiverFixed per_sample(d), block(d);
    std::vector<EventFixed> want, got;
    for (auto v : x) {
      if (auto e = per_sample.execute_raw(v)) want.push_back(*e);
    }
    for (std::size_t i = 0; i < x.size();) {
      const std::size_t n = std::min<std::size_t>(x.size() - i, 1 + rng() % 5000);
      block.execute_block(std::span(x).subspan(i, n), got);
      i += n;
    }
    if (auto e = per_sample.flush_raw()) want.push_back(*e);
    if (auto e = block.flush_raw()) got.push_back(*e);
    EXPECT_GE(want.size(), d.templates.size()) << family;
    EXPECT_EQ(got, want) << family;
    EXPECT_EQ(block.filtered(), per_sample.filtered());
    EXPECT_EQ(block.overflow_events().saturations, per_sample.overflow_events().saturations);
    EXPECT_EQ(block.overflow_events().wraps, per_sample.overflow_events().wraps);
    EXPECT_EQ(block.bank().energy(), per_sample.bank().energy());
    EXPECT_EQ(block.bank().weighted_power(), per_sample.bank().weighted_power());
  }
}

// The float model's block forms against execute() per sample: the same doubles, bit for bit.
TEST(FloatBlock, BandpassMatchesPerSampleForAnySectionCountAndBlockLength) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g(0.0, 0.3);
  for (int order : {1, 2, 4, 5, 8, 9}) {  // 1..8 sections specialized, 9 the generic path
    const SosFilter f = design_bandpass(BandpassSpec{}, FilterType::Butterworth, order);
    ASSERT_EQ(f.sections.size(), static_cast<std::size_t>(order));
    BandpassFloat per_sample(f), block(f);
    std::vector<double> x(20000);
    for (double& v : x) v = g(rng);
    std::vector<double> want(x.size()), got(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) want[i] = per_sample.execute(x[i]);
    for (std::size_t i = 0; i < x.size();) {
      const std::size_t n = std::min<std::size_t>(x.size() - i, rng() % 3000);
      block.execute_block(std::span<const double>(x).subspan(i, n), std::span<double>(got).subspan(i, n));
      i += n;
    }
    ASSERT_EQ(got, want) << "order " << order;
    EXPECT_EQ(block.section_outputs(), per_sample.section_outputs()) << "order " << order;
  }
  BandpassFloat b(design_bandpass(BandpassSpec{}, FilterType::Butterworth));
  std::vector<double> in(4), out(3);
  EXPECT_THROW(b.execute_block(in, out), InputError);
}

TEST(FloatBlock, ReceiverMatchesPerSampleExecutionInChunksOfAnyLength) {
  ReceiverConfig cfg;
  const ReceiverDesign d = design_receiver(cfg);
  std::mt19937_64 rng(4);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<double> x;
  for (int rep = 0; rep < 2; ++rep) {
    for (const auto& t : d.templates) {
      double peak = 0;
      for (double v : t) peak = std::max(peak, std::abs(v));
      for (double v : t) x.push_back(0.5 * v / peak + noise(rng));
    }
  }
  ReceiverFloat per_sample(d), block(d);
  std::vector<Event> want, got;
  std::vector<double> fw(x.size()), fg(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (auto e = per_sample.execute(x[i])) want.push_back(*e);
    fw[i] = per_sample.filtered();
  }
  for (std::size_t i = 0; i < x.size();) {
    const std::size_t n = std::min<std::size_t>(x.size() - i, 1 + rng() % 9000);
    block.execute_block(std::span<const double>(x).subspan(i, n), got, std::span<double>(fg).subspan(i, n));
    i += n;
  }
  ASSERT_GE(want.size(), d.templates.size());
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t k = 0; k < want.size(); ++k) {
    EXPECT_EQ(got[k].code, want[k].code);
    EXPECT_EQ(got[k].arrival, want[k].arrival);
    EXPECT_EQ(got[k].score, want[k].score);
    EXPECT_EQ(got[k].margin, want[k].margin);
  }
  EXPECT_EQ(fg, fw);
  EXPECT_EQ(block.filtered(), per_sample.filtered());
  std::vector<double> bad(3);
  EXPECT_THROW(block.execute_block(x, got, bad), InputError);
}

namespace {
// The float bank's equations one sample at a time, with modulo indexing and plain histories
// (the per-sample form it had before its block form): the reference of CorrelatorBankFloat.
struct FloatBankReference {
  const CorrelatorReference& r;
  std::size_t n = 0;
  double acc_re = 0, acc_im = 0, energy = 0;
  std::vector<double> b_re, b_im, y2, bd_re, bd_im, f_re, f_im, q;
  explicit FloatBankReference(const CorrelatorReference& ref)
      : r(ref), b_re(static_cast<std::size_t>(ref.period)), b_im(b_re.size()), y2(static_cast<std::size_t>(ref.window)),
        q(ref.codes.size()) {}
  bool execute(double y) {
    const std::size_t p = n % static_cast<std::size_t>(r.period);
    const double w = 2.0 * std::numbers::pi * static_cast<double>(p) / r.period;
    const double bre = y * std::cos(w), bim = -y * std::sin(w);
    acc_re += bre - b_re[p];
    acc_im += bim - b_im[p];
    b_re[p] = bre;
    b_im[p] = bim;
    const std::size_t yi = n % y2.size();
    energy += y * y - y2[yi];
    y2[yi] = y * y;
    energy = std::max(energy, 0.0);
    ++n;
    if (n % static_cast<std::size_t>(r.decimation) != 0) return false;
    bd_re.push_back(acc_re);
    bd_im.push_back(acc_im);
    const std::size_t k = bd_re.size() - 1;
    double fre = 0, fim = 0;
    for (std::size_t i = 0; i < r.chip_taps.size(); ++i) {
      fre += r.chip_taps[i] * (i <= k ? bd_re[k - i] : 0.0);
      fim += r.chip_taps[i] * (i <= k ? bd_im[k - i] : 0.0);
    }
    f_re.push_back(fre);
    f_im.push_back(fim);
    const std::size_t step = static_cast<std::size_t>(r.chip_samples / r.decimation);
    const std::size_t chips = r.codes.front().size();
    for (std::size_t j = 0; j < q.size(); ++j) {
      double cre = 0, cim = 0;
      for (std::size_t c = 0; c < chips; ++c) {
        const std::size_t back = (chips - 1 - c) * step;
        const double s = r.codes[j][c] ? 1.0 : -1.0;
        cre += s * (back <= k ? f_re[k - back] : 0.0);
        cim += s * (back <= k ? f_im[k - back] : 0.0);
      }
      q[j] = (cre * cre + cim * cim) / r.code_gain[j];
    }
    return true;
  }
};
}  // namespace

TEST(FloatBlock, BankFeedMatchesItsEquationsSampleBySample) {
  for (const char* family : {"Gold4", "M3"}) {
    ReceiverConfig cfg;
    cfg.family = family;
    const ReceiverDesign d = design_receiver(cfg);
    std::mt19937_64 rng(9);
    std::normal_distribution<double> noise(0.0, 0.05);
    std::vector<double> x;
    for (const auto& t : d.templates) {
      for (double v : t) x.push_back(v + noise(rng));
    }
    FloatBankReference ref(d.reference);
    std::vector<std::vector<double>> want_q;
    std::vector<double> want_e;
    for (double v : x) {
      if (ref.execute(v)) {
        want_q.push_back(ref.q);
        want_e.push_back(ref.energy);
      }
    }
    CorrelatorBankFloat bank(d.reference);
    std::size_t k = 0;
    for (std::size_t i = 0; i < x.size();) {
      const std::size_t n = std::min<std::size_t>(x.size() - i, 1 + rng() % 300);
      std::span<const double> rest(x.data() + i, n);
      while (!rest.empty()) {
        rest = rest.subspan(bank.feed(rest));
        if (bank.output_ready()) {
          ASSERT_LT(k, want_q.size());
          ASSERT_EQ(bank.weighted_power(), want_q[k]) << family << " output " << k;
          ASSERT_EQ(bank.energy(), want_e[k]) << family << " output " << k;
          ++k;
        }
      }
      i += n;
    }
    EXPECT_EQ(k, want_q.size());
    EXPECT_GT(k, 100u);
    EXPECT_EQ(bank.sample_index(), static_cast<std::int64_t>(x.size()) - 1);
  }
}
