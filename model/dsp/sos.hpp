#pragma once
// Second-order sections: the one representation of an IIR filter shared by the filter
// designer (filter_design.hpp), the float and fixed-point cascades (bandpass_filter.hpp)
// and the hardware generator.
//
//   H_k(z) = (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2),   H(z) = prod_k H_k(z)
//
// The overall gain is folded into the sections (no separate gain term).
#include <complex>
#include <string>
#include <vector>

namespace ranging {

struct Biquad {
  double b0 = 1, b1 = 0, b2 = 0;
  double a1 = 0, a2 = 0;  // a0 = 1
};

enum class FilterType { Butterworth, Chebyshev1, Elliptic };

struct SosFilter {
  FilterType type = FilterType::Butterworth;
  int order = 0;       // prototype (lowpass) order; a bandpass has 2*order poles
  double fs = 0;       // sample rate, Hz
  std::vector<Biquad> sections;
};

// Frequency response of the cascade at frequency f (Hz).
std::complex<double> sos_response(const SosFilter& filter, double f);

}  // namespace ranging
