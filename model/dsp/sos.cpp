#include "model/dsp/sos.hpp"

#include <numbers>

namespace ranging {

std::complex<double> sos_response(const SosFilter& filter, double f) {
  const double w = 2.0 * std::numbers::pi * f / filter.fs;
  const std::complex<double> z1 = std::polar(1.0, -w);  // z^-1
  const std::complex<double> z2 = z1 * z1;
  std::complex<double> h = 1.0;
  for (const Biquad& s : filter.sections) {
    h *= (s.b0 + s.b1 * z1 + s.b2 * z2) / (1.0 + s.a1 * z1 + s.a2 * z2);
  }
  return h;
}

}  // namespace ranging
