#include "model/dsp/quantize.hpp"

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

}  // namespace ranging
