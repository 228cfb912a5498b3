#include "model/sim/front_end.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>

#include "model/base/error.hpp"
#include "model/sim/scene.hpp"

namespace ranging {

void add_white_noise(std::span<double> x, double sigma, std::uint64_t seed) {
  if (!(sigma > 0.0)) return;
  boost::random::mt19937_64 rng(seed);
  boost::random::normal_distribution<double> nd(0.0, 1.0);
  for (double& v : x) v += sigma * nd(rng);
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
