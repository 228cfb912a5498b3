// simulate --plot (distance error against distance) and decode --plot (capture, bandpass output,
// bank rho^2 per code with the detections): the tool computes, scripts/plot_*.py draws with
// matplotlib (installed by scripts/install-deps.sh); the PNG appears only when drawn.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "tests/process.hpp"
#include "tests/scratch.hpp"

namespace {

namespace fs = std::filesystem;
using ranging::testing_support::run_tool;

std::string slurp(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Width and height from the PNG's IHDR chunk; {0, 0} when the file is not a PNG.
std::pair<unsigned, unsigned> png_size(const fs::path& p) {
  const std::string s = slurp(p);
  if (s.size() < 24 || s.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0 || s.compare(12, 4, "IHDR") != 0) return {0, 0};
  auto be32 = [&](std::size_t o) {
    unsigned v = 0;
    for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(s[o + i]);
    return v;
  };
  return {be32(16), be32(20)};
}

TEST(Plots, SimulateAndDecodeWritePngs) {
  const ranging::testing_support::ScratchDir scratch("plots", ::testing::TempDir());
  const std::string dir = scratch.str();
  {
    std::ofstream(dir + "/s.yaml") << "name: plots\ntransducers: {}\ngeometry:\n  distances_m: [0.2, 0.6]\n"
                                      "excitation:\n  family: M1\n  codes: [2]\nnoise:\n  noise_v: 0.002\n  seed: 3\n";
  }
  const auto sim = run_tool("simulate " + dir + "/s.yaml --out " + dir + "/out --quiet --write-captures --plot " + dir +
                            "/error.png");
  ASSERT_EQ(sim.status, 0) << sim.err;
  EXPECT_NE(sim.out.find(dir + "/error.png"), std::string::npos) << sim.out;
  // figsize 8 x 4.5 in at 110 dpi (scripts/plot_simulate_error.py)
  EXPECT_EQ(png_size(dir + "/error.png"), std::make_pair(880u, 495u));
  EXPECT_FALSE(fs::exists(dir + "/error.png.tmp"));
  EXPECT_FALSE(fs::exists(dir + "/error.png.data.json"));

  const auto dec = run_tool("decode " + dir + "/out/captures/M1_600mm_r1_j2.wav --family M1 --plot " + dir + "/dec.png");
  ASSERT_EQ(dec.status, 0) << dec.err;
  EXPECT_EQ(png_size(dir + "/dec.png"), std::make_pair(1000u, 800u));  // 10 x 8 in at 100 dpi
  EXPECT_FALSE(fs::exists(dir + "/dec.png.data.json"));
}

TEST(Plots, BadPlotPathsAreRefusedBeforeAnyWork) {
  const ranging::testing_support::ScratchDir scratch("plots_bad", ::testing::TempDir());
  const std::string dir = scratch.str();
  const std::string scene = std::string(RANGING_SOURCE_DIR) + "/scenes/minimal.yaml";
  auto r = run_tool("simulate " + scene + " --out " + dir + "/out --quiet --plot " + dir + "/error.txt");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("option --plot: '" + dir + "/error.txt' must name a .png file"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
  r = run_tool("simulate " + scene + " --out " + dir + "/out --quiet --plot " + dir + "/no/such/e.png");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("option --plot: the folder '" + dir + "/no/such'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir + "/out"));
  r = run_tool("decode " + dir + "/missing.wav --family M1 --plot " + dir);
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
}

}  // namespace
