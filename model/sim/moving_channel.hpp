#pragma once
// Propagation between moving transducers (docs/signal-model.md, "Moving transducers").
//
// Emission time. The sound received at the receiver's position R(t_r) was emitted at the
// transmitter's position T(t_e), where t_e solves, with tau = t_r - t_e,
//     | R(t_r) - T(t_e) - u tau | = c tau                                    (1)
// u is a uniform wind (the air moves at u in the frame of R and T): in the air's frame the
// wave is a sphere of radius c tau centred on the emission point, which drifts with the air.
// With still air (u = 0) this is |R(t_r) - T(t_e)| = c (t_r - t_e). The left side of (1)
// minus the right is strictly increasing in t_e as long as |dT/dt - u| < c, so the root is
// unique; it is found by Newton's method from a guess (the previous sample's root), with a
// bisection fallback, to |residual| < 1e-13 s c.
//
// Received pressure for an emitted (TX-resonator output) waveform e(t):
//     y(t_r) = e(t_e) * g0 * (0.1 m / (c tau)) * D(x_tx) * D(x_rx) * A
// - spreading 1/d over the path in the air frame, d = c tau (0.1 m reference, like channel.hpp);
// - directivity of both transducers, the piston |2 J1(x)/x| with ka from the full -3 dB beam
//   angle at the carrier (ka sin(beam/2) = 1.6163). For a transducer moving at v relative to
//   the air, the array factor of its face at air-frame ray direction n (unit, TX -> RX) is that
//   of a static piston with the air-frame wavenumber k/(1 - n.v_tx/c) (the face's elements
//   emit at retarded times that differ by n.xi/(c - n.v_tx)); the receiver's face sums the
//   incoming air-frame wave, whose wavenumber is the same. So x = ka sin(theta)/(1 - n.v_tx/c)
//   at both ends, theta the air-frame angle between the ray and each transducer's axis.
//   The convective amplitude factor of a moving source and the directivity's frequency
//   dependence within the band are not modelled (within the -3 dB beam both are < 7 %).
// - A: air absorption at the carrier over c tau (a scalar; absent when not configured).
// The Doppler compression follows from (1): dt_e/dt_r = (1 - n.v_rx'/c)/(1 - n.v_tx'/c)
// (v' relative to the air); it varies within a burst because n and v change.
//
// Interpolation of e at t_e: the 64-tap Kaiser-windowed sinc of model/sim/channel.hpp
// (fractional_delay_taps, beta = 10), tabulated at 4096 fractional positions and used at the
// nearest one: the time is quantized to 1/8192 sample (24 ps at 5 MS/s, 8 nm of path at 340 m/s).
#include <array>
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

namespace ranging {

using Vec3 = std::array<double, 3>;

struct Trajectory {
  std::function<Vec3(double)> position;  // m, at time t (s)
  std::function<Vec3(double)> velocity;  // m/s
};

struct MovingLink {
  Trajectory tx, rx;
  double c = 340.0;                 // speed of sound in the air, m/s
  Vec3 wind{0, 0, 0};               // uniform air velocity, m/s
  double ka = 0;                    // piston ka at the carrier; 0: omnidirectional
  Vec3 tx_axis{0, 0, -1};           // unit axes (TX looks down, RX up)
  Vec3 rx_axis{0, 0, 1};
  double gain = 1.0;                // received/emitted amplitude on axis at 0.1 m, static
  double absorption_db_per_m = 0;   // at the carrier
};

// piston ka whose |2 J1(x)/x| is -3 dB at half the full beam angle.
double piston_ka(double beam_angle_deg);
// |2 J1(x)/x|, 1 at x = 0.
double piston_pattern(double x);

struct Ray {
  double t_e = 0;      // emission time
  double tau = 0;      // t_r - t_e
  Vec3 n{0, 0, 0};     // unit air-frame ray direction, TX -> RX
  double x_tx = 0;     // directivity argument at TX and RX (equal: see the header)
  double amplitude = 0;  // the factor multiplying e(t_e)
  double doppler = 1;  // dt_e/dt_r: received frequency / emitted frequency
};

// Root t_e of (1) for reception at t_r, starting from guess (any value; t_r - 1e-3 if unsure).
double emission_time(const MovingLink& link, double t_r, double guess);
// The reception time t_r of the sound emitted at t_e (the same equation solved for t_r).
double reception_time(const MovingLink& link, double t_e, double guess);
// Everything about the ray received at t_r.
Ray ray_at(const MovingLink& link, double t_r, double guess);

// e(t) = emitted[k] at t = (e0 + k)/fs (zero outside); returns y at t_r = (r0 + m)/fs,
// m = 0..n_out-1, before the receiving transducer. Also fills rays (one per output) if given.
std::vector<double> render_moving(const MovingLink& link, std::span<const double> emitted, long e0, long r0,
                                  std::size_t n_out, double fs, std::vector<Ray>* rays = nullptr);

// Band-limited value of x at fractional sample position p (x[k] at p = k; zero outside).
double interpolate(std::span<const double> x, double p);

}  // namespace ranging
