// CorrelatorBankFloat::feed_outputs: the chip filter and the combiner of a run of outputs
// computed across the outputs (one per SIMD lane). Every output handed over (Q_j, its sample
// index, its energy) and every accessor after each block must be the per-sample feed loop's,
// bit for bit, on designs with other periods, decimations and code lengths, for blocks shorter
// than one output, ending mid-decimation, and longer than a run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "model/dsp/receiver.hpp"

using namespace ranging;

namespace {

struct Output {
  std::vector<double> q;
  std::int64_t n;
  double energy;
};

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

// Code-like bursts (phase flips every 100 samples) of a 200 kHz tone on noise, silence between.
std::vector<double> bank_input(std::size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> nz(0.0, 0.05);
  std::vector<double> y(n);
  double sign = 1;
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 100 == 0 && rng() % 2) sign = -sign;
    const bool on = (i / 3000) % 3 != 2;
    y[i] = (on ? 0.6 * sign * std::sin(2 * M_PI * 0.04 * static_cast<double>(i)) : 0.0) + (on ? nz(rng) : 0.0);
  }
  return y;
}

ReceiverDesign design(const std::string& family, int decimation) {
  ReceiverConfig cfg;
  cfg.family = family;
  cfg.decimation = decimation;
  fit_decimation_to_chip(cfg);
  return design_receiver(cfg);
}

void expect_runs_exact(const ReceiverDesign& d, const std::string& what) {
  const std::vector<double> y = bank_input(40000, 3);
  CorrelatorBankFloat plain(d.reference), runs(d.reference);
  std::vector<Output> po, ro;
  const std::size_t blocks[] = {1, 3, 1279, 0, 1280, 1281, 5000, 20, 7, 6400, 333};
  std::size_t acc_diff = 0, prev_diff = 0, b = 0;
  for (std::size_t i = 0; i < y.size(); ++b) {
    const std::size_t m = std::min(blocks[b % std::size(blocks)], y.size() - i);
    const std::span<const double> blk(y.data() + i, m);
    for (std::span<const double> rest = blk; !rest.empty();) {
      rest = rest.subspan(plain.feed(rest));
      if (plain.output_ready()) po.push_back({plain.weighted_power(), plain.sample_index(), plain.energy()});
    }
    runs.feed_outputs(blk, [&](std::span<const double> q, std::span<const double> prev, std::int64_t n, double e) {
      // prev: the output before (zeros before the first)
      const std::vector<double> want = ro.empty() ? std::vector<double>(q.size(), 0.0) : ro.back().q;
      prev_diff += !same_bits(want, std::vector<double>(prev.begin(), prev.end()));
      ro.push_back({std::vector<double>(q.begin(), q.end()), n, e});
    });
    acc_diff += !same_bits(plain.weighted_power(), runs.weighted_power());
    acc_diff += !same_bits(plain.energy(), runs.energy()) || plain.output_ready() != runs.output_ready();
    acc_diff += plain.sample_index() != runs.sample_index();
    acc_diff += !same_bits(plain.chip_magnitude(), runs.chip_magnitude());
    acc_diff += !same_bits(plain.max_corr_magnitude(), runs.max_corr_magnitude());
    i += m;
  }
  ASSERT_EQ(po.size(), ro.size()) << what;
  EXPECT_GT(po.size(), 40000u / static_cast<std::size_t>(d.reference.decimation) - 2) << what;
  std::size_t diff = 0;
  for (std::size_t k = 0; k < po.size(); ++k) {
    diff += !same_bits(po[k].q, ro[k].q) || po[k].n != ro[k].n || !same_bits(po[k].energy, ro[k].energy);
  }
  EXPECT_EQ(diff, 0u) << what << ": outputs differ";
  EXPECT_EQ(acc_diff, 0u) << what << ": accessors after a block differ";
  EXPECT_EQ(prev_diff, 0u) << what << ": the previous outputs handed over differ";
  // and the state: the same continuation
  std::vector<double> tail(y.begin(), y.begin() + 2000);
  for (double v : tail) {
    const bool a = plain.execute(v), r = runs.execute(v);
    ASSERT_EQ(a, r) << what;
    if (a) {
      ASSERT_TRUE(same_bits(plain.weighted_power(), runs.weighted_power())) << what;
    }
  }
}

}  // namespace

TEST(BankFloatRun, OutputsAndStateAreTheFeedLoopsBitForBit) {
  for (auto [family, dec] : {std::pair{"Gold4", 20}, std::pair{"Gold4", 5}, std::pair{"mseq-5", 10}, std::pair{"Gold4", 4}}) {
    expect_runs_exact(design(family, dec), std::string(family) + " D=" + std::to_string(dec));
  }
}

// ReceiverFloat::execute_block hands the bank's outputs to the detector with the previous
// output's Q_j; per-sample execute() after a block must find the detector where a per-sample
// run leaves it. A burst's detection against block boundaries around its correlation peak.
TEST(BankFloatRun, PerSampleCallsAfterABlockGiveThePerSampleEvents) {
  const ReceiverDesign d = design("Gold4", 20);
  const auto& t = d.templates[2];
  double peak = 0;
  for (double v : t) peak = std::max(peak, std::abs(v));
  std::vector<double> x(t.size() + 3000, 0.0);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> nz(0.0, 0.01);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = (i >= 500 && i < 500 + t.size() ? 0.4 * t[i - 500] / peak : 0.0) + nz(rng);
  auto run = [&](std::size_t b) {
    ReceiverFloat rx(d);
    std::vector<Event> ev;
    rx.execute_block(std::span<const double>(x.data(), b), ev);
    for (std::size_t i = b; i < x.size(); ++i) {
      if (auto e = rx.execute(x[i])) ev.push_back(*e);
    }
    if (auto e = rx.flush()) ev.push_back(*e);
    return ev;
  };
  const std::vector<Event> ref = run(0);
  ASSERT_EQ(ref.size(), 1u);
  EXPECT_EQ(ref[0].code, 3);
  const auto at = static_cast<std::size_t>(ref[0].arrival);
  std::size_t diff = 0;
  for (std::size_t b = at - 120; b <= at + 120; ++b) {
    const std::vector<Event> ev = run(b);
    diff += ev.size() != 1 || ev[0].code != ref[0].code || !same_bits(ev[0].arrival, ref[0].arrival) ||
            !same_bits(ev[0].score, ref[0].score) || !same_bits(ev[0].margin, ref[0].margin);
  }
  EXPECT_EQ(diff, 0u);
}
