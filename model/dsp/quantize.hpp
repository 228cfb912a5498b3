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
#include <cstdint>
#include <string>

#include "model/dsp/fixed_point.hpp"

namespace ranging {

std::int64_t quantize_input(double x, int bits, OverflowCounter* counter);
// The same function through a 128-bit intermediate for every argument (the reference that
// quantize_input's int64 path is tested against: tests/test_quantize.cpp).
std::int64_t quantize_input_wide(double x, int bits, OverflowCounter* counter);

std::int64_t quantize_coefficient(double value, int bits, int frac, const std::string& field);

}  // namespace ranging
