#pragma once
// Coaxial rotor blade crossings (the paper's application, section 2.1; docs/results/blade-crossing.md).
//
// Geometry (`geometry.type: rotor`, docs/scenes.md). Two counter-rotating rotors about the z
// axis: the upper one (transmitters, plane z = h) turns at +Omega_u = 2 pi rpm/60, the lower one
// (receivers, plane z = 0) at -Omega_l. The transducers sit at r = transducer_radius_fraction * R
// on the blades, the TX looking down (-z), the RX up (+z). One transmitter (upper blade 1) meets
// the receivers of the lower blades in turn: crossing i (0-based) happens at
//     t_i = t_first + i * Delta,   Delta = 2 pi / (blades (Omega_u + Omega_l)),  t_first = Delta/2
// at the azimuth psi_i = Omega_u t_i, with the vertical separation
//     h_i = h_m[i mod |h_m|] + blade_offsets_m[i mod blades] + flap_amplitude_m cos(psi_i - flap_phase)
// (per-blade offsets: lower blade i mod blades; flapping: a first-harmonic function of the azimuth).
//     TX(t) = (r cos(Omega_u t), r sin(Omega_u t), h_i)
//     RX(t) = (r cos(psi_i - Omega_l (t - t_i)), r sin(psi_i - Omega_l (t - t_i)), 0)
// h_i is the distance of closest approach (both at radius r). An optional uniform wind moves
// the air (model/sim/moving_channel.hpp).
//
// Measurement. The scheduler emits burst k at k T (T = excitation.schedule.period_s rounded to a
// sample) with code (k mod eta) + 1 (rtl/tx_scheduler.v), continuously; only the bursts emitted
// while the line of sight is within window_angle_deg of the vertical are rendered (outside it
// the two piston patterns are below -60 dB for the default beam). The received stream of a
// crossing goes through the scene's receiver (SceneSimulator::receive_stream: calibrated latency,
// ToF against the latest send of the decoded code).
//
// Estimators (per crossing, from the receiver's measurements with c ToF <= max_range_m and
// rho^2 >= accept_score, on the longest consistent chain, consistent_chain()):
// - paper: the shortest two distances d_m, d_n (c ToF), s = (v_u + v_l) |t_m - t_n| with the
//   tip speeds v = Omega r and the emission times, eq. 1 with the erratum (Heron);
// - motion-aware: least squares over all measurements of
//     | RX(t_e + ToF) - TX(t_e) - u ToF | = c ToF,   t_e = t_k + T_b/2
//   for (h, t_c) (the lower rotor's phase is the other unknown), Gauss-Newton. t_e is the burst
//   centre: the correlation peak of a time-compressed burst aligns its centre (first-order
//   Doppler bias of the start's ToF: (1 - kappa) T_b / 2).
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "model/sim/moving_channel.hpp"

namespace ranging {

namespace yaml {
class Reader;
}
struct Scene;
class SceneSimulator;

struct RotorParams {
  double radius_m = 4.244;                 // R: 200 m/s blade tip at 450 RPM
  double rpm = 450;                        // upper rotor
  double rpm_lower = 0;                    // 0: the same as rpm
  int blades = 4;
  double transducer_radius_fraction = 0.85;  // or transducer_radius_m
  std::vector<double> h_m{0.1};            // vertical separation, cycled over crossings
  std::vector<double> blade_offsets_m;     // + per lower blade (i mod blades), default none
  double flap_amplitude_m = 0;             // + a cos(psi - phase)
  double flap_phase_deg = 0;
  Vec3 wind_mps{0, 0, 0};
  int crossings = 8;
  double window_angle_deg = 50;            // rendered bursts: line of sight within this of vertical
  double accept_score = 0.75;              // estimators use detections with receiver rho^2 >= this
  double chain_tolerance_m = 0.005;        // ... forming the longest physically consistent chain

  double omega_u() const;                  // rad/s
  double omega_l() const;
  double r() const { return transducer_radius_fraction * radius_m; }
  double crossing_interval_s() const;      // Delta
  double crossing_time_s(int i) const;     // t_i
  double h_of(int i) const;                // h_i
};

// Reads geometry keys of a rotor scene (type already read); c for the tip-speed check.
// InputError naming file:line:key for impossible geometry (transducer radius above the rotor
// radius, rpm <= 0, h <= 0 at any crossing, tip speed + wind >= c).
void parse_rotor(yaml::Reader& r, RotorParams& p, double c);

// The paper's measurable window in the static picture (section 2.1, Figure 5): B at depth d
// under A inside both -3 dB cones of half-angle alpha: w(d) = 2 d tan(alpha); the required
// measurement rate for two measurements 2 v_rel / w.
// Scene-level checks of a rotor scene after parsing (InputError naming the key): a periodic
// schedule with period_s, one family, no codes subset (the scheduler cycles them all);
// max_range_m defaults to the longest line of sight in the rendered window.
void check_rotor_scene(Scene& s);

double static_window_m(double d, double half_angle_deg);

// Kinematics of crossing i; h and t_c free (the estimator's unknowns; the truth is h_of(i), t_i).
Trajectory rotor_tx(const RotorParams& p, double h);
Trajectory rotor_rx(const RotorParams& p, double t_c);

struct TofSample {
  double t_emit_s = 0;   // start of the burst's emission
  double tof_s = 0;      // measured
};
// Paper's estimator; NaN if fewer than two samples or the shortest two are not a triangle.
double estimate_h_paper(const std::vector<TofSample>& m, double c, double v_rel);
// Motion-aware estimator (see above); NaN if fewer than two samples or no convergence.
// burst_s: the burst duration T_b. t_c0: a start for the crossing time.
double estimate_h_motion(const RotorParams& p, const std::vector<TofSample>& m, double c, double burst_s,
                         double* t_c_out = nullptr);

// The system-side gate of the estimators: the longest chain of measurements (by emission time)
// whose successive distances change by at most v_rel |dt| + tolerance (the slant distance
// cannot change faster than the relative tip speed); misdecodes assign a burst of another code
// and land at arbitrary distances, off the chain.
std::vector<TofSample> consistent_chain(std::vector<TofSample> m, double c, double v_rel, double tolerance_m);

struct RotorMeasurement {
  int crossing = 0, burst = -1;            // burst: the true burst matched (-1: none)
  int code = 0;
  bool correct = false;                    // matched burst carried the decoded code
  double t_emit_s = 0, tof_s = 0, distance_m = 0, score = 0;
  double true_tof_start_s = 0;             // flight time of the matched burst's start
  double true_tof_centre_s = 0;            // ... of its centre (emission t_k + T_b/2)
};
struct RotorBurst {
  int crossing = 0, burst = 0, code = 0;
  double t_emit_s = 0, t_rel_s = 0;        // emission start; relative to the crossing time
  double angle_deg = 0;                    // air-frame line of sight from vertical at the burst centre
  double doppler = 1;                      // received / emitted frequency at the burst centre
  double los_speed_mps = 0;                // c (1 - 1/doppler): closing speed equivalent
  double amplitude_rel = 0;                // received amplitude / on-axis static amplitude at h
  bool decoded = false;                    // a correct detection matched it
  double tof_error_start_m = std::numeric_limits<double>::quiet_NaN();   // c (ToF - true start)
  double tof_error_centre_m = std::numeric_limits<double>::quiet_NaN();  // c (ToF - true centre)
};
struct RotorCrossing {
  int index = 0;
  double t_s = 0, h_true_m = 0;
  double h_est_m = std::numeric_limits<double>::quiet_NaN();
  double h_est_paper_m = std::numeric_limits<double>::quiet_NaN();
  int measurements = 0;                    // accepted by the estimators
  std::vector<RotorMeasurement> list;
};
struct RotorRun {
  std::string family;
  double period_s = 0, burst_s = 0, v_rel = 0;
  std::vector<RotorCrossing> crossings;
  std::vector<RotorBurst> bursts;
  std::size_t misdecodes = 0, false_alarms = 0;
  std::uint64_t overflows = 0;
  std::uint64_t adc_clipped = 0;  // received samples the scene's ADC clipped (every crossing)
};

// Doppler at a constant line-of-sight speed: the TX fixed at height d, the RX moving along the
// common axis at v_los (> 0 closing), reaching z = 0 when the burst's centre arrives; both on
// axis (no directivity loss), the scene's transducers, absorption, noise, ADC and receiver.
// Burst k = 0..eta*repeats-1 is emitted alone at k T (code (k mod eta) + 1), one stream each.
struct DopplerPoint {
  double los_speed_mps = 0, doppler = 1;   // received / emitted frequency
  int bursts = 0, decoded = 0, misdecoded = 0, missed = 0;
  std::uint64_t adc_clipped = 0;           // received samples the scene's ADC clipped
  double bias_start_m = std::numeric_limits<double>::quiet_NaN();   // mean c (ToF - true start) over decoded
  double bias_centre_m = std::numeric_limits<double>::quiet_NaN();  // ... against the centre's flight time
  double std_m = std::numeric_limits<double>::quiet_NaN();          // spread of c ToF
};
DopplerPoint doppler_point(SceneSimulator& sim, double d, double v_los, int repeats);

RotorRun run_rotor(SceneSimulator& sim, const std::function<void()>& tick = {});
std::size_t rotor_crossings(const Scene& s);

}  // namespace ranging
