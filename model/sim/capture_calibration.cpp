#include "model/sim/capture_calibration.hpp"

#include <cmath>
#include <string>

#include "model/base/error.hpp"

namespace ranging {

double LatencyCalibration::correct(int code, double tof_s) const {
  const auto it = per_code_s.find(code);
  return tof_s - (it != per_code_s.end() ? it->second : mean_s);
}

LatencyCalibration calibrate_latency(const std::vector<Detection>& dets, double distance_m, double c,
                                     const std::string& what) {
  require_in_range(what + ": distance", distance_m, 1e-3, 1000.0);
  require_in_range(what + ": speed of sound", c, 100.0, 10000.0);
  if (dets.empty()) throw InputError(what + ": the receiver detects no burst in the calibration capture");
  std::map<int, const Detection*> best;
  for (const auto& d : dets) {
    if (!d.tof_from_send) continue;  // no send of its code before it: no ToF to calibrate with
    auto& b = best[d.code];
    if (!b || d.score > b->score) b = &d;
  }
  if (best.empty()) {
    throw InputError(what + ": every burst the receiver detects arrives before its code was first sent (the "
                     "capture's t = 0 is not the first burst's start, or its period is wrong)");
  }
  LatencyCalibration cal;
  double sum = 0;
  for (const auto& [code, d] : best) {
    cal.per_code_s[code] = d->tof_s - distance_m / c;
    sum += cal.per_code_s[code];
  }
  cal.mean_s = sum / static_cast<double>(best.size());
  return cal;
}

}  // namespace ranging
