#pragma once
// Host side of a blade crossing measured by the board (issue 15 §5): the vertical distance h
// from the UART measurement frames (model/hw/frames.hpp) alone, as a host program would do it.
//
// Emission times. A frame carries the code j and the ToF, not the emission time. The scheduler
// sends burst k at k T from its start (T = PERIOD_T / fs) with code (k mod eta) + 1
// (rtl/tx_scheduler.v), so the burst of a frame is the k = j - 1 (mod eta) nearest to
//     (t_host - ToF - latency) / T
// where t_host is the host's reception time of the frame (system clock), latency the time
// from the arrival to the frame (pipeline + 17 bytes of UART) passed by the caller. This is
// exact while the host's time error is below eta T / 2 (1.5 ms for 9 codes at 327 us).
// Emission times are then k T in the system's time base; both estimators of model/sim/rotor.hpp
// depend only on differences of times (the crossing time is an unknown of the motion-aware one).
//
// Selection, as run_rotor does: frames without flags, c ToF <= max_range_m, score (rho^2) >=
// accept_score, the longest consistent chain (consistent_chain()), then estimate_h_paper and
// estimate_h_motion with c the system's assumed speed of sound.
#include <span>
#include <vector>

#include "model/hw/frames.hpp"
#include "model/sim/rotor.hpp"

namespace ranging {

struct HostTiming {
  double fs = 5e6;          // full-rate samples/s
  int period_t = 0;         // samples between bursts
  int codes = 0;            // eta
  double latency_s = 0;     // arrival -> frame at the host
};

// Burst index of a frame (see the header); -1 for a code outside 1..codes.
long frame_burst_index(const UartFrame& f, double t_host_s, const HostTiming& t);

struct HostCrossingEstimate {
  std::vector<TofSample> samples;   // accepted, on the chain
  double h_paper_m = 0, h_motion_m = 0;
};
HostCrossingEstimate estimate_crossing_from_frames(const RotorParams& p, std::span<const UartFrame> frames,
                                                   std::span<const double> t_host_s, const HostTiming& t,
                                                   double c, double burst_s, double max_range_m);

}  // namespace ranging
