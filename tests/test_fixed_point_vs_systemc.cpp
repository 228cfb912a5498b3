// Proof of model/dsp/fixed_point.hpp against an independent implementation: SystemC's fixed-point
// types (IEEE 1666 sc_fix / sc_ufix with runtime parameters, and the sc_fixed templates).
// Every rounding x overflow mode, widths 2..48 (plus 49..64), signed and unsigned, random
// fracs (negative and > width included); results compared bit for bit, overflow events
// counted against SystemC's.
//
// Linking notes: libsystemc.so references sc_main (it defines main itself; gtest_main's main
// in the executable takes precedence), so a stub is provided. Debian's library is built as
// C++17 and SystemC's headers check the API version, hence SC_CPLUSPLUS.
#define SC_INCLUDE_FX
#define SC_CPLUSPLUS 201703L
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <sstream>
#include <string>
#include <systemc>

#include "model/base/error.hpp"
#include "model/dsp/fixed_point.hpp"

int sc_main(int, char**) { return 0; }

namespace ranging {
namespace {

using sc_dt::sc_fix;
using sc_dt::sc_fxval;
using sc_dt::sc_ufix;

struct ScMode {
  Rounding rounding;
  Overflow overflow;
  sc_dt::sc_q_mode q;
  sc_dt::sc_o_mode o;
  const char* name;
};

constexpr ScMode kModes[] = {
    {Rounding::Truncate, Overflow::Wrap, sc_dt::SC_TRN, sc_dt::SC_WRAP, "TRN/WRAP"},
    {Rounding::Truncate, Overflow::Saturate, sc_dt::SC_TRN, sc_dt::SC_SAT, "TRN/SAT"},
    {Rounding::RoundHalfUp, Overflow::Wrap, sc_dt::SC_RND, sc_dt::SC_WRAP, "RND/WRAP"},
    {Rounding::RoundHalfUp, Overflow::Saturate, sc_dt::SC_RND, sc_dt::SC_SAT, "RND/SAT"},
    {Rounding::Convergent, Overflow::Wrap, sc_dt::SC_RND_CONV, sc_dt::SC_WRAP, "CONV/WRAP"},
    {Rounding::Convergent, Overflow::Saturate, sc_dt::SC_RND_CONV, sc_dt::SC_SAT, "CONV/SAT"},
};

std::uint64_t width_mask(int width) {
  return width >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << width) - 1;
}

// SystemC's cast of v into fmt: the raw bit pattern (low `width` bits) and whether the value
// before overflow handling lay outside the format. The overflow is detected independently
// of SystemC's flag: by comparing with the same quantization into a format 160 bits wider,
// which nothing in these tests overflows.
struct ScResult {
  std::uint64_t bits;
  bool overflowed;
};

template <class T>
ScResult sc_cast_as(const sc_fxval& v, const FixedFormat& f, const ScMode& m) {
  const int iwl = f.width - f.frac;
  const T r(v, f.width, iwl, m.q, m.o);
  const T unbounded(v, f.width + 160, iwl + 160, m.q, sc_dt::SC_WRAP);
  const bool overflowed = (r != unbounded);
  EXPECT_EQ(overflowed, r.overflow_flag()) << "detection disagrees with SystemC's own flag";
  return {r.range().to_uint64() & width_mask(f.width), overflowed};
}

ScResult sc_cast(const sc_fxval& v, const FixedFormat& f, const ScMode& m) {
  return f.is_signed ? sc_cast_as<sc_fix>(v, f, m) : sc_cast_as<sc_ufix>(v, f, m);
}

// The exact value raw * 2^-frac as an sc_fxval (arbitrary precision, no rounding).
sc_fxval sc_value(std::int64_t raw, int frac) {
  const sc_fxval v(static_cast<sc_dt::int64>(raw));
  return frac >= 0 ? sc_fxval(v >> frac) : sc_fxval(v << -frac);
}

std::string describe(const FixedFormat& f) {
  std::ostringstream os;
  os << (f.is_signed ? "s" : "u") << f.width << "/frac " << f.frac;
  return os.str();
}

class Random {
 public:
  explicit Random(std::uint64_t seed) : rng_(seed) {}
  int uniform(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }
  bool coin() { return (rng_() & 1) != 0; }

  FixedFormat format(int min_width, int max_width, int frac_lo_margin, int frac_hi_margin, const ScMode& m) {
    FixedFormat f;
    f.is_signed = coin();
    f.width = uniform(min_width, f.is_signed ? max_width : std::min(max_width, 63));
    f.frac = uniform(-frac_lo_margin, f.width + frac_hi_margin);
    f.rounding = m.rounding;
    f.overflow = m.overflow;
    return f;
  }
  // A code of the format: half uniform over the whole range, half of random magnitude so
  // that small values (and exact ties after a shift) are frequent too.
  std::int64_t code(const FixedFormat& f) {
    std::int64_t lo = fx_min_raw(f), hi = fx_max_raw(f);
    if (coin()) {
      const int bits = uniform(1, f.is_signed ? f.width - 1 : f.width);
      const std::int64_t m = static_cast<std::int64_t>(width_mask(bits) >> 1);
      lo = std::max(lo, -m - 1);
      hi = std::min(hi, m);
    }
    return std::uniform_int_distribution<std::int64_t>(lo, hi)(rng_);
  }
  // Any 64-bit integer of random bit length.
  std::int64_t wide_code() {
    const int bits = uniform(1, 64);
    const auto v = static_cast<std::int64_t>(rng_() & width_mask(bits));
    return v;  // bits == 64 gives negative values too
  }
  double finite_double() {
    const double m = std::uniform_real_distribution<double>(-1.0, 1.0)(rng_);
    return std::ldexp(m, uniform(-70, 70));
  }

 private:
  std::mt19937_64 rng_;
};

struct Tally {
  std::uint64_t ops = 0, mismatches = 0, sc_overflows = 0;
  OverflowCounter mine;
};

// Compare one cast: my raw (already computed, counted in t.mine) with SystemC's.
void check(Tally& t, std::int64_t mine, const sc_fxval& exact, const FixedFormat& f, const ScMode& m,
           const char* op) {
  const ScResult sc = sc_cast(exact, f, m);
  ++t.ops;
  if (sc.overflowed) ++t.sc_overflows;
  const std::uint64_t my_bits = static_cast<std::uint64_t>(mine) & width_mask(f.width);
  if (my_bits != sc.bits) {
    if (++t.mismatches <= 5) {
      ADD_FAILURE() << m.name << " " << op << " into " << describe(f) << ": exact " << exact.to_string()
                    << " -> mine " << mine << ", SystemC bits " << sc.bits;
    }
  }
  // The unchecked bits above the width must be the sign extension (or zero if unsigned).
  if (mine < fx_min_raw(f) || mine > fx_max_raw(f)) ADD_FAILURE() << "raw out of format range";
}

void expect_counts_match(const Tally& t, const ScMode& m) {
  EXPECT_EQ(t.mismatches, 0u) << m.name;
  if (m.overflow == Overflow::Saturate) {
    EXPECT_EQ(t.mine.saturations, t.sc_overflows) << m.name;
    EXPECT_EQ(t.mine.wraps, 0u) << m.name;
  } else {
    EXPECT_EQ(t.mine.wraps, t.sc_overflows) << m.name;
    EXPECT_EQ(t.mine.saturations, 0u) << m.name;
  }
  // Both outcomes must be well represented, or the comparison proves little.
  EXPECT_GT(t.sc_overflows, t.ops / 20) << m.name;
  EXPECT_LT(t.sc_overflows, t.ops / 2) << m.name;
}

// Per iteration: quantize a 64-bit value, quantize a double, add, sub, mul (5 operations).
void run_mode(const ScMode& m, int iterations, int min_width, int max_width, std::uint64_t seed) {
  Random rnd(seed);
  Tally t;
  for (int i = 0; i < iterations; ++i) {
    // 1. Quantize a random wider value (64-bit code, src_frac spanning growth and shrink).
    {
      const FixedFormat f = rnd.format(min_width, max_width, 8, 8, m);
      const std::int64_t raw = rnd.wide_code();
      const int src_frac = f.frac + rnd.uniform(-12, 40);
      const std::int64_t mine = fx_quantize(raw, src_frac, f, &t.mine);
      check(t, mine, sc_value(raw, src_frac), f, m, "quantize");
    }
    // 2. Quantize a double (exact binary value, any exponent).
    {
      const FixedFormat f = rnd.format(min_width, max_width, 8, 8, m);
      const double v = (i % 64 == 0) ? 0.0 : rnd.finite_double();
      const Fixed x(v, f, &t.mine);
      check(t, x.raw(), sc_fxval(v), f, m, "from double");
    }
    // 3..5. Exact add / sub / mul of two random operands, then the cast.
    const FixedFormat fa = rnd.format(min_width, max_width, 8, 8, m);
    FixedFormat fb = rnd.format(min_width, max_width, 8, 8, m);
    // Keep the exact sum within the 128 bits FixedWide holds (64-bit words whose binary
    // points are > ~60 bits apart would need more; that case throws, tested below).
    if (max_width > 48) fb.frac = fa.frac + rnd.uniform(-60, 60);
    const Fixed a = Fixed::from_raw(rnd.code(fa), fa);
    const Fixed b = Fixed::from_raw(rnd.code(fb), fb);
    const sc_fxval sa = sc_value(a.raw(), fa.frac);
    const sc_fxval sb = sc_value(b.raw(), fb.frac);
    const auto target = [&](const FixedWide& w) {
      FixedFormat f = rnd.format(min_width, max_width, 0, 0, m);
      // Drop between -4 (exact) and 20 fraction bits; keep a plausible integer range.
      f.frac = w.frac - rnd.uniform(-4, 20);
      const int int_bits = w.width - w.frac - rnd.uniform(-2, 6);
      f.width = std::clamp(int_bits + f.frac, min_width, f.is_signed ? max_width : std::min(max_width, 63));
      return f;
    };
    {
      const FixedWide w = a + b;
      const FixedFormat f = target(w);
      check(t, fixed_cast(w, f, &t.mine).raw(), sc_fxval(sa + sb), f, m, "add");
    }
    {
      const FixedWide w = a - b;
      const FixedFormat f = target(w);
      check(t, fixed_cast(w, f, &t.mine).raw(), sc_fxval(sa - sb), f, m, "sub");
    }
    {
      const FixedWide w = a * b;
      const FixedFormat f = target(w);
      check(t, fixed_cast(w, f, &t.mine).raw(), sc_fxval(sa * sb), f, m, "mul");
    }
  }
  expect_counts_match(t, m);
  std::printf("  %-9s widths %d..%d: %llu operations, %llu overflow events, %llu mismatches\n",
              m.name, min_width, max_width, static_cast<unsigned long long>(t.ops),
              static_cast<unsigned long long>(t.sc_overflows), static_cast<unsigned long long>(t.mismatches));
}

// 200000 iterations x 5 operations = 10^6 operations per mode combination.
constexpr int kIterations = 200000;

class FixedVsSystemC : public ::testing::TestWithParam<int> {};

TEST_P(FixedVsSystemC, RandomOperationsBitExactWidths2To48) {
  const ScMode& m = kModes[GetParam()];
  run_mode(m, kIterations, 2, 48, 0x5eed0000u + static_cast<std::uint64_t>(GetParam()));
}

// Wider words (up to the int64 limit) where the products need the full int128.
TEST_P(FixedVsSystemC, RandomOperationsBitExactWidths49To64) {
  const ScMode& m = kModes[GetParam()];
  run_mode(m, kIterations / 20, 49, 64, 0x5eed1000u + static_cast<std::uint64_t>(GetParam()));
}

INSTANTIATE_TEST_SUITE_P(AllModes, FixedVsSystemC, ::testing::Range(0, 6),
                         [](const ::testing::TestParamInfo<int>& info) {
                           std::string n = kModes[info.param].name;
                           for (char& c : n) if (c == '/') c = '_';
                           return n;
                         });

// The compile-time sc_fixed / sc_ufixed templates (the types an HLS flow would use).
template <int W, int I, sc_dt::sc_q_mode Q, sc_dt::sc_o_mode O, bool S>
void check_template(Rounding r, Overflow o, std::uint64_t seed) {
  using T = std::conditional_t<S, sc_dt::sc_fixed<W, I, Q, O>, sc_dt::sc_ufixed<W, I, Q, O>>;
  const FixedFormat f{W, W - I, S, r, o};
  std::mt19937_64 rng(seed);
  OverflowCounter mine;
  std::uint64_t sc_overflows = 0;
  for (int i = 0; i < 20000; ++i) {
    // Exact 51-bit values (so that the wide Fixed operands below hold them exactly).
    std::uniform_int_distribution<std::int64_t> mant(-(std::int64_t{1} << 50), std::int64_t{1} << 50);
    const double v = std::ldexp(static_cast<double>(mant(rng)), I + 2 - 50);
    const double u = std::ldexp(static_cast<double>(mant(rng)), I - 50);
    const T x = v;  // quantize a double
    const T y = sc_fxval(v) * sc_fxval(u);  // cast of an exact product
    sc_overflows += x.overflow_flag() + y.overflow_flag();
    const Fixed fx(v, f, &mine);
    const FixedFormat wide{64, 60 - I, true, Rounding::Truncate, Overflow::Saturate};
    const Fixed pu(u, wide), pv(v, wide);
    ASSERT_EQ(pu.to_double(), u);
    const Fixed fy = fixed_cast(pv * pu, f, &mine);
    ASSERT_EQ(static_cast<std::uint64_t>(fx.raw()) & width_mask(W), x.range().to_uint64() & width_mask(W))
        << "quantize " << v;
    ASSERT_EQ(static_cast<std::uint64_t>(fy.raw()) & width_mask(W), y.range().to_uint64() & width_mask(W))
        << "product " << v << " * " << u;
  }
  EXPECT_EQ(mine.total(), sc_overflows);
  EXPECT_GT(sc_overflows, 0u);
}

TEST(FixedVsSystemCTemplates, FixedWidthTypes) {
  check_template<16, 2, sc_dt::SC_RND, sc_dt::SC_SAT, true>(Rounding::RoundHalfUp, Overflow::Saturate, 1);
  check_template<12, 1, sc_dt::SC_TRN, sc_dt::SC_WRAP, true>(Rounding::Truncate, Overflow::Wrap, 2);
  check_template<40, 6, sc_dt::SC_RND_CONV, sc_dt::SC_SAT, true>(Rounding::Convergent, Overflow::Saturate, 3);
  check_template<10, 3, sc_dt::SC_RND, sc_dt::SC_WRAP, false>(Rounding::RoundHalfUp, Overflow::Wrap, 4);
  check_template<8, -2, sc_dt::SC_RND_CONV, sc_dt::SC_WRAP, true>(Rounding::Convergent, Overflow::Wrap, 5);
  check_template<24, 30, sc_dt::SC_TRN, sc_dt::SC_SAT, false>(Rounding::Truncate, Overflow::Saturate, 6);
}

// Hand-checked rounding of the ties (definitions, not the code's output).
TEST(FixedPointRules, TiesFollowTheDocumentedRules) {
  const auto q = [](double v, Rounding r) {
    return Fixed(v, FixedFormat{8, 0, true, r, Overflow::Saturate}).raw();
  };
  EXPECT_EQ(q(2.5, Rounding::Truncate), 2);
  EXPECT_EQ(q(-2.5, Rounding::Truncate), -3);  // floor, not toward zero
  EXPECT_EQ(q(2.5, Rounding::RoundHalfUp), 3);
  EXPECT_EQ(q(-2.5, Rounding::RoundHalfUp), -2);  // ties toward +inf
  EXPECT_EQ(q(2.5, Rounding::Convergent), 2);
  EXPECT_EQ(q(3.5, Rounding::Convergent), 4);
  EXPECT_EQ(q(-2.5, Rounding::Convergent), -2);
  EXPECT_EQ(q(-3.5, Rounding::Convergent), -4);
  EXPECT_EQ(q(-2.75, Rounding::RoundHalfUp), -3);
}

TEST(FixedPointRules, OverflowIsCountedNeverHidden) {
  OverflowCounter c;
  const FixedFormat sat{8, 4, true, Rounding::Truncate, Overflow::Saturate};
  EXPECT_EQ(Fixed(100.0, sat, &c).raw(), 127);
  EXPECT_EQ(Fixed(-100.0, sat, &c).raw(), -128);
  EXPECT_EQ(Fixed(7.9375, sat, &c).raw(), 127);  // largest code: no event
  EXPECT_EQ(c.saturations, 2u);
  const FixedFormat wrap{8, 4, true, Rounding::Truncate, Overflow::Wrap};
  EXPECT_EQ(Fixed(8.0, wrap, &c).raw(), -128);  // 128 mod 256 read as signed
  EXPECT_EQ(c.wraps, 1u);
  // Extreme shifts: huge values overflow, tiny ones round to 0 / -1 LSB.
  const FixedFormat u{16, 8, false, Rounding::Truncate, Overflow::Saturate};
  EXPECT_EQ(fx_quantize(1, -200, u, &c), 65535);
  EXPECT_EQ(fx_quantize(-1, 300, FixedFormat{16, 8, true, Rounding::Truncate, Overflow::Wrap}, &c), -1);
  EXPECT_EQ(fx_quantize(-1, 300, FixedFormat{16, 8, true, Rounding::RoundHalfUp, Overflow::Wrap}, &c), 0);
  EXPECT_EQ(fx_quantize(3, -130, FixedFormat{16, 0, true, Rounding::Truncate, Overflow::Wrap}, nullptr), 0);
  EXPECT_EQ(c.saturations, 3u);
}

TEST(FixedPointRules, BitGrowthIsExact) {
  const FixedFormat q15{16, 15};
  const Fixed a = Fixed::from_raw(-32768, q15), b = Fixed::from_raw(-32768, q15);
  const FixedWide p = a * b;  // (-1) * (-1) = +1 needs the extra integer bit
  EXPECT_EQ(p.width, 32);
  EXPECT_EQ(p.frac, 30);
  EXPECT_EQ(p.to_double(), 1.0);
  const FixedWide s = a + b;
  EXPECT_EQ(s.width, 17);
  EXPECT_EQ(s.to_double(), -2.0);
  const Fixed big = Fixed::from_raw(INT64_MIN, FixedFormat{64, 0});
  EXPECT_EQ((big * big).to_double(), std::ldexp(1.0, 126));
  EXPECT_THROW(big * big * big.wide(), std::overflow_error);
}

TEST(FixedPointRules, InvalidFormatsAreRefusedNamingTheField) {
  const auto msg = [](const FixedFormat& f) {
    try {
      validate(f, "data");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(msg(FixedFormat{0, 0}).find("data width"), std::string::npos);
  EXPECT_NE(msg(FixedFormat{65, 0}).find("[2, 64]"), std::string::npos);
  EXPECT_NE(msg(FixedFormat{64, 0, false}).find("[2, 63]"), std::string::npos);
  EXPECT_NE(msg(FixedFormat{16, 5000}).find("data fraction bits"), std::string::npos);
  EXPECT_EQ(msg(FixedFormat{64, -3}), "");
  EXPECT_THROW(Fixed::from_raw(128, FixedFormat{8, 0}), InputError);
  EXPECT_THROW(Fixed(std::nan(""), FixedFormat{8, 0}), InputError);
}

}  // namespace
}  // namespace ranging
