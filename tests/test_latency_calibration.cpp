// The receiver's latency calibration (model/dsp/latency.hpp), the one procedure the demo, the
// scene simulator and the system design use: offset = strongest event's arrival - flight.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "model/base/error.hpp"
#include "model/dsp/latency.hpp"

using namespace ranging;

TEST(LatencyCalibration, FlightIsDistanceOverSpeedInSamples) {
  EXPECT_DOUBLE_EQ(calibration_flight(0.1, 340.0, 5e6), 0.1 / 340.0 * 5e6);
}

TEST(LatencyCalibration, StrongestEventIsTheFirstOfTheHighestScore) {
  const std::vector<Event> none;
  EXPECT_EQ(strongest_event(none), nullptr);
  const std::vector<Event> ev{{1, 10.0, 0.5, 0}, {2, 20.0, 0.9, 0}, {3, 30.0, 0.9, 0}};
  EXPECT_EQ(strongest_event(ev), &ev[1]);
}

TEST(LatencyCalibration, OffsetIsTheStrongestArrivalMinusTheFlight) {
  // Float events: per code, a weak stray event and the code's own peak.
  const auto off = calibrate_receiver_latency<Event>(
      3, 100.5,
      [](int code) {
        return std::vector<Event>{{code % 3 + 1, 50.0, 0.1, 0}, {code, 200.0 + code, 0.95, 0.5}};
      },
      [](int code) { return "code " + std::to_string(code); });
  EXPECT_EQ(off, (std::vector<double>{100.5, 101.5, 102.5}));
  // Fixed events: arrival and flight in the same fixed-point unit, exact.
  const auto off_q = calibrate_receiver_latency<EventFixed>(
      2, std::int64_t{1000},
      [](int code) { return std::vector<EventFixed>{{code, 4096 + code, 7, 1}}; },
      [](int code) { return "code " + std::to_string(code); });
  EXPECT_EQ(off_q, (std::vector<std::int64_t>{3097, 3098}));
}

TEST(LatencyCalibration, MissingOrWrongCodeNamesTheCode) {
  auto fail = [](int code) { return "calibration: code " + std::to_string(code); };
  try {
    (void)calibrate_receiver_latency<Event>(
        3, 0.0, [](int code) { return code == 2 ? std::vector<Event>{} : std::vector<Event>{{code, 1, 1, 0}}; },
        fail);
    FAIL() << "no event for code 2 was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "calibration: code 2");
  }
  try {
    (void)calibrate_receiver_latency<Event>(2, 0.0, [](int) { return std::vector<Event>{{1, 1, 1, 0}}; }, fail);
    FAIL() << "code 2 decoded as code 1 was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), "calibration: code 2");
  }
}

TEST(LatencyCalibration, AnyCodeTakesTheStrongestWhateverItsCode) {
  // The demo's mode: a misdecoding receiver is calibrated on what it reports.
  const auto off = calibrate_receiver_latency<Event>(
      2, 10.0, [](int) { return std::vector<Event>{{1, 30.0, 0.2, 0}, {2, 40.0, 0.8, 0}}; },
      [](int code) { return "code " + std::to_string(code); }, CalibrationCode::Any);
  EXPECT_EQ(off, (std::vector<double>{30.0, 30.0}));
  EXPECT_THROW((void)calibrate_receiver_latency<Event>(
                   1, 0.0, [](int) { return std::vector<Event>{}; }, [](int) { return std::string("none"); },
                   CalibrationCode::Any),
               InputError);
}
