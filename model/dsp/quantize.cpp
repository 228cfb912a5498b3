#include "model/dsp/quantize.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
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

std::int64_t quantize_input_wide(double x, int bits, OverflowCounter* counter) {
  const FixedFormat fmt{bits, bits - 1, true, Rounding::RoundHalfUp, Overflow::Saturate};
  if (!std::isfinite(x)) throw InputError("receiver input: sample is not finite");
  // x * 2^(bits-1) with 20 guard bits below the LSB, so the rounding sees the true fraction.
  const double scaled = std::ldexp(x, bits - 1 + 20);
  const double lim = std::ldexp(1.0, 100);
  const int128_t raw = static_cast<int128_t>(std::clamp(std::floor(scaled), -lim, lim));
  return fx_quantize(raw, bits - 1 + 20, fmt, counter);
}

std::int64_t quantize_input(double x, int bits, OverflowCounter* counter) {
  if (!std::isfinite(x)) throw InputError("receiver input: sample is not finite");
  // The int64 path: for 2 <= bits <= 40 and |x| <= 4, floor(x * 2^(bits-1+20)) is exact
  // (a power-of-two scaling) and |floor| <= 2^61, so the same 20 guard bits, round half up
  // ((f >> 20) + bit 19 of f: floor((f + 2^19) / 2^20)) and saturation as quantize_input_wide,
  // without its int128 conversion. Anything else (|x| > 4 always saturates) takes the wide path.
  if (bits >= 2 && bits <= 40 && std::abs(x) <= 4.0) {
    const double scaled = x * static_cast<double>(std::int64_t{1} << (bits - 1 + 20));
    const auto f = static_cast<std::int64_t>(std::floor(scaled));
    const std::int64_t q = (f >> 20) + ((f >> 19) & 1);  // arithmetic shifts (C++20): floor
    const std::int64_t hi = (std::int64_t{1} << (bits - 1)) - 1;
    if (q > hi || q < -hi - 1) [[unlikely]] {
      if (counter) ++counter->saturations;
      return q > hi ? hi : -hi - 1;
    }
    return q;
  }
  return quantize_input_wide(x, bits, counter);
}

namespace {
typedef double D8q __attribute__((vector_size(64)));
typedef std::int64_t I8q __attribute__((vector_size(64)));
}  // namespace

#if defined(__x86_64__)
[[gnu::target_clones("default", "arch=x86-64-v4")]]
#endif
void quantize_input_block(std::span<const double> x, double gain, int bits, std::int64_t* out,
                          OverflowCounter& counter, std::vector<std::size_t>* clamped, std::size_t index0) {
  const auto one_by_one = [&](std::size_t i0, std::size_t i1) {
    for (std::size_t i = i0; i < i1; ++i) {
      const double v = x[i] * gain;
      if (clamped && std::abs(v) > 1.0) clamped->push_back(index0 + i);
      out[i] = quantize_input(std::clamp(v, -1.0, 1.0), bits, &counter);
    }
  };
  std::size_t i = 0;
  if (bits >= 2 && bits <= 40) {
    // quantize_input's int64 path on |v| <= 1: f = floor(v 2^(bits-1+20)) (exact: a power of two,
    // |f| <= 2^59), q = (f >> 20) + bit 19 of f, saturated to [-2^(bits-1), 2^(bits-1) - 1].
    const double scale = static_cast<double>(std::int64_t{1} << (bits - 1 + 20));
    const std::int64_t hi = (std::int64_t{1} << (bits - 1)) - 1, lo = -hi - 1;
    const I8q one = I8q{} + 1, zero{};
    std::uint64_t saturated = 0;
    for (; i + 8 <= x.size(); i += 8) {
      D8q v;
      std::memcpy(&v, x.data() + i, sizeof v);
      v = v * gain;
      // a lane beyond +-1 or not finite (NaN fails every compare): these eight one by one
      const I8q odd = (v >= -1.0 ? zero : one) | (v <= 1.0 ? zero : one);
      std::int64_t any = 0;
      for (int k = 0; k < 8; ++k) any |= odd[k];
      if (any) {
        counter.saturations += saturated;  // the loop's count so far, should these eight throw
        saturated = 0;
        one_by_one(i, i + 8);
        continue;
      }
      const D8q s = v * scale;
      const I8q t = __builtin_convertvector(s, I8q);  // toward zero
      const I8q f = t - (__builtin_convertvector(t, D8q) > s ? one : zero);  // floor
      I8q q = (f >> 20) + ((f >> 19) & one);
      const I8q over = (q > hi ? one : zero) + (q < lo ? one : zero);
      q = q > hi ? I8q{} + hi : (q < lo ? I8q{} + lo : q);
      std::memcpy(out + i, &q, sizeof q);
      for (int k = 0; k < 8; ++k) saturated += static_cast<std::uint64_t>(over[k]);
    }
    counter.saturations += saturated;
  }
  one_by_one(i, x.size());
}

}  // namespace ranging
