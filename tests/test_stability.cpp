// The guard on the quantized design (model/dsp/stability.hpp): exact poles of the integer
// quadratics (against numpy), the spec check, and every configuration path refusing an
// unstable / out-of-spec design with exit 2 unless --allow-out-of-spec.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "model/base/error.hpp"
#include "model/config/receiver_config.hpp"
#include "model/dsp/bandpass_filter.hpp"
#include "model/dsp/filter_design.hpp"
#include "model/dsp/receiver.hpp"
#include "model/dsp/stability.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"

namespace ranging {
namespace {

namespace fs = std::filesystem;
using testing_support::run_command;
using testing_support::run_tool;

// Files of every test in one directory, removed at exit.
fs::path temp_path(const std::string& name) {
  static const testing_support::ScratchDir scratch("ranging_stab");
  return scratch.path() / name;
}
fs::path write_file(const std::string& name, const std::string& text) {
  const fs::path p = temp_path(name);
  std::ofstream(p) << text;
  return p;
}

const char* const kCoef6 = "bandpass_fixed:\n  coef_bits: 6\n  coef_frac: 4\n";  // section 5: a2 = 16/16 = 1
const char* const kCoef8 = "bandpass_fixed:\n  coef_bits: 8\n  coef_frac: 6\n";  // stable, passband 4.6 dB

// ------------------------------------------------------------------ exact poles
TEST(StabilityPoles, JuryTestIsExactAtTheUnitCircle) {
  const int F = 14;
  const std::int64_t one = 1 << F;
  // Complex pair of radius exactly 1 (a2 = 1) and just inside (a2 = 1 - 2^-F).
  EXPECT_FALSE(quantized_section_poles(-31000, one, F).stable);
  EXPECT_TRUE(quantized_section_poles(-31000, one - 1, F).stable);
  EXPECT_TRUE(quantized_section_poles(-31000, one - 1, F).complex_pair);
  // A real pole exactly at z = 1: 1 + a1 + a2 = 0; at z = -1: 1 - a1 + a2 = 0.
  EXPECT_FALSE(quantized_section_poles(-(one + 100), 100, F).stable);
  EXPECT_FALSE(quantized_section_poles(one + 100, 100, F).stable);
  EXPECT_TRUE(quantized_section_poles(-(one + 99), 100, F).stable);
  EXPECT_NEAR(static_cast<double>(quantized_section_poles(-(one + 100), 100, F).radius), 1.0, 1e-15);
  // Huge words: no int128 overflow in the discriminant at frac 62.
  const SectionPoles p = quantized_section_poles(INT64_MIN, INT64_MAX, 62);
  EXPECT_FALSE(p.stable);
  EXPECT_TRUE(std::isfinite(static_cast<double>(p.radius)));
}

// The radii against numpy.roots on the same integers (an independent computation).
TEST(StabilityPoles, RadiiMatchNumpyRoots) {
  struct Case {
    std::int64_t a1, a2;
    int frac;
  };
  std::vector<Case> cases;
  for (FilterType t : {FilterType::Butterworth, FilterType::Chebyshev1, FilterType::Elliptic}) {
    const SosFilter f = design_bandpass(BandpassSpec{}, t);
    for (int bits : {6, 8, 12, 16, 24}) {
      const QuantizedSos q = quantize_sos(f, bits, bits - 2, "");
      for (const auto& c : q.sections) cases.push_back({c[3], c[4], q.frac});
    }
  }
  cases.push_back({-40000, 3000, 14});  // real poles, one outside
  cases.push_back({100, -16000, 14});   // real poles of opposite sign
  std::ostringstream py;
  py << "import numpy as np, json; c = [";
  for (const auto& c : cases) py << "(" << c.a1 << "," << c.a2 << "," << c.frac << "),";
  py << "]; print(json.dumps([float(max(abs(np.roots([2**f, a1, a2])))) for a1, a2, f in c]))";
  const fs::path script = write_file("roots.py", py.str());
  const auto r = run_command(std::string(RANGING_PYTHON) + " " + script.string());
  fs::remove(script);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto radii = nlohmann::json::parse(r.out).get<std::vector<double>>();
  ASSERT_EQ(radii.size(), cases.size());
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const SectionPoles p = quantized_section_poles(cases[i].a1, cases[i].a2, cases[i].frac);
    EXPECT_NEAR(static_cast<double>(p.radius), radii[i], 1e-9 * radii[i]) << cases[i].a1 << " " << cases[i].a2;
    EXPECT_EQ(p.stable, radii[i] < 1 - 1e-12) << cases[i].a1 << " " << cases[i].a2;
  }
}

// ------------------------------------------------------------------ the verdict
TEST(StabilityGuard, DefaultDesignPasses) {
  const DesignGuard g = check_quantized_design(ReceiverConfig{});
  EXPECT_TRUE(g.ok()) << guard_message(g, 0);
  ASSERT_EQ(g.quantized_poles.size(), 5u);
  EXPECT_LT(g.max_quantized_radius(), 0.99);
  EXPECT_LE(g.passband.quantized_db, 2.0 + g.tolerance_db);
  EXPECT_GE(g.stopband.quantized_db, 30.0 - g.tolerance_db);
  ASSERT_EQ(g.edges.size(), 4u);
  // The L1 gain per node agrees with the filter's own headroom analysis (another code path).
  const ReceiverConfig cfg;
  BandpassSpec spec = cfg.filter;
  spec.fs = cfg.fs;
  const BandpassHeadroom h = bandpass_headroom(cfg.bandpass, design_bandpass(spec, cfg.filter_type));
  ASSERT_EQ(h.signal_gain.size(), g.l1_gain.size());
  for (std::size_t k = 0; k < g.l1_gain.size(); ++k) EXPECT_NEAR(g.l1_gain[k], h.signal_gain[k], 1e-9 * h.signal_gain[k]);
}

TEST(StabilityGuard, SixBitCoefficientsPutSectionFiveOnTheUnitCircle) {
  ReceiverConfig cfg;
  cfg.bandpass.coef_bits = 6;
  cfg.bandpass.coef_frac = 4;
  const DesignGuard g = check_quantized_design(cfg);
  EXPECT_FALSE(g.stable);
  EXPECT_TRUE(g.float_within_spec);
  EXPECT_FALSE(g.quantized_poles[4].stable);
  EXPECT_TRUE(std::isinf(g.l1_gain[4]));
  const std::string m = guard_message(g, 0);
  EXPECT_NE(m.find("bandpass_fixed.coef_bits: 6"), std::string::npos) << m;
  EXPECT_NE(m.find("section 5 quantized pole radius 1.000 >= 1"), std::string::npos) << m;
  EXPECT_THROW(design_receiver(cfg), InputError);
  cfg.allow_out_of_spec = true;
  EXPECT_NO_THROW(design_receiver(cfg));
}

TEST(StabilityGuard, EightBitCoefficientsMissThePassband) {
  ReceiverConfig cfg;
  cfg.bandpass.coef_bits = 8;
  cfg.bandpass.coef_frac = 6;
  const DesignGuard g = check_quantized_design(cfg);
  EXPECT_TRUE(g.stable);
  EXPECT_FALSE(g.within_spec);
  EXPECT_GT(g.passband.quantized_db, 2.5);
  const std::string m = guard_message(g, 0);
  EXPECT_NE(m.find("passband"), std::string::npos) << m;
  EXPECT_NE(m.find("> rp_db 2 + 0.5"), std::string::npos) << m;
  try {
    design_receiver(cfg);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tolerance 0.5 dB"), std::string::npos) << e.what();
  }
}

TEST(StabilityGuard, TooLowAnOrderIsBlamedOnTheOrder) {
  ReceiverConfig cfg;
  cfg.filter_order = 2;  // minimum is 5
  const DesignGuard g = check_quantized_design(cfg);
  EXPECT_FALSE(g.float_within_spec);
  EXPECT_NE(guard_message(g, 2).find("filter.order: 2"), std::string::npos) << guard_message(g, 2);
}

TEST(StabilityGuard, ParsedConfigurationIsRefusedNamingTheFile) {
  try {
    parse_receiver_config(kCoef6, "bad.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("bad.yaml:", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("bandpass_fixed.coef_bits: 6"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(parse_receiver_config(kCoef6, "bad.yaml", {}, true).allow_out_of_spec);
}

// ------------------------------------------------------------------ every tool path
void expect_refused(const std::string& args, const std::string& what) {
  const auto r = run_tool(args);
  EXPECT_EQ(r.status, 2) << args << "\n" << r.err;
  EXPECT_TRUE(r.out.empty()) << args << " printed: " << r.out;
  EXPECT_NE(r.err.find(what), std::string::npos) << args << ": " << r.err;
}

TEST(StabilityCli, FilterRefusesUnstableAndOutOfSpecWidths) {
  expect_refused("filter --coef-bits 6", "option --coef-bits: 6 (--coef-frac 4): section 5 quantized pole radius 1.000 >= 1");
  expect_refused("filter --coef-bits 4 --json", "quantized pole radius");
  expect_refused("filter --coef-bits 8 --json", "> rp_db 2 + 0.5");
  expect_refused("filter --order 2", "option --order: 2: the unquantized design misses the spec");
}

TEST(StabilityCli, FilterAllowOutOfSpecReportsTheQuantizedDesign) {
  const auto r = run_tool("filter --coef-bits 6 --allow-out-of-spec --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j.at("guard").at("ok").get<bool>());
  EXPECT_FALSE(j.at("guard").at("stable").get<bool>());
  EXPECT_FALSE(j.at("guard").at("sections")[4].at("stable").get<bool>());
  EXPECT_GE(j.at("quantized").at("pole_radius")[4].get<double>(), 1.0);
  EXPECT_LT(j.at("pole_radius")[4].get<double>(), 1.0);  // the float design is stable
  const auto t = run_tool("filter --coef-bits 6 --allow-out-of-spec");
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_NE(t.out.find("UNSTABLE"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("REFUSED without --allow-out-of-spec"), std::string::npos) << t.out;
  // The default design: the text shows both columns and the verdict.
  const auto d = run_tool("filter");
  ASSERT_EQ(d.status, 0) << d.err;
  EXPECT_NE(d.out.find("float vs quantized"), std::string::npos);
  EXPECT_NE(d.out.find("quantized design: stable and within spec (tolerance 0.5 dB)"), std::string::npos) << d.out;
}

TEST(StabilityCli, FilterPlotWritesAPng) {
  const fs::path png = temp_path("plot.png");
  const auto r = run_tool("filter --coef-bits 8 --allow-out-of-spec --plot " + png.string());
  ASSERT_EQ(r.status, 0) << r.err;
  std::ifstream in(png, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  EXPECT_FALSE(fs::exists(png.string() + ".data.json"));
  fs::remove(png);
}

TEST(StabilityCli, GenerateAndDemoRefuseABadConfiguration) {
  const fs::path cfg = write_file("coef6.yaml", kCoef6);
  const fs::path out = temp_path("gen");
  expect_refused("generate --config " + cfg.string() + " --out " + out.string(),
                 cfg.string() + ":2: bandpass_fixed.coef_bits: 6, coef_frac: 4: section 5 quantized pole radius 1.000 >= 1");
  EXPECT_FALSE(fs::exists(out));
  expect_refused("demo --quiet --config " + cfg.string(), "bandpass_fixed.coef_bits: 6");
  const fs::path cfg8 = write_file("coef8.yaml", kCoef8);
  expect_refused("demo --quiet --config " + cfg8.string(), "passband");
  // Allowed: it runs (the unstable fixed receiver misdecodes: demo's status 1, not 2), and the
  // verdict is still on stderr.
  const auto r = run_tool("demo --quiet --allow-out-of-spec --distances 0.5 --config " + cfg.string());
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.out.find("decode errors: float 0/"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("warning: bandpass_fixed.coef_bits: 6"), std::string::npos) << r.err;
  fs::remove(cfg);
  fs::remove(cfg8);
}

TEST(StabilityCli, SimulateAndEvaluateRefuseABadReceiverInTheScene) {
  const fs::path cfg = write_file("scene_coef6.yaml", kCoef6);
  const fs::path scene = write_file("scene.yaml", "geometry:\n  distances_m: [0.5]\nreceiver:\n  config: " + cfg.string() + "\n");
  const fs::path out = temp_path("sim_out");
  expect_refused("simulate --quiet " + scene.string() + " --out " + out.string(), "bandpass_fixed.coef_bits: 6");
  EXPECT_FALSE(fs::exists(out));
  expect_refused("evaluate --quiet --no-plots " + scene.string() + " --out " + out.string(), "bandpass_fixed.coef_bits: 6");
  // Allowed: simulate runs and its JSON carries the verdict.
  const auto r = run_tool("simulate --json --allow-out-of-spec " + scene.string() + " --out " + out.string());
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j.at("design_guard").at("ok").get<bool>());
  EXPECT_NE(r.err.find("warning"), std::string::npos);
  fs::remove_all(out);
  fs::remove(cfg);
  fs::remove(scene);
}

}  // namespace
}  // namespace ranging

namespace ranging {
namespace {

// numpy's roots of the given coefficient lists (descending powers): their moduli, sorted.
std::vector<std::vector<double>> numpy_root_radii(const std::vector<std::vector<long double>>& polys) {
  std::ostringstream py;
  py.precision(21);
  py << "import numpy as np, json; P = [";
  for (const auto& p : polys) {
    py << "[";
    for (long double c : p) py << static_cast<double>(c) << ",";
    py << "],";
  }
  py << "]; print(json.dumps([sorted(abs(np.roots(p)).tolist()) for p in P]))";
  const fs::path script = write_file("roots2.py", py.str());
  const auto r = run_command(std::string(RANGING_PYTHON) + " " + script.string());
  fs::remove(script);
  EXPECT_EQ(r.status, 0) << r.err;
  return nlohmann::json::parse(r.out).get<std::vector<std::vector<double>>>();
}

std::vector<double> sorted_radii(const std::vector<std::complex<long double>>& z) {
  std::vector<double> r;
  for (const auto& v : z) r.push_back(static_cast<double>(std::abs(v)));
  std::sort(r.begin(), r.end());
  return r;
}

TEST(StabilityStructures, DirectFormRootsMatchNumpyAndTheSectionPoles) {
  std::vector<std::vector<long double>> polys;
  std::vector<SosFilter> filters;
  for (FilterType t : {FilterType::Butterworth, FilterType::Chebyshev1, FilterType::Elliptic}) {
    filters.push_back(design_bandpass(BandpassSpec{}, t));
    const DirectForm d = direct_form(filters.back());
    polys.push_back(d.a);
    // The same polynomial with 32-bit block-floating-point coefficients (frac 23 for |a| < 256).
    std::vector<long double> q = d.a;
    for (auto& c : q) c = std::round(c * std::ldexp(1.0L, 23)) * std::ldexp(1.0L, -23);
    polys.push_back(q);
  }
  const auto np = numpy_root_radii(polys);
  ASSERT_EQ(np.size(), polys.size());
  for (std::size_t i = 0; i < polys.size(); ++i) {
    const std::vector<double> ours = sorted_radii(polynomial_roots(polys[i]));
    ASSERT_EQ(ours.size(), np[i].size());
    // Clustered roots: both evaluations are limited by the conditioning, to ~1e-8 here.
    for (std::size_t k = 0; k < ours.size(); ++k) EXPECT_NEAR(ours[k], np[i][k], 1e-6) << i << " " << k;
  }
  // The expanded product's roots are the sections' poles.
  for (const SosFilter& f : filters) {
    double rmax = 0;
    for (const Biquad& b : f.sections) rmax = std::max(rmax, pole_radius(b));
    EXPECT_NEAR(sorted_radii(polynomial_roots(direct_form(f).a)).back(), rmax, 1e-8);
  }
}

TEST(StabilityStructures, DirectFormNeedsFarMoreBitsAndIsUnstableAt32) {
  const BandpassSpec spec;
  for (FilterType t : {FilterType::Butterworth, FilterType::Chebyshev1, FilterType::Elliptic}) {
    const SosFilter f = design_bandpass(spec, t);
    const int sos = minimum_coefficient_bits(f, spec, FilterStructure::Sos);
    const int direct = minimum_coefficient_bits(f, spec, FilterStructure::Direct);
    ASSERT_GT(sos, 3) << filter_type_name(t);
    EXPECT_TRUE(evaluate_structure(f, spec, FilterStructure::Sos, sos).ok());
    EXPECT_FALSE(evaluate_structure(f, spec, FilterStructure::Sos, sos - 1).ok());
    EXPECT_TRUE(evaluate_structure(f, spec, FilterStructure::Direct, direct).ok());
    EXPECT_GT(direct, sos + 8) << filter_type_name(t);
  }
  // Butterworth order 5 as one 10th-order recursion: unstable even with 32-bit coefficients.
  const StructurePoint p = evaluate_structure(design_bandpass(spec, FilterType::Butterworth), spec, FilterStructure::Direct, 32);
  EXPECT_EQ(p.frac_a, 23);
  EXPECT_FALSE(p.stable);
  EXPECT_GT(p.max_radius, 1.0);
}

TEST(StabilityStructures, TheReceiverRefusesTheDirectStructure) {
  try {
    parse_receiver_config("filter:\n  structure: direct\n", "d.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("filter.structure: 'direct' is a study structure"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_receiver_config("filter:\n  structure: lattice\n", "d.yaml"), InputError);
  EXPECT_NO_THROW(parse_receiver_config("filter:\n  structure: sos\n", "d.yaml"));
}

// ------------------------------------------------------------------ limit cycles
// docs/fixed-point.md: after settling the output is bounded by floor(noise_bound/LSB + 1/2)
// (319 LSB for the defaults) and was measured at <= 30 LSB (round-half-up). Here every
// rounding mode and excitation: the bound holds, rounding to nearest stays within 4 LSB and
// truncation within 30 LSB.
TEST(StabilityLimitCycles, TheDocumentedBoundsHoldForEveryModeAndExcitation) {
  const ReceiverConfig cfg;
  BandpassSpec spec = cfg.filter;
  spec.fs = cfg.fs;
  const SosFilter f = design_bandpass(spec, cfg.filter_type);
  for (Rounding r : {Rounding::Truncate, Rounding::RoundHalfUp, Rounding::Convergent}) {
    BandpassFixedConfig c = cfg.bandpass;
    c.rounding = r;
    const BandpassHeadroom h = bandpass_headroom(c, f);
    const double bound = std::floor(h.noise_bound.back() * std::ldexp(1.0, c.data_frac) + 0.5);
    const double measured_claim = r == Rounding::Truncate ? 30 : 4;
    BandpassFixed probe(f, c);
    for (Excitation e : {Excitation::Impulse, Excitation::Step, Excitation::WorstCase, Excitation::Random}) {
      const LimitCycle lc = measure_limit_cycle(f, c, excitation_codes(e, probe.quantized_filter(), c.input_bits, 2000));
      EXPECT_LE(lc.amplitude_lsb, bound) << excitation_name(e);
      EXPECT_LE(lc.amplitude_lsb, measured_claim) << excitation_name(e);
      EXPECT_EQ(lc.overflows, 0u);
      EXPECT_GE(lc.period, 1) << "a steady state within the window";
    }
  }
}

// An all-pole section driven past its output word: wrap sustains a near full-scale overflow
// oscillation after the input stops; saturation leaves only the granular deadband
// |y| <= LSB/2 / (1 - a2) (Jackson's bound for rounding).
TEST(StabilityLimitCycles, WrapSustainsAFullScaleOscillationAndSaturationCannot) {
  const SosFilter f = design_bandpass(BandpassSpec{}, FilterType::Butterworth);
  const Biquad& s5 = f.sections[4];
  SosFilter one = f;
  one.sections = {Biquad{1, 0, 0, s5.a1, s5.a2}};
  BandpassFixedConfig c;
  c.data_bits = 8;
  c.data_frac = 6;
  c.input_bits = 7;
  c.acc_bits = 40;
  c.overflow = Overflow::Wrap;
  BandpassFixed probe(one, c);
  const double full = static_cast<double>(fx_max_raw(probe.data_format()));
  const auto x = excitation_codes(Excitation::Impulse, probe.quantized_filter(), c.input_bits, 2000);
  const LimitCycle wrap = measure_limit_cycle(one, c, x);
  EXPECT_GE(wrap.amplitude_lsb, 0.75 * full);
  EXPECT_GT(wrap.period, 1);
  EXPECT_GT(wrap.overflows, 1000u) << "it keeps overflowing with zero input";
  c.overflow = Overflow::Saturate;
  const double a2 = static_cast<double>(probe.coefficients()[0][4]) * std::ldexp(1.0, -c.coef_frac);
  for (Excitation e : {Excitation::Impulse, Excitation::Step, Excitation::WorstCase, Excitation::Random}) {
    const LimitCycle sat = measure_limit_cycle(one, c, excitation_codes(e, probe.quantized_filter(), c.input_bits, 2000));
    EXPECT_LE(sat.amplitude_lsb, 0.5 / (1 - a2)) << excitation_name(e);
  }
}

// ------------------------------------------------------------------ ranging stability
TEST(StabilityCli, ReportOnTheDefaultShowsNoOverflowAndThePoles) {
  const auto r = run_tool("stability --quick --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j.at("guard").at("ok").get<bool>());
  ASSERT_EQ(j.at("headroom").size(), 5u);
  for (const auto& h : j.at("headroom")) {
    EXPECT_EQ(h.at("overflows").get<int>(), 0);
    EXPECT_LE(h.at("measured_peak").get<double>(), h.at("peak_bound").get<double>());
    EXPECT_GT(h.at("measured_peak").get<double>(), 0.99 * h.at("l1_gain").get<double>()) << "the worst case is reached";
    EXPECT_GT(h.at("headroom_bits").get<double>(), 0);
  }
  EXPECT_EQ(j.at("limit_cycles").size(), 24u);
  bool wrap_oscillates = false;
  for (const auto& o : j.at("overflow_oscillations")) {
    if (o.at("overflow") == "wrap" && o.at("amplitude_lsb").get<double>() > 0.5 * o.at("full_scale_lsb").get<double>()) {
      wrap_oscillates = true;
    }
    if (o.at("overflow") == "saturate") {
      EXPECT_LT(o.at("amplitude_lsb").get<double>(), 100);
    }
  }
  EXPECT_TRUE(wrap_oscillates);
}

TEST(StabilityCli, ReportStudiesAnOutOfSpecConfigurationInsteadOfRefusingIt) {
  const fs::path cfg = write_file("report6.yaml", kCoef6);
  const auto r = run_tool("stability --quick --config " + cfg.string());
  fs::remove(cfg);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("guard: FAILS: bandpass_fixed.coef_bits: 6"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("UNSTABLE"), std::string::npos);
}

// The same design made by --set on the built-in default and on a --config file: reported too.
TEST(StabilityCli, ReportStudiesAnOutOfSpecOverrideInsteadOfRefusingIt) {
  for (const std::string& base : {std::string(), " --config " + std::string(RANGING_SOURCE_DIR) + "/configs/default.yaml"}) {
    const auto r = run_tool("stability --quick" + base + " --set bandpass_fixed.coef_bits=6 --set bandpass_fixed.coef_frac=4");
    ASSERT_EQ(r.status, 0) << base << ": " << r.err;
    EXPECT_NE(r.out.find("guard: FAILS: bandpass_fixed.coef_bits: 6"), std::string::npos) << r.out;
  }
}

}  // namespace
}  // namespace ranging
