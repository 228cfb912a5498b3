// calibrated_speed_register (model/hw/sound_speed_cal.hpp), the model of rtl/sound_speed_cal.v:
// values from exact integer arithmetic (Python's ((D << 24) + ToF // 2) // ToF, which the RTL
// divider also produced under Icarus), saturation, and the round trip through the speed.
#include <gtest/gtest.h>

#include <cmath>

#include "model/hw/hw_system.hpp"
#include "model/hw/sound_speed_cal.hpp"

using namespace ranging;

TEST(SoundSpeedCal, ExactQuotientsRoundedHalfUp) {
  bool sat = true;
  EXPECT_EQ(calibrated_speed_register(376471, 100000, 24, &sat), 4456443u);
  EXPECT_FALSE(sat);
  EXPECT_EQ(calibrated_speed_register(12345, 100000, 24, &sat), 135902924u);
  EXPECT_EQ(calibrated_speed_register(0xffffffffu, 100000, 24, &sat), 391u);
  EXPECT_EQ(calibrated_speed_register(393937, 100000, 24, &sat), 4258858u);
  // half up: 7 / 2 = 3.5 -> 4, 5 / 2 = 2.5 -> 3 (D 2^0)
  EXPECT_EQ(calibrated_speed_register(2, 7, 0), 4u);
  EXPECT_EQ(calibrated_speed_register(2, 5, 0), 3u);
  EXPECT_EQ(calibrated_speed_register(3, 4, 0), 1u);  // 1.33 -> 1
}

TEST(SoundSpeedCal, SaturatesAt32Bits) {
  bool sat = false;
  EXPECT_EQ(calibrated_speed_register(1, 100000, 24, &sat), 0xffffffffu);
  EXPECT_TRUE(sat);
  EXPECT_THROW(calibrated_speed_register(0, 100000, 24), std::logic_error);
}

TEST(SoundSpeedCal, RoundTripThroughTheSpeedOfSound) {
  const double fs = 5e6;
  for (double c : {300.0, 325.0, 343.21, 360.0}) {
    // the ToF of 0.1 m at c, 8 fraction bits
    const auto tof = static_cast<std::uint32_t>(std::lround(0.1 / c * fs * 256));
    const auto reg = calibrated_speed_register(tof, 100000, 8 + 16);
    EXPECT_NEAR(speed_of_register(reg, fs, 16), c, c * 2e-6);
    EXPECT_NEAR(static_cast<double>(reg), static_cast<double>(speed_register(c, fs, 16)), 12.0);
  }
}
