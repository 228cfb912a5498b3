// ReceiverFixedBatch (several streams, one per SIMD lane) against a fresh ReceiverFixed per
// stream: the same events and overflow counts, bit for bit, for streams of any length (empty,
// shorter than one decimated output, ending mid-output), more streams than lanes, every
// bandpass rounding and overflow mode, both multiply widths, with saturating inputs, and an
// out-of-range code refused as the scalar receiver refuses it. On a CPU without AVX-512 the
// batch runs the scalar receiver per stream; the comparison holds either way, and the test
// prints which path ran.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "model/base/error.hpp"
#include "model/dsp/quantize.hpp"
#include "model/dsp/receiver.hpp"
#include "model/dsp/receiver_batch.hpp"

using namespace ranging;

namespace {

// Streams of every code's template at random amplitudes and offsets with noise; stream 1 is
// driven to full scale (the filter and mixer saturate), stream 2 is a full-scale square wave.
std::vector<std::vector<std::int64_t>> make_streams(const ReceiverDesign& d, const std::vector<std::size_t>& lengths,
                                                    unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.02);
  std::uniform_real_distribution<double> amp(0.05, 0.9);
  const int bits = d.config.bandpass.input_bits;
  std::vector<std::vector<std::int64_t>> out;
  for (std::size_t s = 0; s < lengths.size(); ++s) {
    std::vector<double> x(lengths[s], 0.0);
    for (std::size_t at = rng() % 500; at < x.size(); at += 200 + rng() % 3000) {
      const auto& t = d.templates[rng() % d.templates.size()];
      double peak = 0;
      for (double v : t) peak = std::max(peak, std::abs(v));
      const double a = (s == 1 ? 3.0 : amp(rng)) / peak;
      for (std::size_t i = 0; i < t.size() && at + i < x.size(); ++i) x[at + i] += a * t[i];
    }
    std::vector<std::int64_t> q(x.size());
    for (std::size_t i = 0; i < x.size(); ++i) {
      const double v = s == 2 ? ((i / 12) % 2 ? 1.0 : -1.0) : x[i] + noise(rng);
      q[i] = quantize_input(std::clamp(v, -1.0, 1.0), bits, nullptr);
    }
    out.push_back(std::move(q));
  }
  return out;
}

// The default receiver for a family (its decimation fitted to the chip), bandpass rounding r.
ReceiverDesign family_design(const char* family, Rounding r = ReceiverConfig{}.bandpass.rounding) {
  ReceiverConfig cfg;
  cfg.family = family;
  cfg.bandpass.rounding = r;
  fit_decimation_to_chip(cfg);
  return design_receiver(cfg);
}

// 11 streams: two batches, the second partial; lengths around a decimated output's end (D).
std::vector<std::size_t> mixed_lengths(const ReceiverDesign& d) {
  const auto dec = static_cast<std::size_t>(d.layout.decimation);
  return {30011, 24000, 9000, 0, 1, dec - 1, dec, dec + 1, 17777, 30011, 5003};
}

// Every stream through the batch and through its own ReceiverFixed; returns the total
// overflow count (so a case can assert it exercised the overflow path).
std::uint64_t expect_same(const ReceiverDesign& d, const std::vector<std::vector<std::int64_t>>& streams,
                          const char* what) {
  std::vector<std::span<const std::int64_t>> spans(streams.begin(), streams.end());
  ReceiverFixedBatch batch(d);
  std::vector<std::vector<EventFixed>> events;
  std::vector<OverflowCounter> ovf;
  batch.run(spans, events, ovf);
  EXPECT_EQ(events.size(), streams.size());
  std::uint64_t total = 0;
  std::size_t detected = 0;
  for (std::size_t s = 0; s < streams.size(); ++s) {
    ReceiverFixed rx(d);
    std::vector<EventFixed> want;
    rx.execute_block(streams[s], want);
    if (auto e = rx.flush_raw()) want.push_back(*e);
    EXPECT_EQ(events[s], want) << what << " stream " << s << " (" << streams[s].size() << " samples)";
    EXPECT_EQ(ovf[s].saturations, rx.overflow_events().saturations) << what << " stream " << s;
    EXPECT_EQ(ovf[s].wraps, rx.overflow_events().wraps) << what << " stream " << s;
    total += ovf[s].total();
    detected += want.size();
  }
  EXPECT_GT(detected, streams.size()) << what << ": the streams must hold detections to compare";
  return total;
}

}  // namespace

TEST(ReceiverBatch, MatchesTheScalarReceiverPerStreamOfAnyLength) {
  for (const char* family : {"Gold4", "M3"}) {
    const ReceiverDesign d = family_design(family);
    const auto streams = make_streams(d, mixed_lengths(d), 11);
    const std::uint64_t ovf = expect_same(d, streams, family);
    std::printf("[ receiver batch ] %s: %s path, %llu overflow events compared\n", family,
                ReceiverFixedBatch(d).vectorized() ? "AVX-512" : "scalar", static_cast<unsigned long long>(ovf));
  }
}

TEST(ReceiverBatch, MatchesInEveryRoundingAndOverflowModeAndBothMultiplyWidths) {
  struct Case {
    Rounding r;
    Overflow o;
    int data_bits, data_frac, coef_bits, coef_frac;
  };
  // coef_bits 34 takes the full 64-bit multiplies; data_frac = data_bits - 1 (range [-1, 1))
  // makes the loud streams overflow the sections.
  const Case cases[] = {{Rounding::Truncate, Overflow::Saturate, 16, 15, 16, 14},
                        {Rounding::Convergent, Overflow::Wrap, 16, 15, 16, 14},
                        {Rounding::RoundHalfUp, Overflow::Wrap, 14, 13, 12, 10},
                        {Rounding::Convergent, Overflow::Saturate, 24, 22, 34, 30},
                        {Rounding::RoundHalfUp, Overflow::Saturate, 24, 23, 34, 31},
                        {Rounding::Truncate, Overflow::Wrap, 24, 22, 20, 18}};
  std::uint64_t overflowed = 0;
  for (const Case& c : cases) {
    ReceiverConfig cfg;
    cfg.bandpass.rounding = c.r;
    cfg.bandpass.overflow = c.o;
    cfg.bandpass.data_bits = c.data_bits;
    cfg.bandpass.data_frac = c.data_frac;
    cfg.bandpass.coef_bits = c.coef_bits;
    cfg.bandpass.coef_frac = c.coef_frac;
    cfg.bandpass.acc_bits = 64;
    const ReceiverDesign d = design_receiver(cfg);
    const auto streams = make_streams(d, {20000, 20000, 20000, 15000, 20000, 12345, 20000, 20000, 777}, 5);
    const std::string what = "data " + std::to_string(c.data_bits) + "/" + std::to_string(c.data_frac) + " coef " +
                             std::to_string(c.coef_bits) + "/" + std::to_string(c.coef_frac);
    const std::uint64_t ovf = expect_same(d, streams, what.c_str());
    overflowed += ovf > 0;
    if (c.data_frac == c.data_bits - 1) {
      EXPECT_GT(ovf, 0u) << what << ": the loud streams must overflow";
    }
  }
  EXPECT_GE(overflowed, 4u);
}

// The bank's weight multiply Q = P w takes a 32 x 32 -> 64 unsigned multiply when P and w fit
// 32 bits (corr_bits <= 16: P <= 2^(2 corr_bits - 1)), else the full 64-bit one: both against
// the scalar receiver, at the boundary (16, 17) and beyond, with the loud stream saturating C.
TEST(ReceiverBatch, TheBanksWeightMultiplyMatchesAtEveryCorrelatorWidth) {
  // (corr_bits 24 with weight_bits 24 would exceed the layout's 63 bits)
  const std::pair<int, int> widths[] = {{12, 12}, {12, 24}, {16, 12}, {16, 24}, {17, 12}, {17, 24}, {24, 12}};
  for (const auto& [corr_bits, weight_bits] : widths) {
    ReceiverConfig cfg;
    cfg.correlator.corr_bits = corr_bits;
    cfg.correlator.weight_bits = weight_bits;
    const ReceiverDesign d = design_receiver(cfg);
    const auto streams = make_streams(d, {20000, 20000, 20000, 15000, 20000, 12345, 20000, 20000, 777}, 9);
    const std::string what = "corr_bits " + std::to_string(corr_bits) + " weight_bits " + std::to_string(weight_bits);
    expect_same(d, streams, what.c_str());
  }
}

// Leading silence at fixed precision: a batch's common leading codes of 0 are skipped in steps
// of P when the design allows it (every rounding mode: 0 rounds to 0), with the scalar
// receiver's events and overflow counts; lanes silent to their end (one ends where the skip
// does); a gate that opens on silence (threshold 0, min_energy 0) skips nothing.
TEST(ReceiverBatch, FixedSkipsLeadingSilenceWithTheSameResults) {
  const Rounding modes[] = {Rounding::RoundHalfUp, Rounding::Truncate, Rounding::Convergent};
  for (const char* family : {"Gold4", "M3"}) {
    for (Rounding r : modes) {
      const ReceiverDesign d = family_design(family, r);
      const std::size_t p = ReceiverFixedBatch(d).silence_step();
      if (ReceiverFixedBatch(d).vectorized()) {
        EXPECT_GT(p, 0u) << family << ": silence stays at reset";
      }
      const std::size_t step = p > 0 ? p : 100;
      const auto base = make_streams(d, {9000, 12000, 0, 7000, 15000, 9000, 11000, 8000, 6000}, 41);
      const std::vector<std::size_t> late = {9 * step + 37, 7 * step + 1, 12 * step, 9 * step + 99, 20 * step,
                                             8 * step - 1,  15 * step,    11 * step + 3, 10 * step};
      std::vector<std::vector<std::int64_t>> streams;
      for (std::size_t s = 0; s < base.size(); ++s) {
        std::vector<std::int64_t> x(late[s], 0);
        x.insert(x.end(), base[s].begin(), base[s].end());
        streams.push_back(std::move(x));
      }
      auto run = [&](const std::vector<std::vector<std::int64_t>>& st, const std::string& what) {
        expect_same(d, st, what.c_str());
        ReceiverFixedBatch b(d);
        std::vector<std::span<const std::int64_t>> spans(st.begin(), st.end());
        std::vector<std::vector<EventFixed>> ev;
        std::vector<OverflowCounter> ovf;
        b.run(spans, ev, ovf);
        return b.silence_skipped();
      };
      // what may be skipped: each batch of 8 lanes' common leading zeros, down to a multiple of P
      auto expected = [&](const std::vector<std::vector<std::int64_t>>& st) {
        std::size_t want = 0;
        for (std::size_t s0 = 0; s0 < st.size(); s0 += 8) {
          std::size_t common = SIZE_MAX;
          for (std::size_t s = s0; s < std::min(st.size(), s0 + 8); ++s) {
            std::size_t i = 0;
            while (i < st[s].size() && st[s][i] == 0) ++i;
            common = std::min(common, i);
          }
          want += p > 0 ? common / p * p : 0;
        }
        return want;
      };
      const std::size_t skipped = run(streams, std::string(family) + " late echoes");
      EXPECT_EQ(skipped, expected(streams)) << family;
      if (p > 0) {
        EXPECT_GE(skipped, 6 * step + 9 * step) << family << ": both batches skip";
      }
      streams[1].assign(3 * step, 0);
      streams[4].assign(3 * step + 5, 0);
      EXPECT_EQ(run(streams, std::string(family) + " silent lanes"), expected(streams)) << family;
      // a code of -1 ends the silence as any other non-zero code
      std::vector<std::vector<std::int64_t>> blip(8, std::vector<std::int64_t>(5 * step - 1, 0));
      for (auto& x : blip) {
        x.push_back(-1);
        x.insert(x.end(), 2 * step, 0);
        x.insert(x.end(), base[0].begin(), base[0].end());
      }
      EXPECT_EQ(run(blip, std::string(family) + " -1 after 5P - 1 zeros"), p > 0 ? 4 * step : 0) << family;
    }
  }
  ReceiverConfig cfg;
  cfg.detector.threshold = 0.0;
  cfg.detector.min_energy = 0.0;
  EXPECT_EQ(ReceiverFixedBatch(design_receiver(cfg)).silence_step(), 0u);
}

TEST(ReceiverBatch, RefusesAnOutOfRangeCodeAsTheScalarReceiverDoes) {
  ReceiverConfig cfg;
  const ReceiverDesign d = design_receiver(cfg);
  std::vector<std::vector<std::int64_t>> streams(3, std::vector<std::int64_t>(5000, 0));
  streams[1][4000] = std::int64_t{1} << cfg.bandpass.input_bits;  // beyond the signed input word
  std::vector<std::span<const std::int64_t>> spans(streams.begin(), streams.end());
  ReceiverFixedBatch batch(d);
  std::vector<std::vector<EventFixed>> events;
  std::vector<OverflowCounter> ovf;
  EXPECT_THROW(batch.run(spans, events, ovf), InputError);
  ReceiverFixed rx(d);
  std::vector<EventFixed> ev;
  EXPECT_THROW(rx.execute_block(streams[1], ev), InputError);
}

namespace {

// ReceiverFloatBatch against ReceiverFloat per stream: the same events and every filtered
// sample, bit for bit (memcmp of the doubles), with the input gain applied the same way.
// Returns the number of events.
std::size_t expect_float_same(const ReceiverDesign& d, const std::vector<std::vector<double>>& volts, double gain,
                              const std::string& what) {
  std::vector<std::span<const double>> spans(volts.begin(), volts.end());
  ReceiverFloatBatch batch(d);
  std::vector<std::vector<Event>> events;
  std::vector<std::vector<double>> filtered;
  batch.run(spans, gain, events, &filtered);
  std::size_t detected = 0;
  for (std::size_t s = 0; s < volts.size(); ++s) {
    ReceiverFloat rx(d);
    std::vector<double> x(volts[s].size()), f(volts[s].size());
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = volts[s][i] * gain;
    std::vector<Event> want;
    rx.execute_block(x, want, f);
    if (auto e = rx.flush()) want.push_back(*e);
    EXPECT_EQ(events[s].size(), want.size()) << what << " stream " << s;
    for (std::size_t i = 0; i < std::min(want.size(), events[s].size()); ++i) {
      EXPECT_EQ(events[s][i].code, want[i].code);
      EXPECT_EQ(std::memcmp(&events[s][i].arrival, &want[i].arrival, sizeof(double)), 0) << what << " " << s;
      EXPECT_EQ(std::memcmp(&events[s][i].score, &want[i].score, sizeof(double)), 0) << what << " " << s;
      EXPECT_EQ(std::memcmp(&events[s][i].margin, &want[i].margin, sizeof(double)), 0) << what << " " << s;
    }
    EXPECT_EQ(filtered[s].size(), f.size());
    if (!f.empty() && filtered[s].size() == f.size()) {  // (memcmp of an empty vector's null data is undefined)
      EXPECT_EQ(std::memcmp(filtered[s].data(), f.data(), f.size() * sizeof(double)), 0) << what << " stream " << s;
    }
    detected += want.size();
  }
  std::printf("[ receiver batch ] float %s: %s path, %zu events\n", what.c_str(),
              batch.vectorized() ? "AVX-512" : "scalar", detected);
  return detected;
}

// volts: the codes' streams as doubles at an arbitrary scale, so the gain's rounding matters
std::vector<std::vector<double>> make_volts(const ReceiverDesign& d, unsigned seed) {
  std::vector<std::vector<double>> volts;
  for (const auto& q : make_streams(d, mixed_lengths(d), seed)) {
    std::vector<double> v;
    for (auto c : q) v.push_back(0.037 * static_cast<double>(c) + 1e-7 * static_cast<double>(v.size() % 7));
    volts.push_back(std::move(v));
  }
  return volts;
}
constexpr double kVoltsGain = 1.0 / (0.037 * 2048.0);

}  // namespace

TEST(ReceiverBatch, FloatMatchesTheScalarReceiverPerStreamBitForBit) {
  for (const char* family : {"Gold4", "M3"}) {
    const ReceiverDesign d = family_design(family);
    EXPECT_GT(expect_float_same(d, make_volts(d, 13), kVoltsGain, family), 11u) << family;
  }
}

// The batch calls a lane's detector only when its gate is open or a candidate is pending: the
// gate (threshold on rho^2, min_energy on E) must be the detector's in every setting. A low
// threshold opens it on noise, a high min_energy closes it on the quiet streams; both change
// the events (asserted), and the batch must still match the scalar receiver.
TEST(ReceiverBatch, FloatDetectorGateMatchesAtAnyThresholdAndMinimumEnergy) {
  ReceiverConfig cfg;
  const ReceiverDesign d0 = design_receiver(cfg);
  const auto volts = make_volts(d0, 21);
  const std::size_t base = expect_float_same(d0, volts, kVoltsGain, "default detector");
  cfg.detector.threshold = 0.05;
  const std::size_t low = expect_float_same(design_receiver(cfg), volts, kVoltsGain, "threshold 0.05");
  // thresholds across the bursts' peaks: some peak just above one of them
  for (double thr : {0.15, 0.25, 0.35, 0.45, 0.55, 0.65, 0.75, 0.85, 0.95}) {
    cfg.detector.threshold = thr;
    expect_float_same(design_receiver(cfg), volts, kVoltsGain, "threshold " + std::to_string(thr));
  }
  cfg.detector.threshold = ReceiverConfig{}.detector.threshold;
  cfg.detector.min_energy = 2.0;
  const std::size_t quiet = expect_float_same(design_receiver(cfg), volts, kVoltsGain, "min_energy 2");
  EXPECT_NE(low, base);
  EXPECT_NE(quiet, base);
}

// Leading silence: a batch's common leading +0.0 inputs are skipped in steps of P (the batch's
// silence_step) when the design's silence has a fixed point; the events and every filtered
// sample must stay the scalar receiver's. Lanes start their echoes at different samples (the
// skip is the common prefix, not a multiple of P itself), lanes that are silent to their end
// (one ends exactly where the skip does), -0.0 and a negative gain (x = -0.0: not skipped), and
// a detector whose gate opens on silence (threshold 0, min_energy 0: no fixed point).
TEST(ReceiverBatch, FloatSkipsLeadingSilenceWithTheSameResults) {
  for (const char* family : {"Gold4", "M3"}) {
    const ReceiverDesign d = family_design(family);
    ReceiverFloatBatch probe(d);
    const std::size_t p = probe.silence_step();
    if (probe.vectorized()) {
      EXPECT_GT(p, 0u) << family << ": the default design's silence has a fixed point";
    }
    const std::size_t step = p > 0 ? p : 100;
    const auto base = make_volts(d, 31);
    // silence before stream s's own samples
    auto silenced = [&](const std::vector<std::size_t>& quiet, double zero) {
      std::vector<std::vector<double>> v;
      for (std::size_t s = 0; s < quiet.size(); ++s) {
        std::vector<double> x(quiet[s], zero);
        const auto& b = base[s % base.size()];
        x.insert(x.end(), b.begin(), b.end());
        v.push_back(std::move(x));
      }
      return v;
    };
    const std::vector<std::size_t> late = {9 * step + 37, 7 * step + 1, 12 * step, 9 * step + 99,
                                           20 * step,     8 * step - 1, 15 * step, 11 * step + 3};
    // what the batch may skip: the lanes' common leading x = +0.0, down to a multiple of P
    auto expected = [&](const std::vector<std::vector<double>>& volts, double gain) {
      std::size_t common = SIZE_MAX;
      for (const auto& v : volts) {
        std::size_t i = 0;
        while (i < v.size() && std::signbit(v[i] * gain) == 0 && v[i] * gain == 0.0) ++i;
        common = std::min(common, i);
      }
      return p > 0 ? common / p * p : 0;
    };
    auto run = [&](const std::vector<std::vector<double>>& volts, double gain, const std::string& what) {
      ReceiverFloatBatch b(d);
      std::vector<std::span<const double>> spans(volts.begin(), volts.end());
      std::vector<std::vector<Event>> ev;
      b.run(spans, gain, ev);
      expect_float_same(d, volts, gain, std::string(family) + " " + what);
      return b.silence_skipped();
    };
    // every lane silent for 7P - 1 .. 20P (then the stream's own samples): at least 6P skipped
    const auto late_volts = silenced(late, 0.0);
    const std::size_t skipped = run(late_volts, kVoltsGain, "late echoes");
    EXPECT_EQ(skipped, expected(late_volts, kVoltsGain)) << family;
    if (p > 0) {
      EXPECT_GE(skipped, 6 * step) << family;
    }
    // lanes silent to their end: lengths 3P (ends where the skip does), 3P + 5 and 4P
    std::vector<std::vector<double>> quiet_lanes = silenced(late, 0.0);
    quiet_lanes[1].assign(3 * step, 0.0);
    quiet_lanes[4].assign(3 * step + 5, 0.0);
    quiet_lanes[6].assign(4 * step, 0.0);
    EXPECT_EQ(run(quiet_lanes, kVoltsGain, "silent lanes"), p > 0 ? 3 * step : 0) << family;
    // -0.0 inputs, or +0.0 times a negative gain, are not silence: nothing skipped
    EXPECT_EQ(run(silenced(late, -0.0), kVoltsGain, "-0.0 prefix"), 0u) << family;
    EXPECT_EQ(run(silenced(late, 0.0), -kVoltsGain, "negative gain"), 0u) << family;
  }
  // a gate that opens on silence (rho^2 = 0 >= 0 and E = 0 >= 0): no fixed point, no skip
  ReceiverConfig cfg;
  cfg.detector.threshold = 0.0;
  cfg.detector.min_energy = 0.0;
  const ReceiverDesign open = design_receiver(cfg);
  EXPECT_EQ(ReceiverFloatBatch(open).silence_step(), 0u);
  std::vector<std::vector<double>> v(3, std::vector<double>(5000, 0.0));
  const std::vector<double> b = make_volts(open, 5)[0];
  for (std::size_t s = 0; s < v.size(); ++s) {
    std::copy(b.begin(), b.begin() + 2000, v[s].begin() + static_cast<std::ptrdiff_t>(3000 - 500 * s));
  }
  expect_float_same(open, v, kVoltsGain, "gate open on silence");
}

// bandpass_float_streams (the metrics' float filter on the SIMD lanes) against a fresh
// BandpassFloat per stream, bit for bit: 11 streams of mixed lengths (empty, shorter than a
// vector, around the chunk), cascades of 1, 3 and 5 sections and one of 9 (the scalar path).
TEST(ReceiverBatch, FloatBandpassOnTheLanesIsBandpassFloatPerStream) {
  const ReceiverDesign d = design_receiver(ReceiverConfig{});
  auto volts = make_volts(d, 23);
  volts[4].assign(1023, 0.0);
  for (std::size_t i = 0; i < volts[4].size(); ++i) volts[4][i] = std::sin(0.25 * static_cast<double>(i));
  volts.push_back(std::vector<double>(1025, -0.0));
  std::vector<std::span<const double>> spans(volts.begin(), volts.end());
  for (std::size_t k : {std::size_t{1}, std::size_t{3}, std::size_t{5}, std::size_t{9}}) {
    SosFilter f = d.filter;
    f.sections.clear();
    for (std::size_t i = 0; i < k; ++i) f.sections.push_back(d.filter.sections[i % d.filter.sections.size()]);
    std::vector<std::vector<double>> got;
    bandpass_float_streams(f, spans, got);
    ASSERT_EQ(got.size(), volts.size());
    for (std::size_t s = 0; s < volts.size(); ++s) {
      std::vector<double> want(volts[s].size());
      BandpassFloat(f).execute_block(volts[s], want);
      ASSERT_EQ(got[s].size(), want.size()) << k << " sections, stream " << s;
      if (!want.empty()) {
        EXPECT_EQ(std::memcmp(got[s].data(), want.data(), want.size() * sizeof(double)), 0)
            << k << " sections, stream " << s << " (" << want.size() << " samples)";
      }
    }
  }
}

// The bank's combiner saturations through the batch: a corr_shift 4 below the automatic one
// makes the loud streams saturate C_q (the scalar receiver's count is asserted non-zero), and
// the batch's total per stream must equal the scalar receiver's. (F_q keeps >= 6 dB over a
// full-scale input, so no clamped input reaches its top; the mixer has y's integer bits.)
TEST(ReceiverBatch, CountsTheCombinersSaturationsPerStream) {
  ReceiverConfig cfg;
  cfg.correlator.corr_shift = design_receiver(cfg).layout.corr_shift - 4;
  const ReceiverDesign d = design_receiver(cfg);
  const auto streams = make_streams(d, {20000, 20000, 20000, 9000, 15000}, 17);
  expect_same(d, streams, "corr_shift - 4");
  std::uint64_t corr = 0;
  for (const auto& s : streams) {
    ReceiverFixed rx(d);
    std::vector<EventFixed> ev;
    rx.execute_block(s, ev);
    corr += rx.bank().corr_overflow_events().total();
  }
  EXPECT_GT(corr, 0u);
}
