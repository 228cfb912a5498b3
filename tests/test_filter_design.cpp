// The bandpass designer against scipy.signal (tests/oracle/filter_oracle.py), the paper's
// spec, the fixed-point section structure (pairing, ordering, L-infinity scaling) and the CLI.
#include <gtest/gtest.h>

#include "tests/process.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <unistd.h>

#include "model/base/error.hpp"
#include "model/dsp/filter_design.hpp"

namespace ranging {
namespace {

constexpr FilterType kTypes[] = {FilterType::Butterworth, FilterType::Chebyshev1,
                                 FilterType::Elliptic};

using Proc = testing_support::ProcessResult;
using testing_support::run_command;

Proc run(const std::string& cmd) { return run_command(cmd); }

std::string num(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// Specs the oracle checks: the paper's, a narrower band with tighter ripple, a 2 MHz rate,
// and a wide band at a low rate (high order, poles far from the band centre).
std::vector<BandpassSpec> oracle_specs() {
  std::vector<BandpassSpec> v;
  v.push_back(BandpassSpec{});
  v.push_back(BandpassSpec{180e3, 220e3, 140e3, 260e3, 1.0, 40.0, 5e6});
  v.push_back(BandpassSpec{150e3, 250e3, 100e3, 320e3, 0.5, 45.0, 2e6});
  v.push_back(BandpassSpec{20e3, 60e3, 12e3, 75e3, 1.0, 60.0, 200e3});
  return v;
}

class Oracle : public ::testing::TestWithParam<int> {};

TEST_P(Oracle, OrdersAndResponsesMatchScipy) {
  const BandpassSpec s = oracle_specs().at(static_cast<size_t>(GetParam()));
  const std::string cmd = std::string(RANGING_PYTHON) + " " + RANGING_SOURCE_DIR +
                          "/tests/oracle/filter_oracle.py " + num(s.fp1) + " " + num(s.fp2) +
                          " " + num(s.fs1) + " " + num(s.fs2) + " " + num(s.rp_db) + " " +
                          num(s.rs_db) + " " + num(s.fs);
  const Proc r = run(cmd);
  // No scipy is a failure, not a skip: the oracle is the point of this test.
  ASSERT_EQ(r.status, 0) << cmd << "\n" << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const std::vector<double> freqs = j.at("freqs").get<std::vector<double>>();
  ASSERT_GE(freqs.size(), 200u);
  for (FilterType t : kTypes) {
    const std::string name = filter_type_name(t);
    const nlohmann::json& d = j.at("designs").at(name);
    const int order = minimum_order(s, t);
    EXPECT_EQ(order, d.at("order").get<int>()) << name;
    const std::vector<double> wn = natural_frequencies(s, t, order);
    const std::vector<double> swn = d.at("wn").get<std::vector<double>>();
    ASSERT_EQ(swn.size(), 2u);
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(wn[i], swn[i], 1e-9 * swn[i]) << name;

    const SosFilter f = design_bandpass(s, t, d.at("order").get<int>());
    const std::vector<double> re = d.at("re").get<std::vector<double>>();
    const std::vector<double> im = d.at("im").get<std::vector<double>>();
    ASSERT_EQ(re.size(), freqs.size());
    double worst = 0;
    for (size_t i = 0; i < freqs.size(); ++i) {
      const std::complex<double> hs(re[i], im[i]);
      const std::complex<double> h = sos_response(f, freqs[i]);
      const double rel = std::abs(h - hs) / std::max(std::abs(hs), 1e-3);
      worst = std::max(worst, rel);
      EXPECT_LT(rel, 1e-6) << name << " at " << freqs[i] << " Hz";
    }
    RecordProperty(name + "_order", order);
    RecordProperty(name + "_max_rel_error", num(worst));
  }
}

INSTANTIATE_TEST_SUITE_P(Specs, Oracle, ::testing::Range(0, 4));

TEST(FilterDesign, PaperButterworthIsOrderFiveWithTenPoles) {
  const SosFilter f = design_bandpass(BandpassSpec{}, FilterType::Butterworth);
  EXPECT_EQ(f.order, 5);
  EXPECT_EQ(f.sections.size(), 5u);
  EXPECT_EQ(f.fs, 5e6);
  EXPECT_EQ(f.type, FilterType::Butterworth);
}

// The designs meet the spec they were made for (sampled densely, every type, every spec).
TEST(FilterDesign, MeetsTheSpec) {
  for (const BandpassSpec& s : oracle_specs()) {
    for (FilterType t : kTypes) {
      const SosFilter f = design_bandpass(s, t);
      const std::string ctx = filter_type_name(t) + " fs=" + num(s.fs);
      constexpr int kN = 2000;
      for (int i = 0; i <= kN; ++i) {
        const double fp = s.fp1 + (s.fp2 - s.fp1) * i / kN;
        ASSERT_LE(attenuation_db(f, fp), s.rp_db + 1e-9) << ctx << " passband " << fp;
        ASSERT_GE(attenuation_db(f, fp), -1e-9) << ctx << " gain above 0 dB at " << fp;
        const double lo = s.fs1 * i / kN;
        ASSERT_GE(attenuation_db(f, lo), s.rs_db - 1e-9) << ctx << " lower stopband " << lo;
        const double hi = s.fs2 + (s.fs / 2 - s.fs2) * i / kN;
        ASSERT_GE(attenuation_db(f, hi), s.rs_db - 1e-9) << ctx << " upper stopband " << hi;
      }
    }
  }
}

// Butterworth natural frequencies put exactly rp at both passband edges; Chebyshev I and
// elliptic have their passband edges there by construction. Also at a non-minimal order.
TEST(FilterDesign, PassbandEdgesAtExactlyRp) {
  const BandpassSpec s;
  for (FilterType t : kTypes) {
    for (int order : {minimum_order(s, t), 7}) {
      const SosFilter f = design_bandpass(s, t, order);
      EXPECT_NEAR(attenuation_db(f, s.fp1), s.rp_db, 1e-7) << filter_type_name(t) << order;
      EXPECT_NEAR(attenuation_db(f, s.fp2), s.rp_db, 1e-7) << filter_type_name(t) << order;
    }
  }
  // A higher order is more selective.
  EXPECT_GT(attenuation_db(design_bandpass(s, FilterType::Butterworth, 7), s.fs2),
            attenuation_db(design_bandpass(s, FilterType::Butterworth, 5), s.fs2) + 10);
}

// Pairing, ordering and scaling leave the response of the zeros/poles/gain design intact.
TEST(FilterDesign, SectioningKeepsTheResponse) {
  for (const BandpassSpec& s : oracle_specs()) {
    for (FilterType t : kTypes) {
      for (int order : {1, 2, minimum_order(s, t), 9}) {
        const Zpk d = design_bandpass_zpk(s, t, order);
        const SosFilter f = design_bandpass(s, t, order);
        ASSERT_EQ(d.p.size(), 2u * static_cast<size_t>(order));
        ASSERT_EQ(f.sections.size(), static_cast<size_t>(order));
        for (int i = 0; i <= 500; ++i) {
          const double fr = s.fs / 2 * i / 500;
          const auto hz = zpk_response(d, fr, s.fs);
          const auto hs = sos_response(f, fr);
          ASSERT_LT(std::abs(hz - hs), 1e-9 * std::max(std::abs(hz), 1e-3))
              << filter_type_name(t) << " order " << order << " at " << fr;
        }
      }
    }
  }
}

TEST(FilterDesign, PolesInsideUnitCircleAndSectionsInAscendingRadius) {
  for (const BandpassSpec& s : oracle_specs()) {
    for (FilterType t : kTypes) {
      const SosFilter f = design_bandpass(s, t);
      double prev = 0;
      for (const Biquad& b : f.sections) {
        const double r = pole_radius(b);
        EXPECT_LT(r, 1.0) << filter_type_name(t);
        EXPECT_GE(r, prev) << filter_type_name(t) << ": highest-Q section must be last";
        prev = r;
      }
    }
  }
}

TEST(FilterDesign, PoleRadiusOfKnownSections) {
  // (1 - 0.9 e^{j w} z^-1)(1 - 0.9 e^{-j w} z^-1) and (1 - 0.5 z^-1)(1 + 0.8 z^-1)
  const double w = 0.3;
  EXPECT_NEAR(pole_radius(Biquad{1, 0, 0, -1.8 * std::cos(w), 0.81}), 0.9, 1e-15);
  EXPECT_NEAR(pole_radius(Biquad{1, 0, 0, 0.3, -0.4}), 0.8, 1e-15);
}

TEST(FilterDesign, ButterworthAndChebyshevNumeratorsAreG_0_MinusG) {
  for (const BandpassSpec& s : oracle_specs()) {
    for (FilterType t : {FilterType::Butterworth, FilterType::Chebyshev1}) {
      for (const Biquad& b : design_bandpass(s, t).sections) {
        EXPECT_EQ(b.b1, 0.0);
        EXPECT_FALSE(std::signbit(b.b1)) << "b1 must be +0 exactly";
        EXPECT_EQ(b.b2, -b.b0);
      }
    }
  }
  // Elliptic zeros sit on the unit circle: symmetric numerators (b2 = b0), or g*[1, 0, -1]
  // for the odd-order section holding the zeros at z = +1 and z = -1.
  for (const Biquad& b : design_bandpass(BandpassSpec{}, FilterType::Elliptic, 3).sections) {
    EXPECT_TRUE(b.b2 == b.b0 || (b.b1 == 0.0 && b.b2 == -b.b0));
  }
}

// Each section's conjugate zeros are the ones nearest to its poles among the unit-circle
// zeros: on the paper's elliptic design the zero angle closest to a pole angle is its own.
TEST(FilterDesign, EllipticZerosPairedWithNearestPoles) {
  const SosFilter f = design_bandpass(BandpassSpec{}, FilterType::Elliptic, 4);
  ASSERT_EQ(f.sections.size(), 4u);
  auto pole_angle = [](const Biquad& b) {
    return std::acos(std::clamp(-b.a1 / (2 * std::sqrt(b.a2)), -1.0, 1.0));
  };
  auto zero_angle = [](const Biquad& b) { return std::acos(std::clamp(-b.b1 / (2 * b.b0), -1.0, 1.0)); };
  // Highest-Q (last) section: its zeros are the nearest of all zeros to its pole.
  const Biquad& last = f.sections.back();
  double own = std::abs(zero_angle(last) - pole_angle(last));
  for (const Biquad& b : f.sections) {
    EXPECT_LE(own, std::abs(zero_angle(b) - pole_angle(last)) + 1e-12);
  }
}

// L-infinity scaling: from the input to each section's output but the last, the peak gain is
// 1 (checked on a grid unlike the designer's); the last carries the rest.
TEST(FilterDesign, IntermediateNodesPeakAtOne) {
  for (const BandpassSpec& s : oracle_specs()) {
    for (FilterType t : kTypes) {
      const SosFilter f = design_bandpass(s, t);
      constexpr int kN = 30011;
      std::vector<std::complex<double>> cum(kN + 1, 1.0);
      for (size_t k = 0; k < f.sections.size(); ++k) {
        SosFilter one = f;
        one.sections = {f.sections[k]};
        double peak = 0;
        for (int i = 0; i <= kN; ++i) {
          cum[static_cast<size_t>(i)] *= sos_response(one, s.fs / 2 * i / kN);
          peak = std::max(peak, std::abs(cum[static_cast<size_t>(i)]));
        }
        if (k + 1 < f.sections.size()) {
          EXPECT_LE(peak, 1.0 + 1e-9) << filter_type_name(t) << " section " << k + 1;
          EXPECT_GE(peak, 1.0 - 1e-4) << filter_type_name(t) << " section " << k + 1;
        } else {
          EXPECT_NEAR(peak, 1.0, 1e-3) << filter_type_name(t) << " (peak passband gain 0 dB)";
        }
      }
    }
  }
}

void expect_input_error(BandpassSpec s, const std::string& field) {
  try {
    (void)design_bandpass(s, FilterType::Butterworth);
    FAIL() << "no InputError for " << field;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(FilterDesign, InfeasibleSpecsAreRefused) {
  BandpassSpec s;
  s.fp2 = 2.5e6;  // = fs/2
  s.fs2 = 2.6e6;
  expect_input_error(s, "fs2");
  s = {};
  s.fs = 600e3;  // fs2 = 350 kHz > fs/2 = 300 kHz
  expect_input_error(s, "fs2");
  s = {};
  s.fs1 = 150e3;
  expect_input_error(s, "fs1");
  s = {};
  s.fs2 = 250e3;
  expect_input_error(s, "fp2");
  s = {};
  s.rp_db = 30;
  expect_input_error(s, "rp_db");
  s = {};
  s.rp_db = 0;
  expect_input_error(s, "rp_db");
  s = {};
  s.fp1 = std::numeric_limits<double>::quiet_NaN();
  expect_input_error(s, "fp1");
  s = {};
  s.rs_db = std::numeric_limits<double>::infinity();
  expect_input_error(s, "rs_db");
  s = {};
  s.fs = -1;
  expect_input_error(s, "fs");
  // Feasible in principle, but beyond the maximum order: refused, naming the spec.
  s = {};
  s.fs1 = 149e3;
  s.rs_db = 200;
  EXPECT_GT(minimum_order(s, FilterType::Butterworth), kMaxFilterOrder);
  expect_input_error(s, "rs_db");
  EXPECT_THROW(design_bandpass(BandpassSpec{}, FilterType::Elliptic, 0), InputError);
  EXPECT_THROW(design_bandpass(BandpassSpec{}, FilterType::Elliptic, kMaxFilterOrder + 1),
               InputError);
}

TEST(FilterDesign, TypeNames) {
  for (FilterType t : kTypes) EXPECT_EQ(parse_filter_type(filter_type_name(t)), t);
  EXPECT_EQ(filter_type_name(FilterType::Chebyshev1), "cheby1");
  EXPECT_THROW(parse_filter_type("cheby2"), InputError);
  EXPECT_THROW(parse_filter_type(""), InputError);
}

// ------------------------------------------------------------------------------- CLI
TEST(FilterCli, JsonMatchesTheDesign) {
  for (FilterType t : kTypes) {
    const Proc r = run(std::string(RANGING_TOOL) + " filter --json --type " + filter_type_name(t));
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("type"), filter_type_name(t));
    const SosFilter f = design_bandpass(BandpassSpec{}, t);
    EXPECT_EQ(j.at("order").get<int>(), f.order);
    ASSERT_TRUE(j.at("fs").is_number_integer()) << "contract: \"fs\": 5000000";
    EXPECT_EQ(j.at("fs").get<long long>(), 5000000);
    const auto& sos = j.at("sos");
    ASSERT_EQ(sos.size(), f.sections.size());
    for (size_t k = 0; k < sos.size(); ++k) {
      const Biquad& b = f.sections[k];
      const std::vector<double> row = sos[k].get<std::vector<double>>();
      ASSERT_EQ(row.size(), 6u);
      // Full-precision printing: the doubles round-trip exactly.
      EXPECT_EQ(row[0], b.b0);
      EXPECT_EQ(row[1], b.b1);
      EXPECT_EQ(row[2], b.b2);
      EXPECT_EQ(row[3], 1.0);
      EXPECT_EQ(row[4], b.a1);
      EXPECT_EQ(row[5], b.a2);
    }
    const auto& q = j.at("quantized");
    EXPECT_EQ(q.at("bits").get<int>(), 16);
    EXPECT_EQ(q.at("frac").get<int>(), 14);
    ASSERT_EQ(q.at("sections").size(), f.sections.size());
    // The integers are the coefficients to within half an LSB.
    EXPECT_LE(std::abs(q.at("sections")[0][3].get<double>() / 16384.0 - f.sections[0].a1),
              0.5 / 16384.0);
  }
}

TEST(FilterCli, OptionsReachTheDesign) {
  const Proc r = run(std::string(RANGING_TOOL) +
                    " filter --json --type cheby1 --fp1 150000 --fp2 250000 --fs1 100000 "
                    "--fs2 320000 --rp 0.5 --rs 45 --fs 2000000 --order 6");
  ASSERT_EQ(r.status, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const SosFilter f =
      design_bandpass({150e3, 250e3, 100e3, 320e3, 0.5, 45, 2e6}, FilterType::Chebyshev1, 6);
  EXPECT_EQ(j.at("order").get<int>(), 6);
  EXPECT_EQ(j.at("fs").get<long long>(), 2000000);
  ASSERT_EQ(j.at("sos").size(), 6u);
  EXPECT_EQ(j.at("sos")[5][4].get<double>(), f.sections[5].a1);
}

TEST(FilterCli, TextReport) {
  const Proc r = run(std::string(RANGING_TOOL) + " filter");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("prototype order 5 (10 poles), 5 second-order sections"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("pole radius"), std::string::npos);
  EXPECT_NE(r.out.find("quantized coefficients (16-bit signed, 14 fraction bits"),
            std::string::npos);
}

void expect_cli_error(const std::string& args, const std::string& option) {
  const Proc r = run(std::string(RANGING_TOOL) + " filter " + args);
  EXPECT_EQ(r.status, 2) << args;
  EXPECT_TRUE(r.out.empty()) << args << " printed: " << r.out;
  EXPECT_NE(r.err.find(option), std::string::npos) << args << ": " << r.err;
}

TEST(FilterCli, BadSpecsExitTwoNamingTheOption) {
  expect_cli_error("--fp2 2500000 --json", "--fp2");
  expect_cli_error("--fs1 150000", "--fs1");
  expect_cli_error("--fs2 240000", "--fs2");
  expect_cli_error("--rp 40 --rs 30", "--rp");
  expect_cli_error("--fs nan", "--fs");
  expect_cli_error("--type cheby2", "--type");
  expect_cli_error("--order 21", "--order");
  expect_cli_error("--fs1 149000 --rs 200", "--rs");
  // a1 is about -1.8: it does not fit 4 bits with 3 fraction bits ([-1, 0.875]).
  expect_cli_error("--coef-bits 4 --coef-frac 3 --json", "--coef-bits");
}

}  // namespace
}  // namespace ranging
