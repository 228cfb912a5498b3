#pragma once
// Errors of the golden model. An InputError is the user's fault (a bad option, an
// impossible word length, a malformed file): the tool prints it and exits with status 2.
// Its message always names the field (option, key or file:line) and the valid range.
#include <stdexcept>
#include <string>

namespace ranging {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws InputError("<field>: <value> is out of range; valid range is [lo, hi]") unless
// lo <= value <= hi and value is finite.
void require_in_range(const std::string& field, double value, double lo, double hi);
void require_finite(const std::string& field, double value);

}  // namespace ranging
