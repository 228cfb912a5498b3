// The ranging system's generated parameters (model/hw/hw_system.hpp): burst period from eq. 3/4,
// transmit drive, time of flight model, refusals, and the committed generated system files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "model/config/receiver_config.hpp"
#include "model/base/error.hpp"
#include "model/dsp/excitation.hpp"
#include "model/hw/hw_system.hpp"
#include "model/sim/metrics.hpp"
#include "model/dsp/receiver.hpp"

using namespace ranging;

namespace {

const ReceiverDesign& design() {
  static const ReceiverDesign d =
      design_receiver(load_receiver_config(std::string(RANGING_SOURCE_DIR) + "/configs/default.yaml"));
  return d;
}
const SystemDesign& sys() {
  static const SystemDesign s = system_design(design());
  return s;
}

TEST(HwSystem, PeriodFollowsEquations3And4) {
  const auto& s = sys();
  const double c = s.speed_of_sound, l = s.max_range_m;
  // eq. 3: eta codes cover the longest flight; eq. 4's other bound: T >= 1.5 T_d.
  EXPECT_GE(eta_required(l, s.period_t / s.fs, c), 1);
  EXPECT_LE(eta_required(l, s.period_t / s.fs, c), s.codes);
  EXPECT_GE(s.period_t, 1.5 * design().layout.window);
  // The rate is eq. 4's v_max up to the rounding of T to whole samples (the paper's Table 6
  // gives 3060 Hz for Gold codes at L = 1 m).
  const double v = vmax(design().layout.window / s.fs, s.codes, c, l);
  EXPECT_LE(s.measurement_rate_hz(), v + 1e-9);
  EXPECT_GT(s.measurement_rate_hz(), s.fs / (s.fs / v + 1));
  // hardware.clock_hz 30 MHz: 6 clocks per 5 MS/s sample, 20 per 1.5 Mbaud bit.
  EXPECT_EQ(s.clk_div, 6);
  EXPECT_EQ(s.baud_div, 20);
}

TEST(HwSystem, DriveIsTheScheduleOfHbridgeBursts) {
  const auto& d = design();
  const auto& s = sys();
  const std::size_t n = static_cast<std::size_t>(s.period_t) * (s.codes + 1);
  const auto drive = system_drive(d, s, n);
  const ExcitationParams ex = receiver_excitation(d.config);
  for (int b = 0; b <= s.codes; ++b) {
    const auto h = hbridge_drive(d.family.codes[static_cast<std::size_t>(b % s.codes)], ex);
    const std::size_t start = static_cast<std::size_t>(b) * s.period_t;
    for (std::size_t i = 0; i < static_cast<std::size_t>(s.period_t); ++i) {
      const int want = i < h.size() ? h[i] : 0;
      ASSERT_EQ(drive[start + i], want) << "burst " << b << " sample " << i;
    }
  }
}

TEST(HwSystem, TimeOfFlightUsesTheMostRecentBurstOfTheCode) {
  const auto& s = sys();
  TofDistanceModel m(s);
  const std::int64_t t = s.period_t, one = std::int64_t{1} << s.frac_w;
  // Bursts 0..10 sent (codes 1..9, 1, 2); an arrival of code 3 sent at 2T, 4000.5 samples later,
  // reported after burst 10 (code 2): it must use burst 2, not a later or earlier one.
  for (int b = 0; b <= 10; ++b) m.burst(b % s.codes + 1, b * t);
  const std::int64_t arrival = (2 * t + 4000) * one + one / 2 + s.offsets[2];
  const auto r = m.execute(3, arrival, 1, 2);
  EXPECT_EQ(r.flags, 0u);
  EXPECT_EQ(r.tof, static_cast<std::uint32_t>(4000 * one + one / 2));
  EXPECT_EQ(r.distance, 272034u);  // 4000.5 samples * 68 um, rounded
  // Code 1 arriving after its second burst (9T) uses that one.
  const auto r1 = m.execute(1, (9 * t + 100) * one + s.offsets[0], 0, 0);
  EXPECT_EQ(r1.tof, static_cast<std::uint32_t>(100 * one));
  // An arrival before any burst of its code was sent is flagged.
  TofDistanceModel early(s);
  early.burst(1, 0);
  EXPECT_EQ(early.execute(5, 3000 * one + s.offsets[4], 0, 0).flags, 1u);
}

TEST(HwSystem, RefusesClocksThatAreNotMultiplesOfTheSampleRate) {
  SystemOptions o;
  o.clk_hz = 47e6;
  try {
    system_design(design(), o);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("clk_hz"), std::string::npos) << e.what();
  }
  o = {};
  o.baud = 1e6 + 1;
  EXPECT_THROW(system_design(design(), o), InputError);
  o = {};
  o.speed_of_sound = 5;
  EXPECT_THROW(system_design(design(), o), InputError);
}

// (tests/test_generate.cpp checks that the committed generated/default, system files included,
// is what the generator writes.)

}  // namespace

TEST(HwSystem, Ice40PllMatchesIcepll) {
  // What `icepll -i 12 -o 30` and `icepll -i 12 -o 45` print (icestorm's own search).
  const Ice40Pll p30 = ice40_pll(12e6, 30e6);
  EXPECT_EQ(p30.divr, 0);
  EXPECT_EQ(p30.divf, 79);
  EXPECT_EQ(p30.divq, 5);
  EXPECT_EQ(p30.filter_range, 1);
  EXPECT_DOUBLE_EQ(p30.f_vco, 960e6);
  const Ice40Pll p45 = ice40_pll(12e6, 45e6);
  EXPECT_EQ(p45.divf, 59);
  EXPECT_EQ(p45.divq, 4);
  // 47 MHz is not exact from 12 MHz (F_PFD >= 10 MHz leaves DIVR = 0 and 47 * 2^q / 12 is
  // never an integer in the VCO range).
  try {
    ice40_pll(12e6, 47e6);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("clk_hz"), std::string::npos) << e.what();
  }
}

TEST(HwSystem, ClockComesFromTheConfigurationAndReachesTheBoardFiles) {
  const ReceiverDesign d = design();
  const SystemDesign s = system_design(d);
  EXPECT_EQ(s.clk_hz, d.config.clock_hz);
  EXPECT_EQ(s.clk_div, d.config.sample_cycles());
  const auto files = generate_system_files(d, "test");
  const std::string& vh = files.at("rtl/ice40_pll.vh");
  const Ice40Pll p = ice40_pll(12e6, d.config.clock_hz);
  EXPECT_NE(vh.find("`define RANGING_PLL_DIVF " + std::to_string(p.divf) + "\n"), std::string::npos) << vh;
  EXPECT_NE(vh.find("`define RANGING_PLL_DIVQ " + std::to_string(p.divq) + "\n"), std::string::npos) << vh;
  // A configuration clock that is not a multiple of fs is refused by the configuration itself.
  ReceiverConfig c = d.config;
  c.clock_hz = 31e6;
  try {
    validate(c);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("hardware.clock_hz"), std::string::npos) << e.what();
  }
}
