#pragma once
// Bandpass IIR filter designer of the golden model (paper section 3.3.1: passband
// 150-250 kHz, stopbands 50 / 350 kHz, Rp = 2 dB, Rs = 30 dB, fs = 5 MS/s).
//
// Route (the classic MATLAB / scipy one): minimum order and natural frequencies exactly as
// scipy.signal.buttord / cheb1ord / ellipord (analog=False); analog lowpass prototype
// (Butterworth, Chebyshev I, elliptic) -> lowpass-to-bandpass -> bilinear transform with
// prewarping -> second-order sections. The sections are built for fixed point:
//   * pairing: each conjugate pole pair, starting with the one closest to the unit circle,
//     takes the nearest remaining zero pair; a Butterworth / Chebyshev section always gets one
//     zero at z = +1 and one at z = -1, so its numerator is g*[1, 0, -1] with b1 exactly 0;
//   * ordering: ascending pole radius, the highest-Q section last (MATLAB zp2sos 'up');
//   * scaling: L-infinity -- the cumulative response from the input to the output of every
//     section but the last has peak |H| = 1; the last section carries what is left.
// See docs/filter-design.md for the reasoning and the paper spec's result.
#include <complex>
#include <string>
#include <string_view>
#include <vector>

#include "model/dsp/sos.hpp"

namespace ranging {

struct BandpassSpec {                  // defaults = the paper's spec (section 3.3.1)
  double fp1 = 150e3, fp2 = 250e3;     // passband edges, Hz
  double fs1 = 50e3, fs2 = 350e3;      // stopband edges, Hz
  double rp_db = 2.0;                  // max passband attenuation, dB
  double rs_db = 30.0;                 // min stopband attenuation, dB
  double fs = 5e6;                     // sample rate, Hz
};

// Throws InputError naming the field unless 0 < fs1 < fp1 < fp2 < fs2 < fs/2,
// 0 < rp_db < rs_db and everything is finite.
void validate(const BandpassSpec& spec);

// Minimum prototype (lowpass) order meeting the spec; same as scipy's *ord functions.
int minimum_order(const BandpassSpec& spec, FilterType type);

constexpr int kMaxFilterOrder = 20;

// Design at the minimum order, or at a given prototype order (1..kMaxFilterOrder).
// At a given order the natural frequencies follow the same rule as at minimum order
// (Butterworth: exactly rp_db at fp1 and fp2; Chebyshev I / elliptic: the passband edges).
SosFilter design_bandpass(const BandpassSpec& spec, FilterType type);
SosFilter design_bandpass(const BandpassSpec& spec, FilterType type, int order);

// The same design as zeros, poles and gain of the digital filter, before sectioning:
//   H(z) = k * prod(1 - z_i z^-1) / prod(1 - p_i z^-1)
struct Zpk {
  std::vector<std::complex<double>> z, p;
  double k = 1;
};
Zpk design_bandpass_zpk(const BandpassSpec& spec, FilterType type, int order);
std::complex<double> zpk_response(const Zpk& zpk, double f, double fs);

// Natural (critical) frequencies in Hz of the digital design, as scipy's *ord return them.
std::vector<double> natural_frequencies(const BandpassSpec& spec, FilterType type, int order);

FilterType parse_filter_type(std::string_view name);  // "butter" | "cheby1" | "ellip"
std::string filter_type_name(FilterType type);        // "butter" | "cheby1" | "ellip"

double pole_radius(const Biquad& section);  // max |pole| of the section

// Attenuation -20*log10|H(f)| in dB (+inf at an exact zero).
double attenuation_db(const SosFilter& filter, double f);

// The Kaiser window at r in [-1, 1] (1 at r = 0): I0(beta sqrt(1 - r^2)) / I0(beta), I0 by its
// power series (the channel's fractional delay and the medium's absorption FIR taper with it).
double kaiser_window(double r, double beta);

}  // namespace ranging
