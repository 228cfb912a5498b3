// The extremes of the scene (issue 12 section 5) and sound-velocity compensation (issue 14
// section 6, model part). Every test states the outcome it expects; none copies a number from
// the code's own output.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "model/base/error.hpp"
#include "model/sim/medium.hpp"
#include "model/sim/metrics.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"
#include "process.hpp"
#include "scratch.hpp"

using namespace ranging;

namespace {

struct Result {
  std::vector<Measurement> rows;
  FamilySummary sum;
};

Result run(const std::string& yaml, const std::string& family = "Gold4") {
  SceneSimulator sim(parse_scene(yaml, "s.yaml"));
  std::size_t fa = 0;
  Result r;
  r.rows = sim.run(family, {}, {}, &fa);
  r.sum = summarize(sim.scene(), family, r.rows, fa);
  return r;
}

const std::string kAdc = "noise:\n  noise_v: 0.001\n  adc:\n    bits: 12\n    full_scale_v: 1.0\n";

}  // namespace

// 0.02 m: the received burst (25 V drive x 0.02 V/V at 0.1 m, x 5 at 0.02 m = 2.5 V) exceeds the
// ADC's +-1 V: every measurement there is counted as clipped; at 0.5 m (0.1 V) none is.
TEST(SceneExtremes, AdcClippingAtTwoCentimetresIsCounted) {
  const auto r = run("transducers: {}\ngeometry:\n  distances_m: [0.02, 0.5]\nexcitation:\n  family: Gold4\n"
                     "  codes: [1, 2]\n" + kAdc);
  ASSERT_EQ(r.rows.size(), 4u);
  for (const auto& m : r.rows) {
    if (m.true_distance_m < 0.05) {
      EXPECT_GT(m.adc_clipped, 10u) << "code " << m.code_sent;
    } else {
      EXPECT_EQ(m.adc_clipped, 0u) << "code " << m.code_sent;
    }
  }
  EXPECT_EQ(r.sum.clipped_measurements, 2u);
  EXPECT_GT(r.sum.clipped_samples, 20u);
  EXPECT_GE(r.sum.clipped_samples, r.sum.clipped_max);
}

// Without an ADC stage the fixed receiver clamps its input to +-receiver.full_scale_v: counted the same way.
TEST(SceneExtremes, FixedReceiverInputClampIsCountedWithoutAdc) {
  const auto r = run("transducers: {}\ngeometry:\n  distances_m: [0.02]\nexcitation:\n  family: Gold4\n  codes: [3]\n"
                     "receiver:\n  precision: fixed\n");
  ASSERT_EQ(r.rows.size(), 1u);
  EXPECT_GT(r.rows[0].adc_clipped, 10u);
  // The float receiver has no clamp: nothing to count.
  const auto f = run("transducers: {}\ngeometry:\n  distances_m: [0.02]\nexcitation:\n  family: Gold4\n  codes: [3]\n");
  EXPECT_EQ(f.rows[0].adc_clipped, 0u);
}

// eq. 3: a periodic train whose distances reach eta*c*T. Gold4 (eta 9) every T = 1/(9*340) s:
// eta*c*T = 1.0 m. A train of 27 bursts: at 1.05 m the first 18 bursts arrive after the next send
// of their own code and alias to 0.05 m; they must be counted as range-ambiguous errors, and a
// summary with aliased distances never reads "errors 0".
TEST(SceneExtremes, RangeAmbiguityIsAnErrorAndWarned) {
  const std::string yaml = "transducers: {}\ngeometry:\n  distances_m: [0.5, 1.05]\nexcitation:\n  family: Gold4\n"
                           "  schedule:\n    mode: periodic\n    period_s: 0.000326797385620915\n    bursts: 27\n";
  const Scene scene = parse_scene(yaml, "s.yaml");
  ASSERT_EQ(scene.warnings.size(), 1u);
  EXPECT_NE(scene.warnings[0].find("unambiguous range"), std::string::npos) << scene.warnings[0];
  EXPECT_NEAR(scene.unambiguous_range_m(9), 1.0, 1e-9);
  const auto r = run(yaml);
  ASSERT_EQ(r.rows.size(), 54u);
  std::size_t aliased = 0;
  for (const auto& m : r.rows) {
    ASSERT_TRUE(m.detected);
    if (m.true_distance_m < 1.0) {
      EXPECT_FALSE(m.range_ambiguous);
      EXPECT_NEAR(m.error_m, 0.0, 2e-3);
    } else if (m.burst < 18) {
      EXPECT_TRUE(m.range_ambiguous) << "burst " << m.burst << " error " << m.error_m;
      EXPECT_NEAR(m.error_m, -1.0, 2e-3);  // aliased by exactly eta*c*T
      aliased += m.range_ambiguous;
    } else {
      EXPECT_FALSE(m.range_ambiguous) << "burst " << m.burst;  // no later send of its code
      EXPECT_NEAR(m.error_m, 0.0, 2e-3);
    }
  }
  EXPECT_EQ(aliased, 18u);
  EXPECT_EQ(r.sum.range_ambiguous, 18u);
  EXPECT_GE(r.sum.decode_errors, 18u);
  // The RMSE left (aliased distances out) is that of correct measurements; with them it would be
  // hundreds of mm, and then the errors are not 0.
  EXPECT_LT(r.sum.rmse_m, 2e-3);
  EXPECT_GT(r.sum.distance_rmse_with_ambiguous_m, 0.3);
  EXPECT_GT(r.sum.decode_errors, 0u);
}

// Exactly at eta*c*T the arrival coincides with the next send of its code: each measurement is
// either right (within 2 mm) or counted as range-ambiguous, never a quiet 1 m error.
TEST(SceneExtremes, AtTheUnambiguousRangeEveryAliasIsCounted) {
  const std::string yaml = "transducers: {}\ngeometry:\n  distances_m: [1.0]\nexcitation:\n  family: Gold4\n"
                           "  schedule:\n    mode: periodic\n    period_s: 0.000326797385620915\n    bursts: 18\n";
  EXPECT_EQ(parse_scene(yaml, "s.yaml").warnings.size(), 1u);
  const auto r = run(yaml);
  for (const auto& m : r.rows) {
    if (!m.detected) continue;
    EXPECT_TRUE(m.range_ambiguous || std::abs(m.error_m) < 2e-3) << "burst " << m.burst << " error " << m.error_m;
  }
  if (r.sum.distance_rmse_with_ambiguous_m > 0.1) {
    EXPECT_GT(r.sum.decode_errors, 0u);
  }
  // Below the unambiguous range: no warning.
  EXPECT_TRUE(parse_scene("geometry:\n  distances_m: [0.99]\nexcitation:\n  family: Gold4\n"
                          "  schedule:\n    mode: periodic\n    period_s: 0.000326797385620915\n",
                          "s.yaml")
                  .warnings.empty());
}

// 2 m to 5 m with air absorption (ISO 9613-1, about 6 dB/m at 200 kHz) and a fixed noise floor
// the amplitude falls by > 25 dB: misses are counted and never fewer at 5 m than at 2 m;
// at 2 m every burst decodes.
TEST(SceneExtremes, AttenuationFromTwoToFiveMetresCountsMisses) {
  const auto r = run("transducers: {}\nmedium:\n  temperature_c: 20\ngeometry:\n  distances_m: [2, 5]\n"
                     "excitation:\n  family: Gold4\n  codes: [1, 2, 3, 4]\n"
                     "noise:\n  noise_v: 0.004\n  adc:\n    bits: 12\n    full_scale_v: 1.0\n");
  std::size_t miss2 = 0, miss5 = 0, bad2 = 0;
  for (const auto& m : r.rows) {
    const bool bad = !m.detected || m.det.code != m.code_sent;
    if (m.true_distance_m < 3) {
      miss2 += !m.detected;
      bad2 += bad;
    } else {
      miss5 += !m.detected;
    }
  }
  EXPECT_EQ(bad2, 0u);
  EXPECT_GE(miss5, miss2);
  EXPECT_GT(miss5, 0u);
  EXPECT_EQ(r.sum.missed, miss2 + miss5);
  EXPECT_GE(r.sum.decode_errors, r.sum.missed);
}

// SNR +40 dB: no error, ToF spread < 0.1 us; -12 dB: errors > 0 and a larger ToF spread of the
// bursts still decoded right (curves: scripts/snr_curve.py, docs/results/stability-extremes.md).
TEST(SceneExtremes, SnrFromPlusFortyToMinusTwelve) {
  auto at = [](double snr) {
    return run("transducers: {}\ngeometry:\n  distances_m: [0.5]\n  repeats: 4\nexcitation:\n  family: Gold4\n"
               "  codes: [1, 2, 3]\nnoise:\n  snr_db: " + std::to_string(snr) + "\n  seed: 3\n");
  };
  auto spread = [](const std::vector<Measurement>& rows) {
    double m = 0, m2 = 0, n = 0;
    for (const auto& r : rows) {
      if (!r.detected || r.det.code != r.code_sent) continue;
      m += r.det.tof_s;
      m2 += r.det.tof_s * r.det.tof_s;
      n += 1;
    }
    return n > 1 ? std::sqrt(std::max(0.0, m2 / n - (m / n) * (m / n))) : 0.0;
  };
  const auto hi = at(40), lo = at(-12);
  EXPECT_EQ(hi.sum.decode_errors, 0u);
  EXPECT_LT(spread(hi.rows), 0.1e-6);
  EXPECT_GT(lo.sum.decode_errors, 0u);
  EXPECT_GT(lo.sum.error_rate, hi.sum.error_rate);
}

// Tiny and huge amplitudes through a 12-bit ADC: 2 mVpp drive puts the burst (2e-5 V at 0.5 m)
// below half an LSB (0.24 mV): nothing reaches the receiver, every measurement is a miss and an
// error. 10 kVpp: the ADC clips in every measurement, and the summary counts it.
TEST(SceneExtremes, TinyAndHugeAmplitudes) {
  const std::string base = "transducers: {}\ngeometry:\n  distances_m: [0.5]\nexcitation:\n  family: Gold4\n"
                           "  codes: [1, 2]\n";
  const auto tiny = run(base + "  drive_vpp: 0.002\nnoise:\n  adc:\n    bits: 12\n    full_scale_v: 1.0\n");
  EXPECT_EQ(tiny.sum.missed, tiny.sum.measurements);
  EXPECT_EQ(tiny.sum.decode_errors, tiny.sum.measurements);
  const auto huge = run(base + "  drive_vpp: 10000\n" + kAdc);
  EXPECT_EQ(huge.sum.clipped_measurements, huge.sum.measurements);
  EXPECT_GT(huge.sum.clipped_max, 100u);
}

// ADC faults. A DC offset of 0.3 V (the 0.1 V burst stays inside +-1 V): the bandpass removes it,
// no error, no clipping. An offset of 0.95 V pushes the positive peaks over full scale: clipped.
// A stuck LSB adds at most 1 LSB of error: no decode error. A stuck sign bit turns the stream
// into garbage: the scene cannot report a right distance for it quietly (every such measurement
// is an error or within 2 mm).
TEST(SceneExtremes, AdcDcOffsetAndStuckBit) {
  const std::string base = "transducers: {}\ngeometry:\n  distances_m: [0.5]\nexcitation:\n  family: Gold4\n"
                           "  codes: [1, 2, 3]\nnoise:\n  noise_v: 0.001\n  adc:\n    bits: 12\n    full_scale_v: 1.0\n";
  const auto dc = run(base + "    dc_offset_v: 0.3\n");
  EXPECT_EQ(dc.sum.decode_errors, 0u);
  EXPECT_EQ(dc.sum.clipped_measurements, 0u);
  EXPECT_LT(dc.sum.rmse_m, 1e-3);
  const auto dc_clip = run(base + "    dc_offset_v: 0.95\n");
  EXPECT_EQ(dc_clip.sum.clipped_measurements, dc_clip.sum.measurements);
  const auto lsb = run(base + "    stuck_bit: 0\n    stuck_value: 1\n");
  EXPECT_EQ(lsb.sum.decode_errors, 0u);
  EXPECT_LT(lsb.sum.rmse_m, 1e-3);
  const auto sign = run(base + "    stuck_bit: 11\n    stuck_value: 0\n");
  for (const auto& m : sign.rows) {
    const bool counted = !m.detected || m.det.code != m.code_sent || m.pearson_error;
    EXPECT_TRUE(counted || std::abs(m.error_m) < 2e-3) << "code " << m.code_sent << " error " << m.error_m;
  }
  // The keys are checked.
  EXPECT_THROW(parse_scene(base + "    stuck_bit: 12\n", "s.yaml"), InputError);
  EXPECT_THROW(parse_scene(base + "    stuck_value: 2\n", "s.yaml"), InputError);
}

// Temperature -20..+50 C: the channel's c follows the air (Cramer 1993). A receiver that knows
// the channel's c measures the distance right at every temperature.
TEST(SceneExtremes, TemperatureMinusTwentyToPlusFifty) {
  for (const double t : {-20.0, 50.0}) {
    const auto r = run("transducers: {}\nmedium:\n  temperature_c: " + std::to_string(t) +
                       "\ngeometry:\n  distances_m: [1.0]\nexcitation:\n  family: Gold4\n  codes: [1, 6]\n");
    EXPECT_EQ(r.sum.decode_errors, 0u) << t << " C";
    EXPECT_LT(r.sum.rmse_m, 1e-3) << t << " C";
  }
}

// Sound-velocity compensation: the receiver assumes 343.99 m/s (20 C, 50 %); the air is dry, at T.
// Independent calculation: c(T) by the ideal-gas law for dry air, c = 331.3 sqrt(1 + T/273.15)
// (within 0.1 % of Cramer's dry-air value from -20 to +40 C), so the uncompensated error at d is
// d (343.99 / c(T) - 1); with a 0.1 m reference path the error is below 1 mm.
TEST(SoundVelocityCompensation, CorrectsTheTemperatureError) {
  for (const double t : {-20.0, 40.0}) {
    const std::string yaml = "transducers: {}\nmedium:\n  temperature_c: " + std::to_string(t) +
                             "\n  relative_humidity: 0\ngeometry:\n  distances_m: [1.0]\nexcitation:\n  family: Gold4\n  codes: [1, 4]\n"
                             "receiver:\n  speed_of_sound: 343.99\n";
    const double c_ideal = 331.3 * std::sqrt(1.0 + t / 273.15);
    const double expect = 1.0 * (343.99 / c_ideal - 1.0);
    const auto raw = run(yaml);
    for (const auto& m : raw.rows) {
      ASSERT_TRUE(m.detected);
      EXPECT_NEAR(m.error_m, expect, 0.02 * std::abs(expect) + 1e-3) << t << " C";
      EXPECT_DOUBLE_EQ(m.speed_used, 343.99);
    }
    const auto comp = run(yaml + "compensation:\n  reference_distance_m: 0.1\n");
    for (const auto& m : comp.rows) {
      ASSERT_TRUE(m.detected);
      EXPECT_LT(std::abs(m.error_m), 1e-3) << t << " C";
      EXPECT_NEAR(m.speed_used, c_ideal, 0.002 * c_ideal) << t << " C";
      EXPECT_FALSE(m.reference_missed);
    }
    EXPECT_GT(std::abs(expect), 0.03);  // the uncorrected error is centimetres: the test can fail
  }
}

TEST(SoundVelocityCompensation, KeysAreChecked) {
  EXPECT_THROW(parse_scene("geometry:\n  distances_m: [0.5]\ncompensation:\n  reference_distance_m: 0\n", "s.yaml"),
               InputError);
  EXPECT_THROW(parse_scene("geometry:\n  distances_m: [0.5]\ncompensation:\n  distance: 0.1\n", "s.yaml"), InputError);
  EXPECT_THROW(parse_scene("geometry:\n  distances_m: [0.5]\nreceiver:\n  speed_of_sound: 20\n", "s.yaml"), InputError);
}

TEST(FlatTopClipping, CountsRunsAtTheExtremes) {
  std::vector<double> x;
  for (int n = 0; n < 400; ++n) x.push_back(std::sin(2 * 3.14159265358979 * n / 25.0));
  EXPECT_EQ(flat_top_clipping(x).samples, 0u);  // a clean sine: no flat top
  for (double& v : x) v = std::clamp(2.0 * v, -1.0, 1.0);
  const FlatTops t = flat_top_clipping(x);
  EXPECT_GT(t.samples, 100u);
  EXPECT_EQ(t.runs, 32u);  // 16 cycles, one flat top and one flat bottom each
  EXPECT_EQ(flat_top_clipping(std::vector<double>(10, 0.0)).samples, 0u);
}

// The scan in blocks (decode streams the capture) counts what a plain count of the maximal runs
// at the extremes finds, wherever the blocks cut the runs and however long the flat stretches
// between them.
TEST(FlatTopClipping, BlocksOfAnySizeCountThePlainRuns) {
  std::mt19937_64 rng(5);
  std::vector<double> x;
  while (x.size() < 5000) {
    const int kind = static_cast<int>(rng() % 4), len = 1 + static_cast<int>(rng() % 6);
    for (int i = 0; i < (kind < 2 ? len : 1 + static_cast<int>(rng() % 200)); ++i) {
      x.push_back(kind == 0 ? 0.75 : kind == 1 ? -0.5 : std::uniform_real_distribution<double>(-0.49, 0.74)(rng));
    }
  }
  for (std::size_t min_run : {1u, 3u, 5u}) {
    std::size_t samples = 0, runs = 0;  // the plain count
    for (std::size_t i = 0; i < x.size();) {
      std::size_t j = i;
      while (j < x.size() && x[j] == x[i]) ++j;
      if ((x[i] == 0.75 || x[i] == -0.5) && j - i >= min_run) samples += j - i, ++runs;
      i = j;
    }
    ASSERT_GT(runs, 50u);
    for (std::size_t block : {std::size_t{1}, std::size_t{2}, std::size_t{7}, std::size_t{64}, x.size()}) {
      FlatTopScan scan(min_run);
      for (std::size_t i = 0; i < x.size(); i += block) scan.levels(std::span(x).subspan(i, std::min(block, x.size() - i)));
      for (std::size_t i = 0; i < x.size(); i += block) scan.runs(std::span(x).subspan(i, std::min(block, x.size() - i)));
      const FlatTops t = scan.result();
      EXPECT_EQ(t.samples, samples) << "min_run " << min_run << ", blocks of " << block;
      EXPECT_EQ(t.runs, runs) << "min_run " << min_run << ", blocks of " << block;
      EXPECT_EQ(t.high, 0.75);
      EXPECT_EQ(t.low, -0.5);
    }
  }
}

// levels() (eight lanes at a time) finds std::minmax_element's values: the extremes at every
// position of a block of every length, and a zero extreme with std::minmax_element's sign
// (the first smallest, the last largest).
TEST(FlatTopClipping, LevelsAreMinmaxElementsValues) {
  std::mt19937_64 rng(11);
  for (std::size_t n = 1; n <= 40; ++n) {
    for (std::size_t at = 0; at < n; ++at) {
      std::vector<double> x(n);
      for (double& v : x) v = std::uniform_real_distribution<double>(-1, 1)(rng);
      x[at] = 3.0;
      x[n - 1 - at] = -2.0;
      FlatTopScan scan;
      scan.levels(x);
      const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
      ASSERT_EQ(scan.result().high, *hi) << n << " " << at;
      ASSERT_EQ(scan.result().low, *lo) << n << " " << at;
    }
  }
  for (const std::vector<double>& x : {std::vector<double>{-1, 0.0, -0.0}, std::vector<double>{-0.0, 0.0, 1, 2, 3, 4, 5, 6, 7, 8},
                                       std::vector<double>(17, -0.0)}) {
    FlatTopScan scan;
    scan.levels(x);
    const auto [lo, hi] = std::minmax_element(x.begin(), x.end());
    EXPECT_EQ(std::signbit(scan.result().high), std::signbit(*hi));
    EXPECT_EQ(std::signbit(scan.result().low), std::signbit(*lo));
  }
}

// levels() over consecutive parts on scans of their own, merged in order, gives the one scan's
// levels: the same values and, for signed zeros, the same signs (the first of its value).
TEST(FlatTopClipping, LevelsMergedFromPartsAreTheOneScansLevels) {
  std::mt19937_64 rng(12);
  std::vector<std::vector<double>> cases = {{-0.0, 0.0, -0.0, 0.0}, {0.0, -0.0, 0.0, -0.0}, std::vector<double>(24, -0.0)};
  for (int r = 0; r < 60; ++r) {  // ties everywhere; zeros of both signs as the maximum, the minimum, or inside
    std::vector<double> x(37);
    const int lo = r % 3 == 1 ? 0 : -2, hi = r % 3 == 0 ? 0 : 2;
    for (double& v : x) v = std::uniform_int_distribution<int>(lo, hi)(rng) * 0.5;
    for (double& v : x) v = v == 0.0 && rng() % 2 ? -0.0 : v;
    cases.push_back(x);
  }
  for (const auto& x : cases) {
    const std::size_t blk = 2;  // the blocks both ways see
    FlatTopScan one;
    for (std::size_t i = 0; i < x.size(); i += blk) one.levels(std::span<const double>(x).subspan(i, std::min(blk, x.size() - i)));
    for (std::size_t parts = 1; parts <= 5; ++parts) {
      const std::size_t blocks = (x.size() + blk - 1) / blk;
      FlatTopScan merged;
      merged.merge_levels(FlatTopScan());  // an empty part changes nothing
      for (std::size_t p = 0; p < parts; ++p) {
        FlatTopScan part;
        for (std::size_t b = p * blocks / parts; b < (p + 1) * blocks / parts; ++b) {
          part.levels(std::span<const double>(x).subspan(b * blk, std::min(blk, x.size() - b * blk)));
        }
        merged.merge_levels(part);
      }
      const FlatTops a = one.result(), m = merged.result();
      EXPECT_EQ(m.high, a.high) << parts;
      EXPECT_EQ(m.low, a.low) << parts;
      EXPECT_EQ(std::signbit(m.high), std::signbit(a.high)) << parts;
      EXPECT_EQ(std::signbit(m.low), std::signbit(a.low)) << parts;
    }
  }
}

// The tools never clip silently: simulate's text and JSON summaries and decode's output name it,
// and a range-ambiguous scene warns on stderr and never reads "errors 0".
TEST(SceneExtremesCli, SimulateAndDecodeReportClipping) {
  namespace fs = std::filesystem;
  using ranging::testing_support::run_tool;
  const testing_support::ScratchDir scratch("ranging_extremes");
  const fs::path dir = scratch.path();
  {
    std::ofstream(dir / "clip.yaml") << "name: clip\ntransducers: {}\ngeometry:\n  distances_m: [0.02]\nexcitation:\n"
                                        "  family: Gold4\n  codes: [2]\n" << kAdc;
  }
  const auto txt = run_tool("simulate " + (dir / "clip.yaml").string() + " --quiet --write-captures --out " + (dir / "t").string());
  ASSERT_EQ(txt.status, 0) << txt.err;
  EXPECT_NE(txt.out.find("input clipped (ADC) in 1 of 1 measurements"), std::string::npos) << txt.out;
  const auto js = run_tool("simulate " + (dir / "clip.yaml").string() + " --json --out " + (dir / "j").string());
  ASSERT_EQ(js.status, 0) << js.err;
  const auto j = nlohmann::json::parse(js.out);
  EXPECT_EQ(j["families"][0]["input_clipping"]["measurements_clipped"], 1);
  EXPECT_GT(j["families"][0]["input_clipping"]["samples_clipped"].get<int>(), 10);
  const auto dec = run_tool("decode " + (dir / "t" / "captures" / "Gold4_20mm_r1_j2.csv").string());
  EXPECT_NE(dec.out.find("input clipped:"), std::string::npos) << dec.out << dec.err;

  {
    std::ofstream(dir / "amb.yaml") << "name: amb\ntransducers: {}\ngeometry:\n  distances_m: [1.05]\nexcitation:\n"
                                       "  family: Gold4\n  schedule:\n    mode: periodic\n"
                                       "    period_s: 0.000326797385620915\n    bursts: 18\n";
  }
  const auto amb = run_tool("simulate " + (dir / "amb.yaml").string() + " --json --out " + (dir / "a").string());
  ASSERT_EQ(amb.status, 0) << amb.err;
  EXPECT_NE(amb.err.find("unambiguous range"), std::string::npos) << amb.err;
  const auto a = nlohmann::json::parse(amb.out);
  EXPECT_EQ(a["families"][0]["range_ambiguous"], 9);
  EXPECT_GE(a["decode_errors"].get<int>(), 9);
}
