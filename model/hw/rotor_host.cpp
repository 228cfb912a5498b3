#include "model/hw/rotor_host.hpp"

#include <cmath>
#include <stdexcept>

namespace ranging {

long frame_burst_index(const UartFrame& f, double t_host_s, const HostTiming& t) {
  if (f.code < 1 || f.code > t.codes || t.period_t <= 0) return -1;
  const double tof_s = f.tof_q8 / 256.0 / t.fs;
  const double k_est = (t_host_s - tof_s - t.latency_s) * t.fs / t.period_t;
  // k = (code - 1) + m eta, m nearest
  const double m = std::round((k_est - (f.code - 1)) / t.codes);
  return static_cast<long>(m) * t.codes + (f.code - 1);
}

HostCrossingEstimate estimate_crossing_from_frames(const RotorParams& p, std::span<const UartFrame> frames,
                                                   std::span<const double> t_host_s, const HostTiming& t,
                                                   double c, double burst_s, double max_range_m) {
  if (frames.size() != t_host_s.size()) throw std::logic_error("estimate_crossing_from_frames: one time per frame");
  std::vector<TofSample> m;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const auto& f = frames[i];
    if (f.flags != 0) continue;
    const double tof_s = f.tof_q8 / 256.0 / t.fs;
    if (!(tof_s > 0) || c * tof_s > max_range_m || f.score / 65536.0 < p.accept_score) continue;
    const long k = frame_burst_index(f, t_host_s[i], t);
    if (k < 0) continue;
    m.push_back({static_cast<double>(k) * t.period_t / t.fs, tof_s});
  }
  const double v_rel = (p.omega_u() + p.omega_l()) * p.r();
  HostCrossingEstimate e;
  e.samples = consistent_chain(m, c, v_rel, p.chain_tolerance_m);
  e.h_paper_m = estimate_h_paper(e.samples, c, v_rel);
  e.h_motion_m = estimate_h_motion(p, e.samples, c, burst_s);
  return e;
}

}  // namespace ranging
