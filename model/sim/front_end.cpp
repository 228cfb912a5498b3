#include "model/sim/front_end.hpp"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <string>

#include <boost/random/exponential_distribution.hpp>
#include <boost/random/normal_distribution.hpp>
#include <boost/random/uniform_01.hpp>

#include "model/base/error.hpp"
#include "model/sim/scene.hpp"

namespace ranging {

namespace {
// boost::random::normal_distribution<double>(0, 1) on boost::random::mt19937_64(seed), written
// out so that most samples take eight at a time: the same draws and the same values, bit for
// bit (tests/test_front_end checks it against Boost's distribution).
//   The engine: MT19937-64 (Matsumoto & Nishimura; Boost's seeding, twist and tempering), 312
//   outputs per twist, the twist and the tempering eight words at a time.
//   The normal: Boost 1.74's detail::unit_normal_distribution, the 128-level ziggurat over
//   normal_table<double>, with its int/float pair as detail::generate_int_float_pair<double, 8>
//   takes it from one 64-bit draw u: the level and sign from the low 8 bits, the float
//   (u with bit 11 cleared) >> 8, times 2^-56; accepted at once if x = float * x_level is below
//   x_(level+1) (98.8 % of draws, tested eight at a time); the wedges and the tail (Boost's code,
//   on the same draws) call Boost's own uniform_01 and exponential_distribution. The
//   distribution's `* 1.0 + 0.0` is kept (it turns -0 into +0).
constexpr std::size_t kMtN = 312, kMtM = 156;
constexpr std::uint64_t kMtA = 0xB5026F5AA96619E9ull, kMtUpper = ~std::uint64_t{0} << 31, kMtLower = ~kMtUpper;

typedef std::uint64_t U8v __attribute__((vector_size(64)));
typedef double D8v __attribute__((vector_size(64)));
typedef std::int64_t I8v __attribute__((vector_size(64)));

// The draws in order: buf[pos, len) not yet used; refill() keeps them and appends one twist's
// 312 outputs. The engine interface (result_type, min, max, operator()) is what Boost's
// distributions use.
struct Draws {
  using result_type = std::uint64_t;
  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return ~std::uint64_t{0}; }
  std::uint64_t state[kMtN];
  std::uint64_t buf[kMtN + 8];
  std::size_t pos = 0, len = 0;

  explicit Draws(std::uint64_t seed) {
    state[0] = seed;
    for (std::size_t i = 1; i < kMtN; ++i) state[i] = 6364136223846793005ull * (state[i - 1] ^ (state[i - 1] >> 62)) + i;
  }
  [[gnu::always_inline]] inline void refill() {
    const std::size_t keep = len - pos;  // < 8
    for (std::size_t k = 0; k < keep; ++k) buf[k] = buf[pos + k];
    pos = 0;
    len = keep + kMtN;
    std::uint64_t* x = state;
    auto step = [&](std::size_t j, std::size_t from) {  // one word, the wrap included
      const std::uint64_t next = x[(j + 1) % kMtN];
      const std::uint64_t y = (x[j] & kMtUpper) | (next & kMtLower);
      x[j] = x[from] ^ (y >> 1) ^ ((next & 1) * kMtA);
    };
    auto eight = [&](std::size_t j, std::size_t from) {  // words j..j+7; x[j+8] and x[from..from+7] are final
      U8v a, b, c;
      std::memcpy(&a, x + j, 64);
      std::memcpy(&b, x + j + 1, 64);
      std::memcpy(&c, x + from, 64);
      const U8v y = (a & kMtUpper) | (b & kMtLower);
      const U8v r = c ^ (y >> 1) ^ ((b & 1) * kMtA);
      std::memcpy(x + j, &r, 64);
    };
    std::size_t j = 0;
    for (; j + 8 <= kMtN - kMtM; j += 8) eight(j, j + kMtM);  // reads x[j + 1 .. j + 8] before they change
    for (; j < kMtN - kMtM; ++j) step(j, j + kMtM);
    for (; j + 8 <= kMtN - 1; j += 8) eight(j, j - (kMtN - kMtM));
    for (; j < kMtN; ++j) step(j, j - (kMtN - kMtM));
    for (std::size_t k = 0; k < kMtN; k += 8) {  // the tempering
      U8v z;
      std::memcpy(&z, x + k, 64);
      z ^= (z >> 29) & 0x5555555555555555ull;
      z ^= (z << 17) & 0x71D67FFFEDA60000ull;
      z ^= (z << 37) & 0xFFF7EEE000000000ull;
      z ^= z >> 43;
      std::memcpy(buf + keep + k, &z, 64);
    }
  }
  std::uint64_t operator()() {
    if (pos == len) refill();
    return buf[pos++];
  }
};

// The ziggurat's float and level of draw u (generate_int_float_pair<double, 8>).
struct Pair {
  double x;
  int level, sign;
};
inline Pair ziggurat_pair(std::uint64_t u) {
  const double* const tx = boost::random::detail::normal_table<double>::table_x;
  const int bucket = static_cast<int>(u & 0xff);
  u &= ~(std::uint64_t{1} << 11);
  const double r = static_cast<double>(u >> 8) * (1.0 / static_cast<double>(std::uint64_t{1} << 56));
  return {r * tx[bucket >> 1], bucket >> 1, (bucket & 1) * 2 - 1};
}

// One unit normal from the draws (Boost's loop), its first draw's pair given (`p`: the draw
// already taken from eng).
[[gnu::noinline]] double unit_normal_slow(Draws& eng, Pair p) {
  const double* const tx = boost::random::detail::normal_table<double>::table_x;
  const double* const ty = boost::random::detail::normal_table<double>::table_y;
  for (bool first = true;; first = false) {
    if (!first) p = ziggurat_pair(eng());
    const int i = p.level, sign = p.sign;
    const double x = p.x;
    if (x < tx[i + 1]) return x * sign;
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
  const double* const tx = boost::random::detail::normal_table<double>::table_x;
  Draws eng(seed);
  const std::size_t n = x.size();
  std::size_t i = 0;
  while (i < n) {
    if (eng.len - eng.pos < 8) eng.refill();
    if (n - i >= 8) {  // eight draws at once; all pass the fast test 91 % of the time
      U8v u;
      std::memcpy(&u, eng.buf + eng.pos, 64);
      const U8v bucket = u & 0xff;
      const I8v level = reinterpret_cast<I8v>(bucket >> 1);
      const D8v sign = __builtin_convertvector(reinterpret_cast<I8v>(bucket & 1) * 2 - 1, D8v);
      const D8v r = __builtin_convertvector((u & ~(std::uint64_t{1} << 11)) >> 8, D8v) *
                    (1.0 / static_cast<double>(std::uint64_t{1} << 56));
      D8v lo, hi;
      for (int k = 0; k < 8; ++k) lo[k] = tx[level[k]], hi[k] = tx[level[k] + 1];
      const D8v xv = r * lo;
      int ok = 0;  // lanes [0, ok) pass (a lane at a time: the branch is predicted, a vector
      while (ok < 8 && xv[ok] < hi[ok]) ++ok;  // reduction of the test measured slower)
      const D8v v = xv * sign * 1.0 + 0.0;
      if (ok == 8) {
        D8v s;
        std::memcpy(&s, x.data() + i, 64);
        s += sigma * v;
        std::memcpy(x.data() + i, &s, 64);
        eng.pos += 8;
        i += 8;
        continue;
      }
      for (int k = 0; k < ok; ++k) x[i + static_cast<std::size_t>(k)] += sigma * v[k];
      i += static_cast<std::size_t>(ok);
      eng.pos += static_cast<std::size_t>(ok);
    }
    // one sample the slow way (its first draw refused by the fast test, or the last < 8)
    x[i] += sigma * (unit_normal_slow(eng, ziggurat_pair(eng())) * 1.0 + 0.0);
    ++i;
  }
}

#if defined(__x86_64__)
[[gnu::target_clones("default", "arch=x86-64-v4")]]
#endif
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
    std::size_t k = 0;
    // Eight samples at a time, each with the scalar loop's operations (the divide, the clamp
    // by blends, truncation to an integer, the exact fraction); the codes fit int32.
    I8v clip8{};
    for (; k + 8 <= m; k += 8) {
      D8v v;
      std::memcpy(&v, xb + k, 64);
      v = (v + a.dc_offset_v) / q;
      v = v > hi ? D8v{} + hi : (v >= lo ? v : D8v{} + lo);
      const I8v i = __builtin_convertvector(v, I8v);
      const D8v f = v - __builtin_convertvector(i, D8v);
      const I8v one = I8v{} + 1, zero{};
      const I8v rk = i + (f >= 0.5 ? one : zero) - (f <= -0.5 ? one : zero);
      for (std::size_t u = 0; u < 8; ++u) r[k + u] = static_cast<std::int32_t>(rk[u]);
      clip8 += (rk < -top ? one : zero) + (rk > top - 1 ? one : zero);
    }
    for (std::size_t u = 0; u < 8; ++u) clip += static_cast<std::int32_t>(clip8[u]);
    for (; k < m; ++k) {  // std::round: trunc, then the exact fraction decides
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
