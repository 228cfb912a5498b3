#pragma once
// Exhaustive search for zero-input limit cycles of one second-order section (issue 12 section 3,
// "cover every initial state of one section for small widths").
//
// The section's zero-input recursion, as BandpassFixed computes it once its input has gone to 0
// (DF-I: the numerator terms vanish with x = 0):
//   acc  = -(A1 * y[n-1] + A2 * y[n-2])          exact (int128), coefficients A = round(a 2^F)
//   y[n] = fx_quantize(acc, F, data format)       the data word: W bits, its rounding, its overflow
// The state is (y[n-1], y[n-2]): every pair of W-bit codes, 2^(2W) initial states. The map
// state -> next state is a function on a finite set, so every trajectory ends in a cycle; the
// search visits each state once (functional-graph colouring) and reports, over all initial
// states, the cycles reached: their largest |y| in LSB and their period.
//
// The bound checked against it (tests/test_limit_cycle_search.cpp): for complex poles and
// rounding to nearest, a granular limit cycle behaves as if A2 were rounded to 1, so
// |y| <= floor(0.5 / (1 - A2/2^F)) LSB (Jackson's deadband bound); truncation (floor) can add
// up to one LSB per step instead of half, doubling it.
#include <cstdint>

#include "model/dsp/fixed_point.hpp"

namespace ranging {

struct LimitCycleSearch {
  int data_bits = 0;
  std::uint64_t states = 0;           // 2^(2 data_bits) initial states, every one visited
  std::uint64_t cycles = 0;           // distinct cycles (the rest state (0, 0) included)
  std::uint64_t nonzero_cycles = 0;   // cycles other than (0, 0)
  std::uint64_t states_into_nonzero = 0;  // initial states whose trajectory ends in a nonzero cycle
  std::int64_t max_amplitude_lsb = 0;     // largest |y| on any cycle
  int period_of_max = 0;                  // period of a cycle with that amplitude
  std::int64_t start_y1 = 0, start_y2 = 0;  // a state on that cycle
  std::uint64_t overflows = 0;            // overflow events over the whole search (one step per state)
};

// a1, a2: the section's integer feedback coefficients at coef_frac fraction bits. data: the
// data word (width 2..10: 2^20 states at most; InputError otherwise; frac is irrelevant to the
// zero-input recursion and ignored).
LimitCycleSearch exhaustive_limit_cycles(std::int64_t a1, std::int64_t a2, int coef_frac, const FixedFormat& data);

}  // namespace ranging
