#pragma once
// Receiver latency calibrated from a capture at a known distance (`decode --calibrate FILE
// --distance D`): the paper's own method (its references and its sound-velocity module use
// measurements at a known distance). The simulated latency of each code (scene simulator) is
// corrected by what the calibration capture shows:
//   delta_j = tof_j(calibration capture) - D / c        per code j found in it (seconds)
//   delta   = mean of delta_j over the codes found      (for codes the capture lacks)
//   tof'    = tof - delta_j (or - delta)                every later detection
// A transducer pair unlike the modelled one shifts every code's latency by about the same
// amount, which is why the mean stands in for codes the calibration capture does not hold.
#include <map>
#include <vector>

#include "model/sim/scene_simulator.hpp"

namespace ranging {

struct LatencyCalibration {
  std::map<int, double> per_code_s;  // code j -> delta_j
  double mean_s = 0;
  // tof - delta for code j (delta_j if measured, else the mean).
  double correct(int code, double tof_s) const;
};

// From the detections of a calibration capture taken at distance_m with speed of sound c.
// Where a code appears more than once, the strongest detection (receiver score) is used;
// detections with no send of their code before them (Detection::tof_from_send false) have no
// ToF and are left out. InputError naming `what` (the option) if no detection is left or the
// ranges are invalid.
LatencyCalibration calibrate_latency(const std::vector<Detection>& dets, double distance_m, double c,
                                     const std::string& what);

}  // namespace ranging
