#pragma once
// Coefficient quantization, shared by the filter report, the fixed-point cascade and the
// hardware generator, so that every consumer sees the same integers.
//
// A coefficient c is stored as the signed integer round(c * 2^frac) in `bits` bits
// (two's complement). Rounding is to nearest, ties away from zero. A value that does not
// fit in [-2^(bits-1), 2^(bits-1) - 1] is refused with an InputError naming `field`:
// coefficients never saturate silently.
//
// The ADC model, the one quantizer of every analog sample (the receiver, the simulators and
// BandpassFixed::execute(double) all call it): x in full-scale units -> the signed `bits`
// integer round_half_up(x * 2^(bits-1)), saturated to [-2^(bits-1), 2^(bits-1) - 1] and each
// saturation counted in *counter (when not null). InputError when x is not finite.
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>
#include <string>

#include "model/dsp/fixed_point.hpp"

namespace ranging {

std::int64_t quantize_input(double x, int bits, OverflowCounter* counter);

// std::round (to nearest, ties away from zero) without the libm call: for |v| < 2^52 the
// integer part i = trunc(v) (one conversion) and v - i are exact, so i +- 1 on |v - i| >= 1/2
// is the same result bit for bit; anything else (|v| >= 2^52 is integral, NaN, inf) goes to
// std::round. tests/test_block_api.cpp compares the two.
inline double round_half_away(double v) {
  if (!(std::abs(v) < 4503599627370496.0)) return std::round(v);
  const auto i = static_cast<std::int64_t>(v);
  const double frac = v - static_cast<double>(i);
  const double r = static_cast<double>(i + (frac >= 0.5) - (frac <= -0.5));
  return r == 0.0 ? std::copysign(0.0, v) : r;  // std::round keeps the sign of a zero
}
// quantize_input on a block, as the receivers' callers quantize their input: out[i] =
// quantize_input(clamp(x[i] * gain, -1, 1), bits, &counter), and index0 + i appended to
// *clamped (when not null) where |x[i] * gain| > 1, in order. The same values, counts and
// list as that loop, bit for bit (tests/test_block_api.cpp); a NaN x[i] * gain throws
// quantize_input's InputError with out[0, i) written, as the loop does (an infinity is
// clamped). On a CPU with AVX-512 (F, DQ), eight samples at a time: the product,
// floor(v 2^(bits-1+20)) in one conversion rounding down, the int64 path's rounding and
// saturation; a group of eight with a sample beyond +-1 or NaN, a CPU without AVX-512 and any
// bits outside 2..40 run the loop itself.
void quantize_input_block(std::span<const double> x, double gain, int bits, std::int64_t* out,
                          OverflowCounter& counter, std::vector<std::size_t>* clamped, std::size_t index0 = 0);

// The same function through a 128-bit intermediate for every argument (the reference that
// quantize_input's int64 path is tested against: tests/test_quantize.cpp).
std::int64_t quantize_input_wide(double x, int bits, OverflowCounter* counter);

std::int64_t quantize_coefficient(double value, int bits, int frac, const std::string& field);

}  // namespace ranging
