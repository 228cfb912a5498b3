// `ranging bitstream` for real (label soak, minutes: RANGING_SOAK=1): a configuration that is not
// committed (UART at 1 Mbaud, 2 m range) placed and routed with two seeds in parallel, the
// report in --out, the targets checked.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "tests/process.hpp"

namespace {

namespace fs = std::filesystem;

TEST(BitstreamSoak, UserConfigurationPlacedAndRoutedWithParallelSeeds) {
  if (std::system("command -v nextpnr-ice40 >/dev/null") != 0) GTEST_FAIL() << "nextpnr-ice40 not installed";
  const std::string dir = ::testing::TempDir() + "/bitstream_soak_" + std::to_string(::getpid());
  fs::remove_all(dir);
  const auto r = ranging::testing_support::run_tool(
      "bitstream --config " + std::string(RANGING_SOURCE_DIR) +
      "/configs/default.yaml --set system.baud=1000000 --set system.max_range_m=2 --seeds 2 --jobs 2 --check --out " + dir);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("targets met"), std::string::npos) << r.out;
  const auto j = nlohmann::json::parse(std::ifstream(dir + "/results/bitstream.json"));
  EXPECT_TRUE(j["ice40"]["placed_and_routed"].get<bool>());
  EXPECT_EQ(j["ice40"]["nextpnr_seeds_tried"].get<int>(), 2);
  EXPECT_EQ(j["system"]["baud"].get<double>(), 1e6);
  EXPECT_TRUE(fs::exists(dir + "/seed-1/nextpnr.log") && fs::exists(dir + "/seed-2/nextpnr.log"));
  EXPECT_GT(fs::file_size(dir + "/ranging_icebreaker.bin"), 100000u);
  fs::remove_all(dir);
}

}  // namespace
