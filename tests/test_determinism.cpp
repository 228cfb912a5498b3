// A measurement's noise draws depend on the values of its scene entry and the seed, never on
// its place in a list (issue 11): splitting a scene's distance list, reordering its families or
// sending a subset of its codes gives the same per-measurement results.
#include <gtest/gtest.h>

#include <map>
#include <sstream>
#include <tuple>

#include "model/dsp/codes.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"

using namespace ranging;

namespace {

// The scenes/default.yaml chain at a noise level that makes the draws visible.
std::string scene_yaml(const std::string& distances, const std::string& families, const std::string& codes = "") {
  std::ostringstream y;
  y << "medium:\n  temperature_c: 20\ntransducers: {}\ngeometry:\n  distances_m: " << distances
    << "\n  repeats: 2\nexcitation:\n  family: " << families << "\n";
  if (!codes.empty()) y << "  codes: " << codes << "\n";
  y << "noise:\n  noise_v: 0.02\n  seed: 11\n  adc:\n    bits: 12\n    full_scale_v: 2.0\n"
       "receiver:\n  precision: fixed\n";
  return y.str();
}

using Key = std::tuple<std::string, double, int, int>;  // family, distance, repeat, code

std::map<Key, Measurement> run_all(const std::string& yaml) {
  SceneSimulator sim(parse_scene(yaml, "s.yaml"));
  std::map<Key, Measurement> out;
  for (const auto& f : sim.scene().excitation.families) {
    for (const auto& m : sim.run(f)) out[{m.family, m.true_distance_m, m.repeat, m.code_sent}] = m;
  }
  return out;
}

void expect_same(const Measurement& a, const Measurement& b) {
  EXPECT_EQ(a.detected, b.detected);
  EXPECT_EQ(a.det.code, b.det.code);
  EXPECT_EQ(a.det.tof_s, b.det.tof_s);  // bit for bit
  EXPECT_EQ(a.error_m, b.error_m);
  EXPECT_EQ(a.det.rho_max, b.det.rho_max);
  EXPECT_EQ(a.det.energy, b.det.energy);
}

}  // namespace

TEST(Determinism, SplittingTheDistanceListGivesTheSamePerDistanceResults) {
  const auto whole = run_all(scene_yaml("[0.1, 0.5, 1.0]", "[M1, Gold4]"));
  ASSERT_EQ(whole.size(), static_cast<std::size_t>(2 * 3 * (code_family("M1").eta() + code_family("Gold4").eta())));
  std::size_t compared = 0;
  for (const char* d : {"[1.0]", "[0.5]", "[0.1]"}) {
    // One distance alone, the families in the other order.
    for (const auto& [k, m] : run_all(scene_yaml(d, "[Gold4, M1]"))) {
      SCOPED_TRACE(std::get<0>(k) + " at " + std::to_string(std::get<1>(k)) + " m, repeat " +
                   std::to_string(std::get<2>(k)) + ", code " + std::to_string(std::get<3>(k)));
      ASSERT_TRUE(whole.count(k));
      expect_same(whole.at(k), m);
      ++compared;
    }
  }
  EXPECT_EQ(compared, whole.size());
  // The noise is real: the two repeats of a measurement differ.
  const auto& r1 = whole.at({"Gold4", 0.5, 1, 3});
  const auto& r2 = whole.at({"Gold4", 0.5, 2, 3});
  EXPECT_NE(r1.det.energy, r2.det.energy);
}

TEST(Determinism, ASubsetOfTheCodesKeepsEachCodesResult) {
  const auto all = run_all(scene_yaml("[0.5]", "Gold4"));
  const auto some = run_all(scene_yaml("[0.5]", "Gold4", "[7, 2]"));
  ASSERT_EQ(some.size(), 4u);
  for (const auto& [k, m] : some) expect_same(all.at(k), m);
}
