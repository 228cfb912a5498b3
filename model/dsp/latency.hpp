#pragma once
// The receiver's latency calibration, one procedure for every user: the demo
// (model/sim/demo.cpp), the scene simulator (model/sim/scene_simulator.cpp) and the system
// design (model/hw/hw_system.cpp: the OFFSETS of the RTL).
//
// A noise-free burst of code j is sent at sample 0 over a known distance d. It reaches the
// receiver after the flight d / c fs samples; the receiver reports it later by its latency (the
// code window, the filter's and the transducers' group delay):
//   offset_j = arrival of the strongest event the receiver reports on that burst - flight
// and an event of code j at arrival a then means the time of flight (a - offset_j) / fs.
// How the burst is made (the demo's channel, the scene's stages, the system's reference
// transducers) and which receiver runs it stay with the caller.
#include <cstddef>
#include <string>
#include <vector>

#include "model/base/error.hpp"
#include "model/dsp/peak_detector.hpp"

namespace ranging {

// d / c fs: the flight of a calibration burst, in samples.
inline double calibration_flight(double distance_m, double speed_of_sound, double fs) {
  return distance_m / speed_of_sound * fs;
}

// The strongest of the events (the highest score; the first of equal ones), nullptr if none.
// E: Event or EventFixed.
template <class E>
const E* strongest_event(const std::vector<E>& events) {
  const E* best = nullptr;
  for (const auto& e : events) {
    if (!best || e.score > best->score) best = &e;
  }
  return best;
}

// Whether the strongest event on code j's burst must be code j (the scene simulator, the system
// design) or may be any code (the demo: it runs deliberately broken receivers too, and reports
// their misdecodes in its rows).
enum class CalibrationCode { MustMatch, Any };

// offset_j of every code j = 1..codes (element j - 1). burst_events(j) runs the receiver over
// code j's calibration burst and returns the events it reports: Event (arrival in samples) or
// EventFixed (arrival in 2^-frac_bits samples); `flight` is in the same unit. Throws
// InputError(failure(j)) when there is no event or (MustMatch) the strongest is another code.
template <class E, class BurstEvents, class Failure>
std::vector<decltype(E::arrival)> calibrate_receiver_latency(std::size_t codes, decltype(E::arrival) flight,
                                                            BurstEvents&& burst_events, Failure&& failure,
                                                            CalibrationCode check = CalibrationCode::MustMatch) {
  std::vector<decltype(E::arrival)> offset;
  offset.reserve(codes);
  for (std::size_t j = 0; j < codes; ++j) {
    const int code = static_cast<int>(j) + 1;
    const std::vector<E> events = burst_events(code);
    const E* best = strongest_event(events);
    if (!best || (check == CalibrationCode::MustMatch && best->code != code)) throw InputError(failure(code));
    offset.push_back(best->arrival - flight);
  }
  return offset;
}

}  // namespace ranging
