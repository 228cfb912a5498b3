#include "model/dsp/fixed_point.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "model/base/error.hpp"

namespace ranging {

namespace {

constexpr uint128_t kOne = 1;

// floor(raw / 2^k) adjusted by the rounding rule, for k >= 1. No signed overflow: the
// remainder is taken on the unsigned bit pattern and the quotient is at most 2^126.
int128_t shift_right_rounded(int128_t raw, long long k, Rounding rounding) {
  if (k >= 128) {
    // |raw / 2^k| <= 1/2: floor gives -1 for negatives; both round-to-nearest rules give 0
    // (the only tie, -1/2, goes up for RoundHalfUp and to the even 0 for Convergent).
    return (rounding == Rounding::Truncate && raw < 0) ? -1 : 0;
  }
  const int128_t q = raw >> k;  // arithmetic shift (C++20): floor
  if (rounding == Rounding::Truncate) return q;
  const uint128_t rem = static_cast<uint128_t>(raw) & ((kOne << k) - 1);
  const uint128_t half = kOne << (k - 1);
  if (rem > half) return q + 1;
  if (rem < half) return q;
  // Exact tie.
  if (rounding == Rounding::RoundHalfUp) return q + 1;
  return (q & 1) ? q + 1 : q;  // Convergent: to even
}

int128_t min_raw128(const FixedFormat& fmt) {
  return fmt.is_signed ? -static_cast<int128_t>(kOne << (fmt.width - 1)) : 0;
}
int128_t max_raw128(const FixedFormat& fmt) {
  return fmt.is_signed ? static_cast<int128_t>((kOne << (fmt.width - 1)) - 1)
                       : static_cast<int128_t>((kOne << fmt.width) - 1);
}

// The low `width` bits of a bit pattern, read as the format's (signed or unsigned) code.
std::int64_t wrap_bits(uint128_t bits, const FixedFormat& fmt) {
  std::uint64_t low = static_cast<std::uint64_t>(bits);
  if (fmt.width < 64) {
    const std::uint64_t mask = (std::uint64_t{1} << fmt.width) - 1;
    low &= mask;
    if (fmt.is_signed && ((low >> (fmt.width - 1)) & 1)) low |= ~mask;  // sign extension
  }
  return static_cast<std::int64_t>(low);  // modular conversion, well defined in C++20
}

void check_wide(int width, bool is_signed, const char* op) {
  const int limit = is_signed ? 128 : 127;
  if (width > limit) {
    std::ostringstream os;
    os << "fixed-point " << op << ": exact result needs " << width << " bits, more than the "
       << limit << " an int128 holds";
    throw std::overflow_error(os.str());
  }
}

// Integer bits of x when seen as a signed number (an unsigned word needs one more).
int signed_int_bits(const FixedWide& x) { return x.width - x.frac + (x.is_signed ? 0 : 1); }

// x.raw aligned to `frac` fraction bits (frac >= x.frac; the caller checked that it fits).
int128_t align(const FixedWide& x, int frac) {
  return static_cast<int128_t>(static_cast<uint128_t>(x.raw) << (frac - x.frac));
}

FixedWide add_sub(const FixedWide& a, const FixedWide& b, bool subtract) {
  FixedWide r;
  r.is_signed = subtract || a.is_signed || b.is_signed;
  r.frac = std::max(a.frac, b.frac);
  const int ia = r.is_signed ? signed_int_bits(a) : a.width - a.frac;
  const int ib = r.is_signed ? signed_int_bits(b) : b.width - b.frac;
  r.width = std::max(ia, ib) + 1 + r.frac;
  check_wide(r.width, r.is_signed, subtract ? "subtraction" : "addition");
  // Both aligned operands and the result fit the result width, so the modular (unsigned)
  // sum equals the exact one.
  const uint128_t x = static_cast<uint128_t>(align(a, r.frac));
  const uint128_t y = static_cast<uint128_t>(align(b, r.frac));
  r.raw = static_cast<int128_t>(subtract ? x - y : x + y);
  return r;
}

}  // namespace

void validate(const FixedFormat& fmt, const std::string& field) {
  const int max_width = fmt.is_signed ? 64 : 63;
  if (fmt.width >= 2 && fmt.width <= max_width && fmt.frac >= -kMaxFrac && fmt.frac <= kMaxFrac) {
    return;  // fast path: no strings built
  }
  require_in_range(field + (fmt.is_signed ? " width (signed)" : " width (unsigned)"), fmt.width, 2, max_width);
  require_in_range(field + " fraction bits", fmt.frac, -kMaxFrac, kMaxFrac);
}

std::int64_t fx_min_raw(const FixedFormat& fmt) { return static_cast<std::int64_t>(min_raw128(fmt)); }
std::int64_t fx_max_raw(const FixedFormat& fmt) { return static_cast<std::int64_t>(max_raw128(fmt)); }

std::int64_t fx_quantize(int128_t raw, int src_frac, const FixedFormat& fmt, OverflowCounter* counter) {
  const long long shift = static_cast<long long>(src_frac) - fmt.frac;
  int128_t q = raw;
  bool beyond = false;  // |exact result| >= 2^127: outside every format
  uint128_t bits = 0;   // low 128 bits of the exact result when beyond
  if (shift > 0) {
    q = shift_right_rounded(raw, shift, fmt.rounding);
  } else if (shift < 0 && raw != 0) {
    const long long s = -shift;
    if (s >= 128) {
      beyond = true;
      bits = 0;
    } else {
      bits = static_cast<uint128_t>(raw) << s;
      q = static_cast<int128_t>(bits);
      beyond = (q >> s) != raw;  // bits were lost off the top
    }
  }
  const int128_t lo = min_raw128(fmt);
  const int128_t hi = max_raw128(fmt);
  if (!beyond) {
    if (q >= lo && q <= hi) return static_cast<std::int64_t>(q);
    bits = static_cast<uint128_t>(q);
  }
  const bool negative = beyond ? raw < 0 : q < 0;
  if (fmt.overflow == Overflow::Saturate) {
    if (counter) ++counter->saturations;
    return static_cast<std::int64_t>(negative ? lo : hi);
  }
  if (counter) ++counter->wraps;
  return wrap_bits(bits, fmt);
}

FxRange fx_range(const FixedFormat& fmt) {
  return FxRange{fx_min_raw(fmt), fx_max_raw(fmt), fmt.width, fmt.is_signed};
}

std::int64_t fx_overflow_slow(std::int64_t q, const FxRange& r, Overflow o, OverflowCounter& counter) {
  if (o == Overflow::Saturate) {
    ++counter.saturations;
    return q < r.lo ? r.lo : r.hi;
  }
  ++counter.wraps;
  std::uint64_t low = static_cast<std::uint64_t>(q);
  if (r.width < 64) {
    const std::uint64_t mask = (std::uint64_t{1} << r.width) - 1;
    low &= mask;
    if (r.is_signed && ((low >> (r.width - 1)) & 1)) low |= ~mask;  // sign extension
  }
  return static_cast<std::int64_t>(low);
}

double FixedWide::to_double() const { return std::ldexp(static_cast<double>(raw), -frac); }

Fixed::Fixed(double value, const FixedFormat& fmt, OverflowCounter* counter) : fmt_(fmt) {
  validate(fmt, "fixed-point format");
  require_finite("fixed-point value", value);
  if (value == 0) return;
  // value = mant * 2^(e-53) exactly, mant a 53-bit integer.
  int e = 0;
  const double m = std::frexp(value, &e);
  const auto mant = static_cast<std::int64_t>(std::ldexp(m, 53));
  raw_ = fx_quantize(mant, 53 - e, fmt, counter);
}

Fixed Fixed::from_raw(std::int64_t raw, const FixedFormat& fmt) {
  validate(fmt, "fixed-point format");
  if (raw < fx_min_raw(fmt) || raw > fx_max_raw(fmt)) {
    std::ostringstream os;
    os << "fixed-point raw value " << raw << " does not fit the format; valid range is ["
       << fx_min_raw(fmt) << ", " << fx_max_raw(fmt) << "]";
    throw InputError(os.str());
  }
  Fixed x;
  x.raw_ = raw;
  x.fmt_ = fmt;
  return x;
}

double Fixed::to_double() const { return std::ldexp(static_cast<double>(raw_), -fmt_.frac); }

FixedWide Fixed::wide() const {
  FixedWide w;
  w.raw = raw_;
  w.width = fmt_.width;
  w.frac = fmt_.frac;
  w.is_signed = fmt_.is_signed;
  return w;
}

FixedWide operator+(const FixedWide& a, const FixedWide& b) { return add_sub(a, b, false); }
FixedWide operator-(const FixedWide& a, const FixedWide& b) { return add_sub(a, b, true); }

FixedWide operator*(const FixedWide& a, const FixedWide& b) {
  FixedWide r;
  r.is_signed = a.is_signed || b.is_signed;
  r.width = a.width + b.width;
  r.frac = a.frac + b.frac;
  check_wide(r.width, r.is_signed, "multiplication");
  // The exact product fits r.width <= 128 bits, so the modular product is exact.
  r.raw = static_cast<int128_t>(static_cast<uint128_t>(a.raw) * static_cast<uint128_t>(b.raw));
  return r;
}

Fixed fixed_cast(const FixedWide& x, const FixedFormat& fmt, OverflowCounter* counter) {
  validate(fmt, "fixed-point format");
  Fixed r;
  r.raw_ = fx_quantize(x.raw, x.frac, fmt, counter);  // in range by construction
  r.fmt_ = fmt;
  return r;
}

Fixed fixed_cast(const Fixed& x, const FixedFormat& fmt, OverflowCounter* counter) {
  return fixed_cast(x.wide(), fmt, counter);
}

}  // namespace ranging
