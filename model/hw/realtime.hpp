#pragma once
// The real-time budget of a generated receiver (issue 17 section 7): whether the RTL keeps
// pace with the ADC at the configured clock, from the modules' own throughput rules (the
// equations of the rtl/*.v headers, written once here; tests/test_realtime.cpp checks them).
//
//   available  A = floor(clock_hz / fs) clocks per input sample (hardware.clock_hz, signal.fs)
//   bandpass   6 clocks per sample (shared multipliers, rtl/bandpass_sos.v); needs A >= 6
//   bank       front end 6 clocks per sample; back end per decimation group (rtl/correlator_bank.v)
//                B = 2 TAPS ceil(DEC_W/16) ceil(TAP_W/16) + 1
//                    + CODES (2 ceil(CORR_W/16)^2 + ceil(2 CORR_W/16) ceil(WEIGHT_W/16))
//   combiner   per group (rtl/correlator_bank.v, its own engine, no multiplier): one round of
//              CHIPS + 2 clocks per code,  C = (CHIPS + 2) CODES
//   detector   per group, worst case (rtl/peak_detector.v), NA = ceil(WEIGHTED_W/16),
//              NB = ceil(max(ENERGY_W - ENERGY_SHIFT, 1)/16):
//                P = CODES + 1 + 2 (2 NA NB + 3) + 1
//                    + max(CODES + 5 [capture], 6 + 2 FRAC_W + 1 + 2 (SCORE_W + 2) + 1 [event])
//   group time G = DECIM A clocks between two of the bank's groups
//   real time  A >= 6 and B <= G and C <= G and P <= G   (117, 81 and 101 <= 120 at the defaults)
// Integer arithmetic only; the verdict names the stage that does not keep pace.
#include <cstdint>
#include <string>
#include <vector>

#include "model/dsp/receiver.hpp"

namespace ranging {

struct RealTimeBudget {
  long long clocks_per_sample = 0;        // A
  long long decimation = 0;               // DECIM
  long long group_clocks = 0;             // G = DECIM A
  long long bandpass_clocks_per_sample = 6;
  long long bank_back_end_clocks = 0;     // B per group
  long long combiner_clocks = 0;          // C per group
  long long detector_clocks = 0;          // P per group (worst case)
  bool real_time = false;
  std::vector<std::string> limits;        // one line per stage that does not keep pace
  // Clocks per input sample the slowest stage needs: max(6, B / DECIM, C / DECIM, P / DECIM).
  double needed_clocks_per_sample() const;
  // "real time: ..." or "NOT REAL TIME: ..." with the numbers.
  std::string summary() const;
};

RealTimeBudget realtime_budget(const ReceiverDesign& design);

}  // namespace ranging
