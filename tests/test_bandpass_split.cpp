// The bandpass time split (bandpass_filter.cpp): a long block runs as 8 segments on SIMD lanes,
// each checked against the true state at its start and recomputed when it differs. Whatever
// the data, one long execute_block must equal the same samples in short blocks (which never
// split): outputs, section outputs, final state (the next block's outputs) and overflow counts,
// bit for bit. Also the receivers that filter long blocks for it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "model/base/error.hpp"
#include "model/dsp/bandpass_filter.hpp"
#include "model/dsp/quantize.hpp"
#include "model/dsp/receiver.hpp"
#include "model/dsp/receiver_batch_kernels.hpp"

using namespace ranging;

namespace {

constexpr std::size_t kShort = 4093;  // short blocks: below kBandpassFloatSplitMin, never split

// Bursts of a 200 kHz tone at `amp` (full-scale units) on noise, `quiet` after sample `stop`.
std::vector<double> signal(std::size_t n, double amp, double noise, std::size_t stop, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nz(0.0, 1.0);
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double tone = ((i / 1700) % 3 == 0 && i < stop) ? amp * std::sin(2 * M_PI * 0.04 * static_cast<double>(i)) : 0.0;
    x[i] = std::clamp(tone + (i < stop ? noise * nz(rng) : 0.0), -1.0, 1.0);
  }
  return x;
}

std::vector<std::int64_t> codes(const std::vector<double>& x, int bits) {
  std::vector<std::int64_t> q(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) q[i] = quantize_input(x[i], bits, nullptr);
  return q;
}

// One long block, then a short tail block (the state after the long block must be the true
// one), against the same samples in short blocks.
struct FixedRun {
  std::vector<std::int64_t> y;
  std::vector<std::int64_t> sections;
  OverflowCounter ovf;
  BandpassSplitStats split;
};
FixedRun run_fixed(const ReceiverDesign& d, const BandpassFixedConfig& cfg, const std::vector<std::int64_t>& in,
                   std::size_t first) {
  BandpassFixed bp(d.filter, cfg);
  FixedRun r;
  r.y.resize(in.size());
  for (std::size_t i = 0; i < in.size();) {
    const std::size_t m = i == 0 ? first : std::min(kShort, in.size() - i);
    bp.execute_block(std::span<const std::int64_t>(in.data() + i, m), std::span<std::int64_t>(r.y.data() + i, m));
    i += m;
  }
  r.sections = bp.section_outputs();
  r.ovf = bp.overflow_events();
  r.split = bp.split_stats();
  return r;
}

void expect_fixed_split_exact(const ReceiverDesign& d, const BandpassFixedConfig& cfg, const std::vector<std::int64_t>& in,
                              const char* what, std::size_t* redone) {
  const std::size_t first = in.size() - 777;  // one long block, then short ones
  const FixedRun plain = run_fixed(d, cfg, in, kShort);
  const FixedRun split = run_fixed(d, cfg, in, first);
  std::size_t diff = 0;
  for (std::size_t i = 0; i < in.size(); ++i) diff += plain.y[i] != split.y[i];
  EXPECT_EQ(diff, 0u) << what;
  EXPECT_EQ(plain.sections, split.sections) << what;
  EXPECT_EQ(plain.ovf.saturations, split.ovf.saturations) << what;
  EXPECT_EQ(plain.ovf.wraps, split.ovf.wraps) << what;
  EXPECT_EQ(plain.split.blocks, 0u) << what;
  if (batch::batch_kernels_available()) {
    EXPECT_EQ(split.split.blocks, 1u) << what << ": the long block did not split";
  }
  *redone += split.split.recomputed;
  std::printf("[ bandpass split ] %s: %llu saturations, %llu wraps, %zu of 7 lanes recomputed\n", what,
              static_cast<unsigned long long>(split.ovf.saturations), static_cast<unsigned long long>(split.ovf.wraps),
              split.split.recomputed);
}

ReceiverDesign default_design() {
  ReceiverConfig cfg;
  fit_decimation_to_chip(cfg);
  return design_receiver(cfg);
}

}  // namespace

TEST(BandpassSplit, FixedLongBlockIsThePlainLoopBitForBit) {
  const ReceiverDesign d = default_design();
  const std::size_t n = kBandpassSplitMin + 54321;
  std::size_t redone = 0;
  // bursts on noise, the default word lengths
  const BandpassFixedConfig base = d.config.bandpass;
  expect_fixed_split_exact(d, base, codes(signal(n, 0.5, 0.01, n, 1), base.input_bits), "bursts", &redone);
  // a data word too narrow for the gain: saturations, counted per lane
  BandpassFixedConfig sat = base;
  sat.data_frac = 15;  // Q0.15: the loud bursts overflow it
  expect_fixed_split_exact(d, sat, codes(signal(n, 0.99, 0.01, n, 2), sat.input_bits), "saturating", &redone);
  BandpassFixedConfig wrap = sat;
  wrap.overflow = Overflow::Wrap;
  expect_fixed_split_exact(d, wrap, codes(signal(n, 0.99, 0.01, n, 3), wrap.input_bits), "wrapping", &redone);
  for (Rounding r : {Rounding::Truncate, Rounding::Convergent}) {
    BandpassFixedConfig c = base;
    c.rounding = r;
    expect_fixed_split_exact(d, c, codes(signal(n, 0.5, 0.01, n, 4), c.input_bits),
                             r == Rounding::Truncate ? "truncate" : "convergent", &redone);
  }
}

TEST(BandpassSplit, ALaneThatDoesNotReachTheTrueStateIsRecomputed) {
  // Loud bursts, then digital silence from the first lane boundary's warm-up on: the true run
  // carries the bursts' ringing (and, truncating, a limit cycle) into the silence, while the
  // warm-up lanes start from zero in silence and stay there. Their states differ; the split
  // must notice and recompute them, and still equal the plain loop.
  const ReceiverDesign d = default_design();
  const std::size_t n = kBandpassSplitMin + 12345;
  BandpassFixedConfig c = d.config.bandpass;
  c.rounding = Rounding::Truncate;
  const std::size_t seg = (n - 777 - 16384) / 8;  // the first block's segment length
  std::size_t redone = 0;
  expect_fixed_split_exact(d, c, codes(signal(n, 0.9, 0.0, seg - 100, 5), c.input_bits), "ringing into silence",
                           &redone);
  if (batch::batch_kernels_available()) {
    EXPECT_GT(redone, 0u) << "no lane was recomputed: the fallback went untested";
  }
}

TEST(BandpassSplit, AFailingSplitBacksOffThenRetries) {
  // Ringing into digital silence with truncation, over three long blocks: every split fails
  // (the true run keeps a limit cycle the zero-started lanes never reach). The filter runs the
  // second block plainly, tries the third again; the outputs are the plain loop's throughout.
  const ReceiverDesign d = default_design();
  BandpassFixedConfig c = d.config.bandpass;
  c.rounding = Rounding::Truncate;
  const std::size_t block = kBandpassSplitMin + 1000, n = 3 * block;
  const std::vector<std::int64_t> in = codes(signal(n, 0.9, 0.0, 50000, 7), c.input_bits);
  BandpassFixed split(d.filter, c), plain(d.filter, c);
  std::vector<std::int64_t> ys(n), yp(n);
  for (std::size_t i = 0; i < n; i += block) {
    split.execute_block(std::span<const std::int64_t>(in).subspan(i, block), std::span<std::int64_t>(ys).subspan(i, block));
  }
  for (std::size_t i = 0; i < n; i += kShort) {
    const std::size_t m = std::min(kShort, n - i);
    plain.execute_block(std::span<const std::int64_t>(in).subspan(i, m), std::span<std::int64_t>(yp).subspan(i, m));
  }
  EXPECT_EQ(ys, yp);
  EXPECT_EQ(split.section_outputs(), plain.section_outputs());
  if (batch::batch_kernels_available()) {
    const BandpassSplitStats st = split.split_stats();
    EXPECT_EQ(st.blocks, 2u);
    EXPECT_EQ(st.skipped, 1u);
    EXPECT_EQ(st.recomputed, 14u);
  }
}

TEST(BandpassSplit, FloatLongBlockIsThePlainLoopBitForBit) {
  // The float split's shortest block, the fixed one's, and a longer one.
  const ReceiverDesign d = default_design();
  for (std::size_t n : {kBandpassFloatSplitMin + 999, kBandpassFloatSplitMin + 4321, kBandpassSplitMin + 4321})
  for (double noise : {0.0, 0.01}) {
    const std::vector<double> x = signal(n, 0.4, noise, n - 5000, 6);
    BandpassFloat plain(d.filter), split(d.filter), aliased(d.filter);
    std::vector<double> yp(n), ys(n), ya = x;
    for (std::size_t i = 0; i < n; i += kShort) {
      const std::size_t m = std::min(kShort, n - i);
      plain.execute_block(std::span<const double>(x.data() + i, m), std::span<double>(yp.data() + i, m));
    }
    const std::size_t first = n - 999;
    split.execute_block(std::span<const double>(x.data(), first), std::span<double>(ys.data(), first));
    split.execute_block(std::span<const double>(x.data() + first, n - first), std::span<double>(ys.data() + first, n - first));
    aliased.execute_block(ya, ya);  // in place: never split (its recomputation needs the input)
    EXPECT_EQ(std::memcmp(yp.data(), ys.data(), n * sizeof(double)), 0) << "n " << n << " noise " << noise;
    EXPECT_EQ(std::memcmp(yp.data(), ya.data(), n * sizeof(double)), 0) << "n " << n << " noise " << noise;
    EXPECT_EQ(std::memcmp(plain.section_outputs().data(), split.section_outputs().data(),
                          plain.section_outputs().size() * sizeof(double)),
              0);
    EXPECT_EQ(aliased.split_stats().blocks, 0u);
    if (batch::batch_kernels_available()) {
      EXPECT_EQ(split.split_stats().blocks, 1u) << n;  // the first block only (the second is short)
      // the warm-up is long enough: every lane met the true state (else the split costs time)
      EXPECT_EQ(split.split_stats().recomputed, 0u) << "n " << n << " noise " << noise;
    }
  }
}

TEST(BandpassSplit, AFloatBlockShorterThanTheSplitsShortestRunsPlainly) {
  const ReceiverDesign d = default_design();
  const std::size_t n = kBandpassFloatSplitMin - 1;
  const std::vector<double> x = signal(n, 0.4, 0.01, n, 11);
  BandpassFloat f(d.filter);
  std::vector<double> y(n);
  f.execute_block(x, y);
  EXPECT_EQ(f.split_stats().blocks, 0u);
  f.execute_block(std::span<const double>(x.data(), n), std::span<double>(y.data(), n));
  EXPECT_EQ(f.split_stats().blocks, 0u);
}

TEST(BandpassSplit, ReceiversOnLongBlocksGiveTheShortBlocksEvents) {
  const ReceiverDesign d = default_design();
  // one long chunk (2 kBandpassSplitMin), then a shorter one (split by the float filter only)
  const std::size_t n = 2 * kBandpassSplitMin + 99999;
  static_assert(99999 >= kBandpassFloatSplitMin && 99999 < kBandpassSplitMin);
  std::vector<double> x(n, 0.0);
  std::mt19937_64 rng(8);
  std::normal_distribution<double> nz(0.0, 0.01);
  for (std::size_t at = 300; at + 5000 < n; at += 4000 + rng() % 3000) {
    const auto& t = d.templates[rng() % d.templates.size()];
    double peak = 0;
    for (double v : t) peak = std::max(peak, std::abs(v));
    for (std::size_t i = 0; i < t.size(); ++i) x[at + i] += 0.4 * t[i] / peak;
  }
  for (double& v : x) v = std::clamp(v + nz(rng), -1.0, 1.0);
  // float: events and the filtered stream
  ReceiverFloat a(d), b(d);
  std::vector<Event> ea, eb;
  std::vector<double> fa(n), fb(n);
  for (std::size_t i = 0; i < n; i += kShort) {
    const std::size_t m = std::min(kShort, n - i);
    a.execute_block(std::span<const double>(x.data() + i, m), ea, std::span<double>(fa.data() + i, m));
  }
  b.execute_block(x, eb, fb);
  ASSERT_GT(ea.size(), 100u);
  ASSERT_EQ(ea.size(), eb.size());
  for (std::size_t i = 0; i < ea.size(); ++i) {
    EXPECT_EQ(ea[i].code, eb[i].code) << i;
    EXPECT_EQ(std::memcmp(&ea[i].arrival, &eb[i].arrival, sizeof(double)), 0) << i;
    EXPECT_EQ(std::memcmp(&ea[i].score, &eb[i].score, sizeof(double)), 0) << i;
  }
  EXPECT_EQ(std::memcmp(fa.data(), fb.data(), n * sizeof(double)), 0);
  if (batch::batch_kernels_available()) {
    EXPECT_EQ(b.filter().split_stats().blocks, 2u);
    EXPECT_EQ(a.filter().split_stats().blocks, 0u);
  }
  // fixed: raw events and the overflow counts
  const std::vector<std::int64_t> q = codes(x, d.config.bandpass.input_bits);
  ReceiverFixed c(d), e(d);
  std::vector<EventFixed> ec, ee;
  for (std::size_t i = 0; i < n; i += kShort) c.execute_block(std::span<const std::int64_t>(q).subspan(i, std::min(kShort, n - i)), ec);
  e.execute_block(q, ee);
  ASSERT_GT(ec.size(), 100u);
  ASSERT_EQ(ec.size(), ee.size());
  for (std::size_t i = 0; i < ec.size(); ++i) EXPECT_EQ(ec[i], ee[i]) << i;
  EXPECT_EQ(c.overflow_events().total(), e.overflow_events().total());
  EXPECT_EQ(c.filtered(), e.filtered());
  if (batch::batch_kernels_available()) {
    EXPECT_EQ(e.filter().split_stats().blocks, 1u);
    EXPECT_EQ(c.filter().split_stats().blocks, 0u);
  }
}

TEST(BandpassSplit, AnOutOfRangeSampleInALongBlockThrowsAndChangesNoState) {
  // The split checks the input on its lanes' reads and the tail after them; whichever lane or
  // the tail holds the bad code, the block throws InputError naming it, before any state or
  // counter changes: the filter then runs on as if the block had never come.
  const ReceiverDesign d = default_design();
  const BandpassFixedConfig c = d.config.bandpass;
  const std::size_t n = kBandpassSplitMin + 3333;
  const std::vector<std::int64_t> good = codes(signal(n, 0.5, 0.01, n, 9), c.input_bits);
  const std::int64_t top = (std::int64_t{1} << (c.input_bits - 1)) - 1;
  for (std::size_t at : {std::size_t{5}, n / 2, n - 2}) {  // lane 0, a middle lane, the tail (the last 5)
    for (std::int64_t bad : {top + 1, -top - 2, std::int64_t{1} << 40}) {
      BandpassFixed f(d.filter, c), ref(d.filter, c);
      std::vector<std::int64_t> warm(5000, 0), y(n), yr(n), w(5000);
      for (std::size_t i = 0; i < warm.size(); ++i) warm[i] = good[i] / 3;
      f.execute_block(warm, w);
      ref.execute_block(warm, w);
      std::vector<std::int64_t> x = good;
      x[at] = bad;
      try {
        f.execute_block(x, y);
        ADD_FAILURE() << "no error for " << bad << " at " << at;
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(std::to_string(bad)), std::string::npos) << e.what();
      }
      EXPECT_EQ(f.section_outputs(), ref.section_outputs());
      EXPECT_EQ(f.overflow_events().total(), ref.overflow_events().total());
      f.execute_block(good, y);
      ref.execute_block(good, yr);
      EXPECT_EQ(y, yr) << "after the error at " << at;
    }
  }
}
