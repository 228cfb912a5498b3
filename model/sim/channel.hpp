#pragma once
// Simple pitch-catch channel for the demo and the tests:
//   y[k] = g * (0.1 m / d) * RX(TX(x))(k/fs - d/c) + w[k]
// x is the excitation sent at sample 0; TX and RX are resonant transducers
// (transducer.hpp); the propagation delay d/c is applied exactly by a 64-tap
// Kaiser-windowed-sinc fractional-delay interpolator (delay error < 1e-5 sample and gain
// error < 4e-6 from 100 kHz to 2 MHz at 5 MS/s, docs/signal-model.md); the gain follows
// spherical spreading 1/d from a 0.1 m reference; w is white Gaussian noise drawn from the
// seed (add_white_noise, model/sim/front_end.hpp).
// Absent in the model: absorption, multipath, turbulence, transducer directivity.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "model/dsp/transducer.hpp"

namespace ranging {

struct ChannelParams {
  double speed_of_sound = 340.0;  // m/s
  double distance_m = 0.5;
  double gain = 1.0;  // received amplitude at 0.1 m relative to excitation amplitude (after transducers)
  TransducerParams tx, rx;
  double noise_rms = 0.0;  // absolute, same units as the output signal; 0 = no noise stage
  std::uint64_t seed = 1;
};

inline constexpr double kReferenceDistance = 0.1;  // m: the distance at which the gain is `gain`
inline constexpr int kDelayTaps = 64;              // fractional-delay interpolator length

// InputError naming the field: speed_of_sound in [100, 10000], distance_m in [0.001, 1000],
// gain in [0, 1e9], noise_rms in [0, 1e9] (transducers are checked against fs in propagate).
void validate(const ChannelParams& p);

// The interpolator's taps for a fractional delay mu in [0, 1): tap i multiplies
// z[k - I - (i - (kDelayTaps/2 - 1))] (I = the integer delay), so the scene simulator applies
// the same delay as propagate() to signals it assembles itself.
std::vector<double> fractional_delay_taps(double mu);

// Received signal for `excitation` sent at sample 0, sampled at fs, n_out samples long;
// sample k is time k/fs and the true time of flight is distance_m/speed_of_sound exactly.
// The interpolator is non-causal by kDelayTaps/2 samples: its (tiny) pre-ringing can start
// up to 32 samples before the arrival. n_out <= 1e8.
std::vector<double> propagate(std::span<const double> excitation, const ChannelParams& p, double fs,
                              std::size_t n_out);

}  // namespace ranging
