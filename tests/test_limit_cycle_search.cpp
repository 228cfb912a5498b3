// Exhaustive zero-input limit-cycle search over every initial state of one section (issue 12
// section 3). Bounds from theory, not from the code's output.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "model/base/error.hpp"
#include "model/dsp/limit_cycle_search.hpp"

using namespace ranging;

namespace {

// A section shaped like the receiver's narrowest one: poles at radius r, angle 2 pi 200 kHz / 5 MHz.
struct Section {
  std::int64_t a1, a2;
  int frac;
};
Section section(double r, int frac) {
  const double th = 2 * std::numbers::pi * 200e3 / 5e6;
  return {std::llround(-2 * r * std::cos(th) * std::ldexp(1.0, frac)), std::llround(r * r * std::ldexp(1.0, frac)), frac};
}

FixedFormat data(int bits, Rounding r, Overflow o) { return FixedFormat{bits, 0, true, r, o}; }

// ||h||_1 of 1 / (1 + A1/2^F z^-1 + A2/2^F z^-2), by its (decaying) impulse response.
double l1_norm(const Section& s) {
  const double a1 = static_cast<double>(s.a1) / std::ldexp(1.0, s.frac), a2 = static_cast<double>(s.a2) / std::ldexp(1.0, s.frac);
  double y1 = 0, y2 = 0, sum = 0;
  for (int n = 0; n < 200000; ++n) {
    const double y = (n == 0 ? 1.0 : 0.0) - a1 * y1 - a2 * y2;
    sum += std::abs(y);
    y2 = y1;
    y1 = y;
  }
  return sum;
}

}  // namespace

// A granular limit cycle is the linear recursion driven by the rounding error e[n], |e| <= 1/2
// LSB for rounding to nearest: in steady state y = h * e, so |y| <= floor(||h||_1 / 2) LSB
// (rigorous without overflow; the saturating searches below stay far inside it). Jackson's effective-value estimate
// 0.5 / (1 - A2/2^F) is printed beside it: the search finds cycles 1 LSB above that estimate at
// r = 0.984 (16 vs 15.5), so it is not a bound. Checked over every initial state, widths 6..9 bits.
TEST(LimitCycleSearch, RoundingToNearestStaysInsideTheL1Bound) {
  for (const double r : {0.9, 0.95, 0.984}) {
    const Section s = section(r, 10);
    const double a2 = static_cast<double>(s.a2) / std::ldexp(1.0, s.frac);
    const double jackson = 0.5 / (1.0 - a2);
    const auto bound = static_cast<std::int64_t>(std::floor(0.5 * l1_norm(s)));
    for (int bits = 6; bits <= 9; ++bits) {
      for (const Rounding rd : {Rounding::RoundHalfUp, Rounding::Convergent}) {
        const auto res = exhaustive_limit_cycles(s.a1, s.a2, s.frac, data(bits, rd, Overflow::Saturate));
        EXPECT_EQ(res.states, std::uint64_t{1} << (2 * bits));
        EXPECT_LE(res.max_amplitude_lsb, bound) << "r " << r << " bits " << bits << " rounding " << static_cast<int>(rd);
        std::printf("r %.3f (A2 %.4f) bits %d %s: Jackson %.2f, L1 bound %lld, max %lld LSB period %d, %llu nonzero cycles, %llu of %llu states end in one\n",
                    r, a2, bits, rd == Rounding::RoundHalfUp ? "half-up" : "convergent", jackson, static_cast<long long>(bound),
                    static_cast<long long>(res.max_amplitude_lsb), res.period_of_max,
                    static_cast<unsigned long long>(res.nonzero_cycles), static_cast<unsigned long long>(res.states_into_nonzero),
                    static_cast<unsigned long long>(res.states));
      }
    }
  }
}

// Truncation (floor): e in (-1, 0] LSB, so |y| <= ||h||_1 LSB; the search finds a constant
// (period 1) cycle, the floor's DC bias.
TEST(LimitCycleSearch, TruncationWithinTheL1Bound) {
  const Section s = section(0.95, 10);
  const auto bound = static_cast<std::int64_t>(std::floor(l1_norm(s)));
  const auto res = exhaustive_limit_cycles(s.a1, s.a2, s.frac, data(9, Rounding::Truncate, Overflow::Saturate));
  std::printf("truncate r 0.95 bits 9: bound %lld max %lld period %d\n", static_cast<long long>(bound),
              static_cast<long long>(res.max_amplitude_lsb), res.period_of_max);
  EXPECT_LE(res.max_amplitude_lsb, bound);
}

// Wrap (two's complement) overflow sustains a large-scale oscillation from some initial state:
// the search finds a cycle reaching at least a quarter of full scale. Saturation does not.
TEST(LimitCycleSearch, WrapSustainsAnOverflowOscillationSaturationDoesNot) {
  const Section s = section(0.984, 10);
  for (int bits = 6; bits <= 8; ++bits) {
    const auto wrap = exhaustive_limit_cycles(s.a1, s.a2, s.frac, data(bits, Rounding::RoundHalfUp, Overflow::Wrap));
    const auto sat = exhaustive_limit_cycles(s.a1, s.a2, s.frac, data(bits, Rounding::RoundHalfUp, Overflow::Saturate));
    std::printf("bits %d: wrap max %lld period %d; saturate max %lld period %d\n", bits,
                static_cast<long long>(wrap.max_amplitude_lsb), wrap.period_of_max,
                static_cast<long long>(sat.max_amplitude_lsb), sat.period_of_max);
    EXPECT_GE(wrap.max_amplitude_lsb, std::int64_t{1} << (bits - 3)) << bits;
    EXPECT_GT(wrap.overflows, 0u);
    EXPECT_LT(sat.max_amplitude_lsb, wrap.max_amplitude_lsb) << bits;
  }
}

TEST(LimitCycleSearch, StableFirstOrderLikeSectionComesToRest) {
  // a1 = a2 = 0: y = 0 after two steps from any state; one cycle, the rest state.
  const auto res = exhaustive_limit_cycles(0, 0, 8, data(7, Rounding::RoundHalfUp, Overflow::Saturate));
  EXPECT_EQ(res.cycles, 1u);
  EXPECT_EQ(res.nonzero_cycles, 0u);
  EXPECT_EQ(res.max_amplitude_lsb, 0);
  EXPECT_THROW(exhaustive_limit_cycles(0, 0, 8, data(11, Rounding::RoundHalfUp, Overflow::Saturate)), InputError);
}
