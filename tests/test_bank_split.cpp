// The correlator bank's time split (CorrelatorBankFixed::feed_split): a long block runs as 8
// segments on the SIMD lanes, each warm-up lane started from reset split_memory() samples
// before its segment. Whatever the data, the phase the block starts at and the configuration,
// it must give the plain feed() loop's decimated outputs (Q_j, n, norm), overflow counts per
// node and final state (every stage accessor, then the outputs of the samples after it), bit
// for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "model/dsp/quantize.hpp"
#include "model/dsp/receiver.hpp"
#include "model/dsp/receiver_batch_kernels.hpp"

using namespace ranging;

namespace {

struct Output {
  std::vector<std::uint64_t> q;
  std::int64_t n;
  std::uint64_t norm;
  bool operator==(const Output&) const = default;
};

// Bank inputs (signed data_bits): tone bursts of code-like phase flips at `amp` of full scale
// on noise; amp near 1 drives the chip and corr words into saturation.
std::vector<std::int64_t> bank_input(std::size_t n, int data_bits, double amp, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nz(0.0, 0.02);
  const double top = static_cast<double>((std::int64_t{1} << (data_bits - 1)) - 1);
  std::vector<std::int64_t> y(n);
  double sign = 1;
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 100 == 0 && rng() % 2) sign = -sign;
    const bool on = (i / 3000) % 2 == 0;
    double v = (on ? amp * sign * std::sin(2 * M_PI * 0.04 * static_cast<double>(i)) : 0.0) + nz(rng);
    v = std::max(-1.0, std::min(1.0, v));
    y[i] = static_cast<std::int64_t>(std::lround(v * top));
  }
  return y;
}

void collect(const CorrelatorBankFixed& b, std::vector<Output>& out) {
  out.push_back({b.weighted_power(), b.sample_index(), b.norm()});
}

// The plain run: prefix, block and tail through feed(), every output collected.
// The split run: prefix through feed(), the block through feed_split, the tail through execute().
void expect_split_exact(const ReceiverDesign& d, const std::vector<std::int64_t>& y, std::size_t prefix,
                        std::size_t block, const std::string& what, bool expect_saturation, std::size_t pieces = 1) {
  CorrelatorBankFixed plain(d.reference, d.config.correlator), split(d.reference, d.config.correlator);
  std::vector<Output> op, os;
  for (std::span<const std::int64_t> rest(y); !rest.empty();) {
    rest = rest.subspan(plain.feed(rest));
    if (plain.output_ready()) collect(plain, op);
  }
  const std::span<const std::int64_t> all(y);
  for (std::span<const std::int64_t> rest = all.first(prefix); !rest.empty();) {
    rest = rest.subspan(split.feed(rest));
    if (split.output_ready()) collect(split, os);
  }
  ASSERT_GE(block, split.split_min_samples()) << what;
  std::size_t prev_diff = 0;  // prev handed over: the output before (the bank's last before the block)
  const std::vector<std::uint64_t> before = split.weighted_power();
  const bool took = split.feed_split(all.subspan(prefix, block), [&](std::span<const std::uint64_t> q,
                                                                       std::span<const std::uint64_t> prev,
                                                                       std::int64_t n, std::uint64_t norm) {
    const std::vector<std::uint64_t>& want = os.empty() ? before : os.back().q;
    prev_diff += !std::equal(prev.begin(), prev.end(), want.begin(), want.end());
    os.push_back({std::vector<std::uint64_t>(q.begin(), q.end()), n, norm});
  });
  EXPECT_EQ(prev_diff, 0u) << what << ": the previous outputs handed over differ";
  EXPECT_EQ(took, batch::batch_kernels_available()) << what;
  if (!took) {  // no SIMD kernels here: the plain loop (the comparison still holds)
    for (std::span<const std::int64_t> rest = all.subspan(prefix, block); !rest.empty();) {
      rest = rest.subspan(split.feed(rest));
      if (split.output_ready()) collect(split, os);
    }
  }
  // The state right after the block: every stage accessor.
  {
    CorrelatorBankFixed at(d.reference, d.config.correlator);
    for (std::span<const std::int64_t> rest = all.first(prefix + block); !rest.empty();) rest = rest.subspan(at.feed(rest));
    EXPECT_EQ(split.sample_index(), at.sample_index()) << what;
    EXPECT_EQ(split.output_ready(), at.output_ready()) << what;
    EXPECT_EQ(split.mix_re(), at.mix_re()) << what;
    EXPECT_EQ(split.mix_im(), at.mix_im()) << what;
    EXPECT_EQ(split.dec_re(), at.dec_re()) << what;
    EXPECT_EQ(split.dec_im(), at.dec_im()) << what;
    EXPECT_EQ(split.chip_re(), at.chip_re()) << what;
    EXPECT_EQ(split.chip_acc_im(), at.chip_acc_im()) << what;
    EXPECT_EQ(split.comb_re(), at.comb_re()) << what;
    EXPECT_EQ(split.corr_im(), at.corr_im()) << what;
    EXPECT_EQ(split.power(), at.power()) << what;
    EXPECT_EQ(split.weighted_power(), at.weighted_power()) << what;
    EXPECT_EQ(split.energy(), at.energy()) << what;
  }
  for (std::size_t i = prefix + block; i < y.size(); ++i) {
    if (split.execute(y[i])) collect(split, os);
  }
  ASSERT_EQ(op.size(), os.size()) << what;
  std::size_t diff = 0;
  for (std::size_t i = 0; i < op.size(); ++i) diff += !(op[i] == os[i]);
  EXPECT_EQ(diff, 0u) << what << ": outputs differ";
  for (auto node : {&CorrelatorBankFixed::mix_overflow_events, &CorrelatorBankFixed::chip_overflow_events,
                    &CorrelatorBankFixed::corr_overflow_events}) {
    EXPECT_EQ((plain.*node)().saturations, (split.*node)().saturations) << what;
    EXPECT_EQ((plain.*node)().wraps, (split.*node)().wraps) << what;
  }
  if (expect_saturation) {
    EXPECT_GT(plain.overflow_events().total(), 0u) << what << ": nothing saturated";
  }
  EXPECT_EQ(split.split_blocks(), took ? pieces : 0u) << what;
  std::printf("[ bank split ] %s: H = %zu, %zu outputs, %llu saturations\n", what.c_str(), split.split_memory(),
              op.size(), static_cast<unsigned long long>(plain.overflow_events().total()));
}

ReceiverDesign design(const std::string& family, int decimation, int corr_shift = -1) {
  ReceiverConfig cfg;
  cfg.family = family;
  cfg.decimation = decimation;
  cfg.correlator.corr_shift = corr_shift;
  fit_decimation_to_chip(cfg);
  return design_receiver(cfg);
}

}  // namespace

TEST(BankSplit, LongBlockIsThePlainFeedLoopBitForBit) {
  // The default design (P = 25, D = 20: lcm 100), starting at phases that are not a multiple
  // of lcm(P, D), and a block length that leaves a tail after the last segment.
  const ReceiverDesign d = design("Gold4", 20);
  CorrelatorBankFixed probe(d.reference, d.config.correlator);
  const std::size_t block = probe.split_min_samples() + 12345;
  for (std::size_t prefix : {std::size_t{0}, std::size_t{1237}, std::size_t{40013}}) {
    const std::vector<std::int64_t> y = bank_input(prefix + block + 5003, d.config.bandpass.data_bits, 0.5, 1 + prefix);
    expect_split_exact(d, y, prefix, block, "Gold4 D=20 prefix " + std::to_string(prefix), false);
  }
}

TEST(BankSplit, OtherPeriodsDecimationsAndCodeLengths) {
  // D = 5 (lcm(25, 5) = 25), D = 10 on a longer family (31 shifts of a 31-chip M-sequence: a longer
  // memory), and D = 4 (lcm(25, 4) = 100, the phases of the LO and the decimator differ).
  for (auto [family, dec] : {std::pair{"Gold4", 5}, std::pair{"mseq-5", 10}, std::pair{"Gold4", 4}}) {
    const ReceiverDesign d = design(family, dec);
    CorrelatorBankFixed probe(d.reference, d.config.correlator);
    const std::size_t block = probe.split_min_samples() + 999;
    const std::vector<std::int64_t> y = bank_input(block + 3333, d.config.bandpass.data_bits, 0.5, 7);
    expect_split_exact(d, y, 333, block, std::string(family) + " D=" + std::to_string(dec), false);
  }
}

TEST(BankSplit, SaturationsAreCountedPerLaneOnlyOnceEach) {
  // The combiner's output barely scaled (corr_shift 2, not the automatic one) and loud input:
  // C_q saturates, in the warm-ups too (whose counts must not be taken) and in the re-run
  // before the tail (not counted twice).
  const ReceiverDesign d = design("Gold4", 20, 2);
  CorrelatorBankFixed probe(d.reference, d.config.correlator);
  const std::size_t block = probe.split_min_samples() + 4567;
  const std::vector<std::int64_t> y = bank_input(block + 2000, d.config.bandpass.data_bits, 1.0, 3);
  expect_split_exact(d, y, 77, block, "saturating", true);
}

TEST(BankSplit, ABlockLongerThanTheOutputBufferIsSplitPieceByPiece) {
  // 31 codes at D = 4: the lanes' buffered outputs would pass 32 MiB on a block of about 0.5 M
  // samples, so it goes in pieces (two of split_max_samples() or less, the last at least
  // split_min_samples()), each with its own warm-ups: still the plain loop, bit for bit.
  const ReceiverDesign d = design("mseq-5", 4);
  CorrelatorBankFixed probe(d.reference, d.config.correlator);
  const std::size_t hi = probe.split_max_samples(), lo = probe.split_min_samples();
  ASSERT_GE(hi, 2 * lo);
  const std::size_t block = 2 * hi + 12345;  // hi, then hi + 12345 - lo, then lo
  const std::vector<std::int64_t> y = bank_input(block + 1000, d.config.bandpass.data_bits, 0.5, 11);
  expect_split_exact(d, y, 500, block, "mseq-5 D=4 in pieces", false, 3);
}

// ReceiverFixed hands the split's outputs to the detector with the previous output's Q_j; the
// per-sample calls after a split block must find the detector where a per-sample run leaves it.
// A burst's detection against block boundaries around its correlation peak.
TEST(BankSplit, PerSampleCallsAfterASplitBlockGiveThePerSampleEvents) {
  const ReceiverDesign d = design("Gold4", 20);
  CorrelatorBankFixed probe(d.reference, d.config.correlator);
  const std::size_t at0 = probe.split_min_samples() + 2000;  // the burst's start
  const auto& t = d.templates[4];
  double peak = 0;
  for (double v : t) peak = std::max(peak, std::abs(v));
  std::mt19937_64 rng(5);
  std::normal_distribution<double> nz(0.0, 0.01);
  std::vector<std::int64_t> x(at0 + t.size() + 3000);
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double v = (i >= at0 && i < at0 + t.size() ? 0.4 * t[i - at0] / peak : 0.0) + nz(rng);
    x[i] = quantize_input(v, d.config.bandpass.input_bits, nullptr);
  }
  auto run = [&](std::size_t b) {
    ReceiverFixed rx(d);
    std::vector<EventFixed> ev;
    rx.execute_block(std::span<const std::int64_t>(x.data(), b), ev);
    for (std::size_t i = b; i < x.size(); ++i) {
      if (auto e = rx.execute_raw(x[i])) ev.push_back(*e);
    }
    if (auto e = rx.flush_raw()) ev.push_back(*e);
    return ev;
  };
  const std::vector<EventFixed> ref = run(0);
  ASSERT_EQ(ref.size(), 1u);
  EXPECT_EQ(ref[0].code, 5);
  const auto at = static_cast<std::size_t>(ref[0].arrival >> d.config.detector.frac_bits);
  ASSERT_GT(at, probe.split_min_samples() + 200);
  std::size_t diff = 0;
  for (std::size_t b = at - 120; b <= at + 120; ++b) diff += run(b) != ref;
  EXPECT_EQ(diff, 0u);
}
