// Overflow headroom of the correlator bank (model/dsp/correlator_headroom.hpp, issue 12 §4):
// the bounds hold for every input, the worst-case sign sequences attain them, exact nodes never
// overflow, and a saturating node driven past its word counts its saturations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "model/base/error.hpp"
#include "model/dsp/correlator_headroom.hpp"
#include "model/dsp/receiver.hpp"

using namespace ranging;

namespace {

ReceiverDesign design(const char* family) {
  ReceiverConfig cfg;
  cfg.family = family;
  return design_receiver(cfg);
}

const BankNodeHeadroom& node(const std::vector<BankNodeHeadroom>& h, BankNode n) {
  return *std::find_if(h.begin(), h.end(), [n](const BankNodeHeadroom& x) { return x.node == n; });
}

}  // namespace

TEST(CorrelatorHeadroom, ExactNodesNeverOverflowAndEveryBoundHolds) {
  for (const char* fam : {"Gold4", "M1"}) {
    const ReceiverDesign d = design(fam);
    const auto h = correlator_headroom(d.reference, d.config.correlator);
    ASSERT_EQ(h.size(), 9u);
    for (const auto& n : h) {
      SCOPED_TRACE(std::string(fam) + " " + n.name);
      EXPECT_LE(n.measured, n.bound) << "a bound that an input exceeds is no bound";
      EXPECT_GT(n.measured, 0.0);
      if (n.exact) {
        EXPECT_GE(n.headroom_bits, 0.0);
        EXPECT_EQ(n.overflows, 0u);
        EXPECT_LE(n.measured, n.limit);
      }
      if (!n.exact && n.headroom_bits < 0) {
        EXPECT_GT(n.overflows, 0u) << "a worst case past the word must saturate, counted";
      }
    }
  }
}

TEST(CorrelatorHeadroom, WorstCaseSequencesAttainTheLinearBounds) {
  // The sign sequence is the worst input of a linear node: its peak reaches the L1 bound up
  // to the rounding terms (within 1 %).
  const ReceiverDesign d = design("Gold4");
  const auto h = correlator_headroom(d.reference, d.config.correlator);
  for (BankNode n : {BankNode::Mixer, BankNode::Decimator, BankNode::ChipFir, BankNode::Energy}) {
    const auto& x = node(h, n);
    EXPECT_GT(x.measured, 0.99 * x.bound) << x.name;
  }
  // The combiner's worst case is L chips of F at once: above the 6 dB-below-top template peak
  // the layout aims for, so the saturating corr word is where the worst case shows.
  const auto& c = node(h, BankNode::Combiner);
  EXPECT_GT(c.measured, 0.9 * c.bound) << c.name;
}

TEST(CorrelatorHeadroom, RandomFullScaleInputStaysBelowTheWorstCase) {
  // Independent of the derivation: 20 000 samples of random full-scale +-1 input never drive
  // the chip filter accumulator or the combiner above what the worst-case sequences gave.
  const ReceiverDesign d = design("Gold4");
  const auto& cfg = d.config.correlator;
  const auto h = correlator_headroom(d.reference, cfg);
  CorrelatorBankFixed bank(d.reference, cfg);
  std::mt19937_64 rng(5);
  const std::int64_t top = (std::int64_t{1} << (cfg.data_bits - 1)) - 1;
  double f = 0, c = 0;
  for (int i = 0; i < 20000; ++i) {
    if (!bank.execute((rng() & 1) ? top : -top - 1)) continue;
    f = std::max({f, std::abs(static_cast<double>(bank.chip_acc_re())), std::abs(static_cast<double>(bank.chip_acc_im()))});
    for (std::size_t j = 0; j < bank.comb_re().size(); ++j) {
      c = std::max({c, std::abs(static_cast<double>(bank.comb_re()[j])), std::abs(static_cast<double>(bank.comb_im()[j]))});
    }
  }
  EXPECT_LE(f, node(h, BankNode::ChipFir).measured);
  EXPECT_LE(c, node(h, BankNode::Combiner).measured);
  EXPECT_GT(f, 0.0);
}

TEST(CorrelatorHeadroom, CorrShiftZeroDrivesTheCorrWordIntoCountedSaturation) {
  ReceiverConfig cfg;
  cfg.family = "Gold4";
  const ReceiverDesign d = design_receiver(cfg);
  CorrelatorFixedConfig c = d.config.correlator;
  c.corr_shift = 0;
  const auto h = correlator_headroom(d.reference, c);
  const auto& q = node(h, BankNode::CorrQ);
  EXPECT_LT(q.headroom_bits, 0.0);
  EXPECT_GT(q.overflows, 0u);
  EXPECT_DOUBLE_EQ(q.measured, q.limit) << "a saturated word sits at its rail";
  EXPECT_EQ(node(h, BankNode::Combiner).overflows, 0u) << "the exact combiner still holds its bound";
}

TEST(CorrelatorHeadroom, WorstCaseRefusesNodesWithoutALinearWorstCase) {
  const ReceiverDesign d = design("Gold4");
  EXPECT_THROW(correlator_worst_case(d.reference, d.config.correlator, BankNode::Power, 0, false, false), InputError);
  EXPECT_THROW(correlator_worst_case(d.reference, d.config.correlator, BankNode::CorrQ, 99, false, false), InputError);
  const auto y = correlator_worst_case(d.reference, d.config.correlator, BankNode::CorrQ, 3, true, false);
  EXPECT_EQ(y.size() % static_cast<std::size_t>(d.layout.decimation), 0u) << "ends on a decimated output";
}
