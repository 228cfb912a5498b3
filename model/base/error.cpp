#include "model/base/error.hpp"

#include <cmath>
#include <sstream>

namespace ranging {

void require_finite(const std::string& field, double value) {
  if (!std::isfinite(value)) {
    throw InputError(field + ": value is not a finite number");
  }
}

void require_in_range(const std::string& field, double value, double lo, double hi) {
  if (!std::isfinite(value)) {
    std::ostringstream os;
    os << field << ": value is not a finite number; valid range is [" << lo << ", " << hi << "]";
    throw InputError(os.str());
  }
  if (value < lo || value > hi) {
    std::ostringstream os;
    os << field << ": " << value << " is out of range; valid range is [" << lo << ", " << hi << "]";
    throw InputError(os.str());
  }
}

}  // namespace ranging
