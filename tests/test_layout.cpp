// The pure layout functions (docs/architecture.md, "Derived constants"): each returns exactly
// what the runtime object of its stage computes with, for the default and the large
// configuration; the one ADC quantizer is what BandpassFixed::execute(double) applies; the
// excitation of a configuration carries its carrier, chip length and rate.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "model/base/error.hpp"
#include "model/config/receiver_config.hpp"
#include "model/dsp/receiver.hpp"

using namespace ranging;

namespace {

ReceiverDesign design_of(const std::string& name) {
  return design_receiver(load_receiver_config(std::string(RANGING_SOURCE_DIR) + "/configs/" + name + ".yaml"));
}

class Layout : public ::testing::TestWithParam<const char*> {};

TEST_P(Layout, BandpassLayoutIsWhatTheFilterHolds) {
  const ReceiverDesign d = design_of(GetParam());
  const BandpassFixed bp(d.filter, d.config.bandpass);
  const BandpassFixedLayout l = resolve_bandpass_layout(d.filter, d.config.bandpass);
  EXPECT_EQ(l.coefficients, bp.coefficients());
  ASSERT_EQ(l.sections(), d.filter.sections.size());
  const auto flat = l.flat();
  ASSERT_EQ(flat.size(), 5 * l.sections());
  for (std::size_t k = 0; k < l.sections(); ++k) {
    for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(flat[5 * k + i], l.coefficients[k][i]) << k << " " << i;
  }
}

TEST_P(Layout, DetectorLayoutIsWhatTheDetectorHolds) {
  const ReceiverDesign d = design_of(GetParam());
  const PeakDetectorFixed det(d.config.detector, d.layout, d.config.correlator);
  const PeakDetectorFixedLayout l = resolve_detector_layout(d.config.detector, d.layout, d.config.correlator);
  EXPECT_EQ(l.threshold_q, det.threshold_q());
  EXPECT_EQ(l.min_norm_q, det.min_norm_q());
  EXPECT_EQ(l.holdoff, det.holdoff());
  // The derivations, independently: threshold on score_bits, holdoff -1 = the energy window.
  const double want_thr = std::min(std::ldexp(1.0, d.config.correlator.score_bits) - 1,
                                   std::round(std::ldexp(d.config.detector.threshold, d.config.correlator.score_bits)));
  EXPECT_EQ(static_cast<double>(l.threshold_q), want_thr);
  EXPECT_EQ(l.holdoff, d.config.detector.holdoff == -1 ? d.layout.window : d.config.detector.holdoff);
}

INSTANTIATE_TEST_SUITE_P(Configs, Layout, ::testing::Values("default", "large"));

TEST(Layout, BandpassLayoutRefusesWhatTheFilterRefuses) {
  const ReceiverDesign d = design_of("default");
  BandpassFixedConfig c = d.config.bandpass;
  c.acc_bits = 20;  // too narrow for the default filter
  EXPECT_THROW(BandpassFixed(d.filter, c), InputError);
  EXPECT_THROW(resolve_bandpass_layout(d.filter, c), InputError);
}

TEST(Layout, DetectorLayoutRefusesAnOutOfRangeMinimumEnergy) {
  const ReceiverDesign d = design_of("default");
  DetectorConfig c = d.config.detector;
  c.min_energy = 1e30;
  EXPECT_THROW(resolve_detector_layout(c, d.layout, d.config.correlator), InputError);
}

// BandpassFixed::execute(double) quantizes with quantize_input: the same input word, the same
// saturation count, on ties, near-ties, tiny values and values far outside full scale.
TEST(AdcQuantizer, FilterInputIsQuantizeInput) {
  const ReceiverDesign d = design_of("default");
  const int bits = d.config.bandpass.input_bits;
  BandpassFixed a(d.filter, d.config.bandpass), b(d.filter, d.config.bandpass);
  std::vector<double> x;
  const double lsb = std::ldexp(1.0, -(bits - 1));
  for (int k = -2100; k <= 2100; k += 7) {
    for (double off : {0.5, 0.5 - 1e-12, 0.5 + 1e-12, -0.5, 0.0, 0.25}) x.push_back((k + off) * lsb);
  }
  for (double v : {1e-300, -1e-300, 0.999999, 1.0, 1.5, -1.0, -1.0 - lsb, 3e10, -3e10}) x.push_back(v);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1.3, 1.3);
  for (int i = 0; i < 20000; ++i) x.push_back(u(rng));
  OverflowCounter oc;
  std::size_t compared = 0;
  for (double v : x) {
    const double ya = a.execute(v);
    const std::int64_t q = quantize_input(v, bits, &oc);
    ASSERT_GE(q, -(std::int64_t{1} << (bits - 1)));
    ASSERT_LT(q, std::int64_t{1} << (bits - 1));
    // round half up: q = floor(v 2^(bits-1) + 1/2) unless saturated
    const double r = std::floor(v / lsb + 0.5);
    if (r >= -std::ldexp(1.0, bits - 1) && r < std::ldexp(1.0, bits - 1)) {
      ASSERT_EQ(static_cast<double>(q), r) << v;
    }
    const double yb = std::ldexp(static_cast<double>(b.execute_raw(q)), -d.config.bandpass.data_frac);
    ASSERT_EQ(ya, yb) << v;
    ++compared;
  }
  EXPECT_EQ(compared, x.size());
  EXPECT_EQ(a.input_overflow_events().total(), oc.total());
  EXPECT_GT(oc.total(), 0u);  // the out-of-range values above were counted
  EXPECT_THROW(quantize_input(std::numeric_limits<double>::quiet_NaN(), bits, nullptr), InputError);
}

TEST(ReceiverExcitation, CarriesTheConfiguration) {
  ReceiverConfig c;
  c.carrier_hz = 250e3;
  c.cycles_per_chip = 2;
  c.fs = 4e6;
  const ExcitationParams e = receiver_excitation(c, 0.25);
  EXPECT_EQ(e.carrier_hz, 250e3);
  EXPECT_EQ(e.cycles_per_chip, 2);
  EXPECT_EQ(e.fs, 4e6);
  EXPECT_EQ(e.amplitude, 0.25);
  EXPECT_EQ(receiver_excitation(c).amplitude, 1.0);
}

}  // namespace
