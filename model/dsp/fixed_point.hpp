#pragma once
// Bit-accurate fixed-point arithmetic of the golden model: the rules the generated hardware
// implements, proven bit for bit against SystemC's sc_fix / sc_fixed
// (tests/test_fixed_point_vs_systemc.cpp). See docs/fixed-point.md.
//
// A format is runtime configuration (word lengths are swept by later tools):
//   value = raw * 2^-frac,  raw a two's complement (or unsigned) integer of `width` bits.
// Arithmetic is exact: +, -, * return a FixedWide whose format grows so that no bit is lost
// (add/sub: max integer bits + 1, mul: sum of widths). The only place where bits are dropped
// is fixed_cast / fx_quantize, which applies the target format's rounding (on the dropped
// fraction bits) and then its overflow rule (on the dropped integer bits), exactly like a
// SystemC cast: quantize first, then overflow.
#include <cstdint>
#include <string>

namespace ranging {

// GCC/Clang extension; the exact products of two 64-bit words need it.
__extension__ typedef __int128 int128_t;
__extension__ typedef unsigned __int128 uint128_t;
static_assert(sizeof(int128_t) == 16, "ranging needs a compiler with __int128 (GCC or Clang)");

enum class Rounding {
  Truncate,     // floor toward -inf: drop the bits (SystemC SC_TRN)
  RoundHalfUp,  // add half an LSB, then floor: ties toward +inf (SC_RND)
  Convergent,   // round to nearest, ties to even (SC_RND_CONV)
};
enum class Overflow {
  Wrap,      // keep the low `width` bits (SC_WRAP)
  Saturate,  // clamp to the most negative / most positive code (SC_SAT)
};

struct FixedFormat {
  int width = 16;  // 2..64 signed, 2..63 unsigned (the raw value is held in an int64)
  int frac = 15;   // may be negative or larger than width; |frac| <= kMaxFrac
  bool is_signed = true;
  Rounding rounding = Rounding::Truncate;
  Overflow overflow = Overflow::Wrap;
};

constexpr int kMaxFrac = 1024;

// Throws InputError naming `field` and the valid range unless the format is representable.
void validate(const FixedFormat& fmt, const std::string& field);

// Smallest and largest raw code of a format.
std::int64_t fx_min_raw(const FixedFormat& fmt);
std::int64_t fx_max_raw(const FixedFormat& fmt);

// Overflow events are counted, never hidden. A counter may be shared by many casts.
struct OverflowCounter {
  std::uint64_t saturations = 0;
  std::uint64_t wraps = 0;
  std::uint64_t total() const { return saturations + wraps; }
  OverflowCounter& operator+=(const OverflowCounter& o) {
    saturations += o.saturations;
    wraps += o.wraps;
    return *this;
  }
  friend OverflowCounter operator+(OverflowCounter a, const OverflowCounter& b) { return a += b; }
};

// Quantize raw * 2^-src_frac into fmt: round away the surplus fraction bits by fmt.rounding,
// then bring the result into fmt's range by fmt.overflow, counting an overflow event in
// *counter (may be null). src_frac may be any int (negative = integer bits below the LSB).
// The format is not validated here (hot path); validate it once beforehand.
std::int64_t fx_quantize(int128_t raw, int src_frac, const FixedFormat& fmt, OverflowCounter* counter);

// ---- Hot-loop quantizer ---------------------------------------------------------------------
// fx_quantize specialized at compile time for the model's inner loops: the rounding rule R and
// the overflow rule O are template parameters, the source is an int64 and the shift is
// 0 <= shift <= 62 (bits dropped, src_frac - fmt.frac). Every stage that calls it proves its
// int64 bound where it does (bandpass: acc_bits <= 64 by validate(); correlator: the layout's
// widths are <= 62 bits). Same result and the same overflow count as fx_quantize for those
// arguments (tests/test_block_api.cpp compares the two on every mode).
struct FxRange {  // a format's range, resolved once
  std::int64_t lo = 0, hi = 0;
  int width = 2;
  bool is_signed = true;
};
FxRange fx_range(const FixedFormat& fmt);

// floor(raw / 2^shift) adjusted by R (shift = 0: raw). No overflow: |q| <= 2^(63 - shift).
template <Rounding R>
inline std::int64_t fx_round_shift(std::int64_t raw, int shift) {
  if (shift == 0) return raw;
  const std::int64_t q = raw >> shift;  // arithmetic shift (C++20): floor
  if constexpr (R == Rounding::Truncate) {
    return q;
  } else if constexpr (R == Rounding::RoundHalfUp) {
    return q + ((raw >> (shift - 1)) & 1);  // the first dropped bit: remainder >= half
  } else {
    const std::uint64_t rem = static_cast<std::uint64_t>(raw) & ((std::uint64_t{1} << shift) - 1);
    const std::uint64_t half = std::uint64_t{1} << (shift - 1);
    return q + static_cast<std::int64_t>(rem > half || (rem == half && (q & 1)));  // ties to even
  }
}

// The out-of-range branch: saturate or wrap into r, counted (never inlined: it is rare).
std::int64_t fx_overflow_slow(std::int64_t q, const FxRange& r, Overflow o, OverflowCounter& counter);

template <Rounding R, Overflow O>
inline std::int64_t fx_quantize_fast(std::int64_t raw, int shift, const FxRange& r, OverflowCounter& counter) {
  const std::int64_t q = fx_round_shift<R>(raw, shift);
  if (q < r.lo || q > r.hi) [[unlikely]] return fx_overflow_slow(q, r, O, counter);
  return q;
}

// Calls f.template operator()<R, O>() with the format's rules as compile-time constants: the
// one run-time switch per block instead of per sample.
template <class F>
decltype(auto) fx_dispatch(Rounding rounding, Overflow overflow, F&& f) {
  const bool sat = overflow == Overflow::Saturate;
  switch (rounding) {
    case Rounding::Truncate:
      return sat ? f.template operator()<Rounding::Truncate, Overflow::Saturate>()
                 : f.template operator()<Rounding::Truncate, Overflow::Wrap>();
    case Rounding::RoundHalfUp:
      return sat ? f.template operator()<Rounding::RoundHalfUp, Overflow::Saturate>()
                 : f.template operator()<Rounding::RoundHalfUp, Overflow::Wrap>();
    case Rounding::Convergent:
    default:
      return sat ? f.template operator()<Rounding::Convergent, Overflow::Saturate>()
                 : f.template operator()<Rounding::Convergent, Overflow::Wrap>();
  }
}

// An exact intermediate result (up to 128 bits): what +, -, * of Fixed values give.
// It has no rounding/overflow rule of its own; fixed_cast applies the target's.
struct FixedWide {
  int128_t raw = 0;
  int width = 2;  // bits needed for any result of the operation that produced it (<= 128)
  int frac = 0;
  bool is_signed = true;
  double to_double() const;
};

class Fixed {
 public:
  // Zero in a default format (Q1.15 signed, truncate, wrap).
  Fixed() = default;
  // The double is quantized by fmt's rounding and overflow rules (an overflow is counted).
  // Throws InputError if fmt is invalid or value is not finite.
  explicit Fixed(double value, const FixedFormat& fmt, OverflowCounter* counter = nullptr);
  // Takes raw as is; throws InputError if it is outside fmt's range.
  static Fixed from_raw(std::int64_t raw, const FixedFormat& fmt);

  std::int64_t raw() const { return raw_; }
  const FixedFormat& format() const { return fmt_; }
  double to_double() const;
  FixedWide wide() const;  // the same value as a FixedWide (no growth)

 private:
  friend Fixed fixed_cast(const FixedWide& x, const FixedFormat& fmt, OverflowCounter* counter);
  std::int64_t raw_ = 0;
  FixedFormat fmt_{};
};

// Exact operations. The result format is signed if either operand is signed (sub: always),
// with frac = max of the fracs (add/sub) or sum (mul). Throws std::overflow_error if the
// exact result would need more than 128 bits (e.g. adding values whose fracs differ by ~100).
FixedWide operator+(const FixedWide& a, const FixedWide& b);
FixedWide operator-(const FixedWide& a, const FixedWide& b);
FixedWide operator*(const FixedWide& a, const FixedWide& b);
inline FixedWide operator+(const Fixed& a, const Fixed& b) { return a.wide() + b.wide(); }
inline FixedWide operator-(const Fixed& a, const Fixed& b) { return a.wide() - b.wide(); }
inline FixedWide operator*(const Fixed& a, const Fixed& b) { return a.wide() * b.wide(); }

// The one lossy step: round then overflow into fmt (validated; throws InputError if invalid).
Fixed fixed_cast(const FixedWide& x, const FixedFormat& fmt, OverflowCounter* counter = nullptr);
Fixed fixed_cast(const Fixed& x, const FixedFormat& fmt, OverflowCounter* counter = nullptr);

}  // namespace ranging
