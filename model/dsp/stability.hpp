#pragma once
// The guard on the quantized bandpass design (issue 12): what the integer coefficients the
// hardware runs actually implement, checked against the spec before anything uses them.
//
// A section's coefficients are integers q = round(c * 2^F) (quantize.hpp, F = coef_frac).
// Everything here is a pure function of those integers, F and the spec:
//   * poles, exactly: z^2 + (A1/2^F) z + A2/2^F = 0, discriminant D = A1^2 - 4 A2 2^F (an
//     exact int128). D < 0: a conjugate pair of radius sqrt(A2/2^F); D >= 0: real poles
//     (-A1 +- sqrt(D)) / 2^(F+1). The verdict "stable" is the exact integer Jury test
//     |A2| < 2^F and |A1| < 2^F + A2 (both poles strictly inside the unit circle); the
//     radius itself is reported in long double.
//   * response of the quantized cascade: attenuation -20 log10 |H(f)| at the spec edges
//     fp1, fp2, fs1, fs2 and the worst over a grid of each band (257 points per band,
//     edges included): passband [fp1, fp2], stopbands (0, fs1] and [fs2, fs/2];
//   * worst-case (L1) gain ||h_k||_1 from the input to every section output k, by simulation
//     of the impulse response (long double) until it decays by 1e-15; +inf if unstable.
// Verdict: stable, and within spec with a tolerance of kSpecToleranceDb:
//   worst passband attenuation <= rp_db + tol,  worst stopband attenuation >= rs_db - tol.
// The same checks run on the unquantized (double) design, so a failure is blamed on the
// right key: the float design itself (filter.order / filter.*) or the coefficient words
// (bandpass_fixed.coef_bits / coef_frac).
#include <complex>
#include <cstdint>
#include <string>
#include <vector>

#include "model/dsp/bandpass_filter.hpp"
#include "model/dsp/filter_design.hpp"
#include "model/dsp/sos.hpp"

namespace ranging {

struct ReceiverConfig;
struct ReceiverDesign;

constexpr double kSpecToleranceDb = 0.5;

// Integer coefficients {b0, b1, b2, a1, a2} per section, value = q * 2^-frac.
struct QuantizedSos {
  std::vector<std::vector<std::int64_t>> sections;
  int frac = 0;
};

// quantize_coefficient on every coefficient (InputError naming `field` + " section k b0" etc.
// if one does not fit in `bits`).
QuantizedSos quantize_sos(const SosFilter& filter, int bits, int frac, const std::string& field);
// The real-valued filter the integers implement.
SosFilter quantized_sos_filter(const QuantizedSos& q, const SosFilter& like);

struct SectionPoles {
  std::complex<long double> p1, p2;  // p1 has the larger magnitude
  long double radius = 0;            // max |p|
  bool complex_pair = false;         // D < 0
  bool stable = false;               // exact integer Jury test
};
// Poles of 1 + (a1/2^frac) z^-1 + (a2/2^frac) z^-2, a1 and a2 integers, frac 0..62.
SectionPoles quantized_section_poles(std::int64_t a1, std::int64_t a2, int frac);

struct EdgeAttenuation {
  std::string name;  // "fp1", "fp2", "fs1", "fs2"
  double f = 0;      // Hz
  double float_db = 0, quantized_db = 0;
};

struct BandCheck {  // worst over the band grid
  double float_db = 0, float_f = 0;
  double quantized_db = 0, quantized_f = 0;
};

struct DesignGuard {
  BandpassSpec spec;
  double tolerance_db = kSpecToleranceDb;
  int coef_bits = 0, coef_frac = 0;
  std::vector<double> float_radius;            // per section, the double design
  std::vector<SectionPoles> quantized_poles;   // per section, exact
  std::vector<EdgeAttenuation> edges;          // fs1, fp1, fp2, fs2
  BandCheck passband;                          // largest attenuation in [fp1, fp2]
  BandCheck stopband;                          // smallest attenuation in the stopbands
  std::vector<double> l1_gain;                 // per node, quantized, input -> section k output
  bool float_stable = false, float_within_spec = false;
  bool stable = false, within_spec = false;    // the quantized design
  std::vector<std::string> float_failures;     // what the float design misses
  std::vector<std::string> failures;           // what the quantized design misses, e.g.
                                               // "section 5 quantized pole radius 1.000 >= 1"
  bool ok() const { return stable && within_spec; }
  double max_quantized_radius() const;
};

// The check itself (pure): the float design and its quantized integers against the spec.
DesignGuard check_quantized_design(const SosFilter& filter, const QuantizedSos& q, const BandpassSpec& spec,
                                   int coef_bits, double tolerance_db = kSpecToleranceDb);
// The receiver's bandpass: designs the filter of cfg (cheap: no templates) and checks it with
// cfg.bandpass.coef_bits / coef_frac. Throws InputError for a configuration that cannot even
// be quantized (as validate does).
DesignGuard check_quantized_design(const ReceiverConfig& cfg);
DesignGuard check_quantized_design(const ReceiverDesign& design);

// "KEY: VALUE: failure; failure" naming the configuration key to blame: filter.order (the
// float design misses the spec at that order) or bandpass_fixed.coef_bits (quantization).
// Empty if the guard passes.
std::string guard_message(const DesignGuard& g, int filter_order);

// The one entry point every configuration path calls (design_receiver, scene loading):
// throws InputError(guard_message + a hint) unless the guard passes or
// cfg.allow_out_of_spec is set.
void enforce_quantized_design(const ReceiverConfig& cfg);
void enforce_quantized_design(const DesignGuard& g, const ReceiverConfig& cfg);

// ------------------------------------------------------------------ filter structures
// The same design as one high-order recursion (direct form, study only: the receiver and the
// hardware implement the SOS cascade):
//   H(z) = (sum_k b_k z^-k) / (sum_k a_k z^-k),  a_0 = 1, degree 2 * order,
// the products of the sections' polynomials, expanded in long double. Quantized with B bits
// per polynomial in block floating point: each polynomial gets the most fraction bits that let
// its largest coefficient fit B signed bits (the numerator's gain ~1e-5 would vanish otherwise).
// Poles: the roots of the quantized denominator (polynomial_roots); "stable" = all radii
// < 1 - 1e-9 (a root finder, accurate to ~1e-10 here; not an exact test like the SOS one).
enum class FilterStructure { Sos, Direct };
FilterStructure parse_filter_structure(const std::string& name);  // "sos" | "direct"
std::string filter_structure_name(FilterStructure s);

struct DirectForm {
  std::vector<long double> b, a;  // a[0] = 1
};
DirectForm direct_form(const SosFilter& filter);

// Roots of c[0] z^n + c[1] z^(n-1) + ... + c[n] (c[0] != 0), Aberth-Ehrlich iteration in long
// double from points on the circle of the roots' geometric mean radius, until every
// correction is below 1e-9 relative (clustered roots limit the accuracy to about that).
// Throws InputError if c[0] == 0 or the iteration does not converge.
std::vector<std::complex<long double>> polynomial_roots(const std::vector<long double>& c);

struct StructurePoint {   // one structure and coefficient word length
  int bits = 0;
  int frac_a = 0, frac_b = 0;  // fraction bits of the denominator and numerator words
  double max_radius = 0;       // quantized poles
  bool stable = false, within_spec = false;
  double passband_db = 0, stopband_db = 0;  // worst over the band grids (quantized)
  bool ok() const { return stable && within_spec; }
};
// SOS: coef_frac = bits - 2 (a1 in [-2, 2)), exact poles; direct: block floating point.
// Throws InputError if bits is outside 3..60.
StructurePoint evaluate_structure(const SosFilter& filter, const BandpassSpec& spec, FilterStructure s, int bits,
                                  double tolerance_db = kSpecToleranceDb);
// Smallest bits in 3..max_bits with ok(), or -1. Quantization error is not monotonic in the
// word length: with every_wider, the smallest B such that every width B..max_bits is ok.
int minimum_coefficient_bits(const SosFilter& filter, const BandpassSpec& spec, FilterStructure s, int max_bits = 60,
                             bool every_wider = false);

// ------------------------------------------------------------------ limit cycles
// Zero-input behaviour of the bit-accurate cascade (BandpassFixed, its public API): an
// excitation of `length` samples, then zeros for `settle` samples (default: twice the
// float response's decay to LSB/2 plus 2000, as docs/fixed-point.md), then `observe` more
// samples in which the output's steady state is measured:
//   amplitude_lsb = max |y| (data LSB) over the observation window;
//   period        = smallest p such that y[n + p] = y[n] over the window (1 for a constant,
//                   e.g. 0: the filter came to rest); 0 if it does not repeat within observe/2.
enum class Excitation { Impulse, Step, WorstCase, Random };
std::string excitation_name(Excitation e);  // "impulse", "step", "worst-case", "random"

struct LimitCycle {
  double amplitude_lsb = 0;
  int period = 0;
  std::uint64_t overflows = 0;  // section-output overflow events during the whole run
};
// Full-scale excitations of the input word: impulse -2^(B-1) at n = 0; step of -2^(B-1) for
// `length` samples; worst case = the full-scale sign sequence of the float cascade's time-
// reversed impulse response (the L1 input of the output node); random = uniform codes (seed).
std::vector<std::int64_t> excitation_codes(Excitation e, const SosFilter& quantized, int input_bits, int length,
                                           std::uint64_t seed = 1);
LimitCycle measure_limit_cycle(const SosFilter& filter, const BandpassFixedConfig& cfg,
                               const std::vector<std::int64_t>& excitation, int settle = -1, int observe = 4096);

}  // namespace ranging
