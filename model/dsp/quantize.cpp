#include "model/dsp/quantize.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#if defined(__x86_64__)
#include <immintrin.h>
#endif
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

#if defined(__x86_64__)
namespace {
// Eight samples at a time from x[i0] while every v = x[i] * gain of a group is within +-1:
// quantize_input's int64 path (f = floor(v 2^(bits-1+20)), exact: a power of two and |f| <=
// 2^59; q = (f >> 20) + bit 19 of f, >= -2^(bits-1) since v >= -1; saturated at the top, which
// only v = +1 reaches, counted in *sat). Returns where it stopped: the
// first group with a lane beyond +-1 or NaN (then the caller's loop), or the last whole group's
// end. Written with AVX-512 intrinsics: GCC 12 turns the compares of vector extensions into
// scalar code.
[[gnu::target("avx512f,avx512dq")]] std::size_t quantize_groups(const double* x, std::size_t i0, std::size_t n,
                                                               double gain, int bits, std::int64_t* out,
                                                               std::uint64_t* sat) {
  const __m512d g = _mm512_set1_pd(gain), one = _mm512_set1_pd(1.0), mone = _mm512_set1_pd(-1.0);
  const __m512d scale = _mm512_set1_pd(static_cast<double>(std::int64_t{1} << (bits - 1 + 20)));
  const __m512i hi = _mm512_set1_epi64((std::int64_t{1} << (bits - 1)) - 1);
  const __m512i bit = _mm512_set1_epi64(1);
  const __mmask8 all = 0xFF;
  std::uint64_t over = 0;
  std::size_t i = i0;
  for (; i + 8 <= n; i += 8) {
    const __m512d v = _mm512_mul_pd(_mm512_loadu_pd(x + i), g);
    // ordered compares: false for NaN
    const __mmask8 in = _mm512_cmp_pd_mask(v, one, _CMP_LE_OQ) & _mm512_cmp_pd_mask(v, mone, _CMP_GE_OQ);
    if (in != 0xFF) break;
    const __m512i f = _mm512_cvt_roundpd_epi64(_mm512_mul_pd(v, scale), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    // (the zero-masked forms, all lanes: the plain ones trip GCC 12's -Wmaybe-uninitialized)
    __m512i q = _mm512_add_epi64(_mm512_maskz_srai_epi64(all, f, 20),
                                 _mm512_and_si512(_mm512_maskz_srai_epi64(all, f, 19), bit));
    over += static_cast<std::uint64_t>(__builtin_popcount(_mm512_cmpgt_epi64_mask(q, hi)));
    q = _mm512_maskz_min_epi64(all, q, hi);
    _mm512_storeu_si512(out + i, q);
  }
  *sat += over;
  return i;
}

bool avx512_quantizer() {
  static const bool yes = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq");
  }();
  return yes;
}
}  // namespace
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
#if defined(__x86_64__)
  if (bits >= 2 && bits <= 40 && avx512_quantizer()) {
    while (i + 8 <= x.size()) {
      i = quantize_groups(x.data(), i, x.size(), gain, bits, out, &counter.saturations);
      if (i + 8 > x.size()) break;
      one_by_one(i, i + 8);  // a group with a sample beyond +-1 or NaN (which throws)
      i += 8;
    }
  }
#endif
  one_by_one(i, x.size());
}

}  // namespace ranging
