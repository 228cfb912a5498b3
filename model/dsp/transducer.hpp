#pragma once
// Resonant ultrasonic transducer: one 2nd-order resonator (bandpass)
//   H(s) = (w0/Q) s / (s^2 + (w0/Q) s + w0^2),   w0 = 2*pi*centre_hz,
// discretized by the bilinear transform prewarped at the centre, so the digital gain is
// exactly 1 (phase 0) at centre_hz. Its -3 dB bandwidth is centre_hz/Q in the analog
// domain; the bilinear warping makes the digital one ~1.1% narrower at 200 kHz / 5 MS/s.
// A transmitter is one resonator, a receiver another (a pitch-catch pair is a cascade of
// two). bypass = true makes an ideal transducer (output = input), for tests of the channel.
#include "model/dsp/sos.hpp"

namespace ranging {

struct TransducerParams {
  double centre_hz = 200e3;
  double q = 7.5;        // calibrated against the paper's Table 5 T_d (docs/signal-model.md)
  bool bypass = false;   // ideal transducer: no resonance, unity gain at every frequency
};

// InputError unless 0 < centre_hz < 0.45*fs and 0.1 <= q <= 1000 (fs in [1, 1e10]).
void validate(const TransducerParams& p, double fs);

class Transducer {
 public:
  Transducer(const TransducerParams& p, double fs);  // validates
  double execute(double x);                          // one sample in, one sample out
  void reset();                                      // clear the state (at rest)
  const Biquad& coefficients() const { return c_; }  // b2 = -b0, b1 = 0; identity when bypassed

 private:
  Biquad c_;
  bool bypass_;
  double s1_ = 0, s2_ = 0;  // transposed direct form II state
};

}  // namespace ranging
