#include "model/sim/front_end.hpp"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <string>

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/exponential_distribution.hpp>
#include <boost/random/normal_distribution.hpp>
#include <boost/random/uniform_01.hpp>

#include "model/base/error.hpp"
#include "model/sim/scene.hpp"

namespace ranging {

namespace {
// boost::random::normal_distribution<double>(0, 1) on mt19937_64, written out: Boost 1.74's
// detail::unit_normal_distribution (the 128-level ziggurat over normal_table<double>) with its
// int/float pair as detail::generate_int_float_pair<double, 8> takes it from one 64-bit draw
// (bucket: the low 8 bits, 7 for the level and 1 for the sign; the float: bits 8..63 with bit 11
// cleared, times 2^-56), then the distribution's `* 1.0 + 0.0`. The rare paths (1.2 % of draws:
// the wedges and the tail) call Boost's own uniform_01 and exponential_distribution. The same
// draws and the same values, bit for bit (tests/test_front_end checks it against Boost's
// distribution); in this form GCC compiles the common path to straight-line code, about twice
// as fast as Boost's generic one in the AVX-512 clone (unsigned conversions in one instruction).
[[gnu::always_inline]] inline double boost_unit_normal(boost::random::mt19937_64& eng) {
  const double* const tx = boost::random::detail::normal_table<double>::table_x;
  const double* const ty = boost::random::detail::normal_table<double>::table_y;
  for (;;) {
    std::uint64_t u = eng();
    int i = static_cast<int>(u & 0xff);
    u &= ~(std::uint64_t{1} << 11);
    const double r = static_cast<double>(u >> 8) * (1.0 / static_cast<double>(std::uint64_t{1} << 56));
    const int sign = (i & 1) * 2 - 1;
    i >>= 1;
    const double x = r * tx[i];
    if (x < tx[i + 1]) [[likely]] return x * sign;
    if (i == 0) {  // the tail beyond tx[1]: exponential rejection sampling
      const double tail_start = tx[1];
      boost::random::exponential_distribution<double> exp_x(tail_start), exp_y;
      for (;;) {
        const double a = exp_x(eng), b = exp_y(eng);
        if (2 * b > a * a) return (a + tail_start) * sign;
      }
    }
    const double y01 = boost::random::uniform_01<double>()(eng);
    const double y = ty[i] + y01 * (ty[i + 1] - ty[i]);
    double above_upper, above_lower;  // y against the chord and the tangent of the wedge
    if (tx[i] >= 1) {                 // convex (and the inflection)
      above_upper = (tx[i] - tx[i + 1]) * y01 - (tx[i] - x);
      above_lower = y - (ty[i] + (tx[i] - x) * ty[i] * tx[i]);
    } else {  // concave
      above_lower = (tx[i] - tx[i + 1]) * y01 - (tx[i] - x);
      above_upper = y - (ty[i] + (tx[i] - x) * ty[i] * tx[i]);
    }
    if (above_upper < 0 && (above_lower < 0 || y < std::exp(-(x * x / 2)))) return x * sign;
  }
}
}  // namespace

#if defined(__x86_64__)
[[gnu::target_clones("default", "arch=x86-64-v4")]]
#endif
void add_white_noise(std::span<double> x, double sigma, std::uint64_t seed) {
  if (!(sigma > 0.0)) return;
  boost::random::mt19937_64 rng(seed);
  for (double& v : x) v += sigma * (boost_unit_normal(rng) * 1.0 + 0.0);
}

std::size_t adc_quantize(std::span<double> x, const SceneAdc& a, std::vector<std::size_t>* clipped) {
  if (a.bits < 2 || a.bits > 24) {
    throw InputError("adc.bits: " + std::to_string(a.bits) + " is out of range; valid range is 2..24");
  }
  const double q = a.full_scale_v / std::ldexp(1.0, a.bits - 1);
  const std::int32_t top = std::int32_t{1} << (a.bits - 1);
  // round() is monotonic, so rounding v clamped to [-top - 1, top] and then clamping the code
  // gives clamp(round(v)) exactly, and a code outside [-top, top - 1] still marks a clipped
  // sample; the clamp keeps the int32 conversion defined (NaN goes to the low rail).
  const double lo = -static_cast<double>(top) - 1.0, hi = static_cast<double>(top);
  const auto mask = (std::uint32_t{1} << a.bits) - 1;
  constexpr std::size_t kChunk = 256;
  std::int32_t r[kChunk];
  std::size_t count = 0;
  for (std::size_t b = 0; b < x.size(); b += kChunk) {
    const std::size_t m = std::min(kChunk, x.size() - b);
    double* xb = x.data() + b;
    std::int32_t clip = 0;
    for (std::size_t k = 0; k < m; ++k) {  // std::round: trunc, then the exact fraction decides
      double v = (xb[k] + a.dc_offset_v) / q;
      v = v > hi ? hi : (v >= lo ? v : lo);
      const auto i = static_cast<std::int32_t>(v);
      const double f = v - static_cast<double>(i);
      const std::int32_t rk = i + (f >= 0.5) - (f <= -0.5);
      r[k] = rk;
      clip += (rk < -top) | (rk > top - 1);
    }
    if (clip) {
      count += static_cast<std::size_t>(clip);
      if (clipped) {
        for (std::size_t k = 0; k < m; ++k) {
          if (r[k] < -top || r[k] > top - 1) clipped->push_back(b + k);
        }
      }
    }
    if (a.stuck_bit < 0) {
      for (std::size_t k = 0; k < m; ++k) xb[k] = static_cast<double>(std::clamp(r[k], -top, top - 1)) * q;
    } else {  // two's complement of `bits` bits, the bit forced, sign-extended back
      const std::uint32_t bit = std::uint32_t{1} << a.stuck_bit;
      for (std::size_t k = 0; k < m; ++k) {
        std::uint32_t u = static_cast<std::uint32_t>(std::clamp(r[k], -top, top - 1)) & mask;
        u = a.stuck_value ? (u | bit) : (u & ~bit);
        const std::int32_t code = (u & static_cast<std::uint32_t>(top)) ? static_cast<std::int32_t>(u) - static_cast<std::int32_t>(mask) - 1
                                                                     : static_cast<std::int32_t>(u);
        xb[k] = static_cast<double>(code) * q;
      }
    }
  }
  return count;
}

}  // namespace ranging
