#pragma once
// Coefficient quantization, shared by the filter report, the fixed-point cascade and the
// hardware generator, so that every consumer sees the same integers.
//
// A coefficient c is stored as the signed integer round(c * 2^frac) in `bits` bits
// (two's complement). Rounding is to nearest, ties away from zero. A value that does not
// fit in [-2^(bits-1), 2^(bits-1) - 1] is refused with an InputError naming `field`:
// coefficients never saturate silently.
#include <cstdint>
#include <string>

namespace ranging {

std::int64_t quantize_coefficient(double value, int bits, int frac, const std::string& field);

}  // namespace ranging
