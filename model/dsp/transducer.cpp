#include "model/dsp/transducer.hpp"

#include <cmath>
#include <numbers>

#include "model/base/error.hpp"

namespace ranging {

void validate(const TransducerParams& p, double fs) {
  require_in_range("fs", fs, 1.0, 1e10);
  if (p.bypass) return;
  // 0.45*fs keeps the resonance clear of Nyquist, where tan() prewarping blows up.
  require_in_range("transducer centre_hz", p.centre_hz, 1e-6 * fs, 0.45 * fs);
  require_in_range("transducer q", p.q, 0.1, 1000.0);
}

Transducer::Transducer(const TransducerParams& p, double fs) : bypass_(p.bypass) {
  validate(p, fs);
  if (bypass_) return;  // c_ stays the identity section
  // Bilinear transform with prewarp at w0: s = K (1 - z^-1)/(1 + z^-1), K = w0/tan(w0 T/2).
  // With the prewarp, H(s) maps to b = [a, 0, -a]/(1 + a), a = sin(wd)/(2Q), wd = 2*pi*f0/fs.
  const double wd = 2.0 * std::numbers::pi * p.centre_hz / fs;
  const double alpha = std::sin(wd) / (2.0 * p.q);
  const double a0 = 1.0 + alpha;
  c_.b0 = alpha / a0;
  c_.b1 = 0.0;
  c_.b2 = -alpha / a0;
  c_.a1 = -2.0 * std::cos(wd) / a0;
  c_.a2 = (1.0 - alpha) / a0;
}

double Transducer::execute(double x) {
  if (bypass_) return x;
  const double y = c_.b0 * x + s1_;
  s1_ = c_.b1 * x - c_.a1 * y + s2_;
  s2_ = c_.b2 * x - c_.a2 * y;
  return y;
}

void Transducer::reset() { s1_ = s2_ = 0.0; }

}  // namespace ranging
