#pragma once
// The main job at this stage: every code of a family is encoded (BPSK, eq. 5/6), sent through
// the simple channel (delay d/c, 1/d spreading, resonant TX and RX transducers, white noise),
// filtered and decoded by the float and the bit-accurate fixed receiver; the paper's Pearson
// decoder (a matched filter: eq. 9 maximized over lags within +-L chips of the float ToF, with
// received templates) gives rho_max, rho_submax and u = rho(sent) - max rho(other) (eq. 10,
// negative on a Pearson misdecode).
//
// Time of flight: the receiver reports the correlation peak's sample; the latency of the
// chain (code window, filter and transducer group delay) is calibrated per code and per
// precision on a noise-free burst at the reference distance (0.1 m), as the paper's system
// does with its reference measurement.
#include <functional>
#include <vector>

#include "model/sim/channel.hpp"
#include "model/dsp/receiver.hpp"

namespace ranging {

struct DemoParams {
  ReceiverConfig receiver;                        // family, filter, word lengths, detector
  std::vector<double> distances_m = {0.1, 0.55, 1.0};
  double speed_of_sound = 340.0;
  double gain = 0.5;          // received amplitude at 0.1 m, ADC full-scale units
  double noise_rms = 0.002;   // white noise at the ADC input, full-scale units (0: none)
  std::uint64_t seed = 1;
  TransducerParams transducer;                    // TX and RX
  int jobs = 1;               // threads for the rows (distance x code); the rows do not depend on it
};

struct DemoDecode {
  bool detected = false;
  int decoded = 0;            // 1-based code j of the strongest event
  double tof_s = 0;
  double distance_m = 0;
  double error_m = 0;         // measured - true
  double score = 0;           // rho^2 of the event
  double margin = 0;          // rho^2(best) - rho^2(second)
};

struct DemoRow {
  int code = 0;               // sent, 1-based
  double distance_m = 0;      // true
  DemoDecode flt, fix;
  // The paper's decoder (Pearson matched filter with received templates around the float ToF).
  int pearson_decoded = 0;
  double rho_max = 0, rho_submax = 0;
  double u = 0;               // eq. 10: rho(sent) - max rho(other codes)
  double energy = 0;          // sum of squares of the filtered received burst
  std::uint64_t overflows = 0;  // fixed-point saturation events (input, filter, correlator)
};

std::vector<DemoRow> run_demo(const DemoParams& params,
                              const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace ranging
