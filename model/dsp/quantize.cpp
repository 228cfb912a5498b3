#include "model/dsp/quantize.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "model/base/error.hpp"

namespace ranging {

std::int64_t quantize_coefficient(double value, int bits, int frac, const std::string& field) {
  require_in_range(field + " word length (bits)", bits, 2, 62);
  require_in_range(field + " fraction bits", frac, 0, 62);
  require_finite(field, value);
  const double scaled = std::ldexp(value, frac);
  const double lo = -std::ldexp(1.0, bits - 1);
  const double hi = std::ldexp(1.0, bits - 1) - 1.0;
  const double q = std::round(scaled);  // ties away from zero
  if (!(q >= lo && q <= hi)) {
    std::ostringstream os;
    os.precision(17);
    os << field << ": coefficient " << value << " does not fit a signed " << bits << "-bit word with "
       << frac << " fraction bits; valid range is [" << std::ldexp(lo, -frac) << ", "
       << std::ldexp(hi, -frac) << "]";
    throw InputError(os.str());
  }
  return static_cast<std::int64_t>(q);
}

std::int64_t quantize_input(double x, int bits, OverflowCounter* counter) {
  const FixedFormat fmt{bits, bits - 1, true, Rounding::RoundHalfUp, Overflow::Saturate};
  if (!std::isfinite(x)) throw InputError("receiver input: sample is not finite");
  // x * 2^(bits-1) with 20 guard bits below the LSB, so the rounding sees the true fraction.
  const double scaled = std::ldexp(x, bits - 1 + 20);
  const double lim = std::ldexp(1.0, 100);
  const int128_t raw = static_cast<int128_t>(std::clamp(std::floor(scaled), -lim, lim));
  return fx_quantize(raw, bits - 1 + 20, fmt, counter);
}

}  // namespace ranging
