#pragma once
// iCE40 SB_PLL40 settings (SIMPLE feedback) that make f_out from f_in exactly, searched like
// icestorm's icepll: F_PFD = f_in / (DIVR+1) in [10, 133] MHz, F_VCO = F_PFD (DIVF+1) in
// [533, 1066] MHz, f_out = F_VCO / 2^DIVQ (DIVQ 1..6). find_ice40_pll returns none when no
// setting is exact; ice40_pll throws InputError naming clk_hz then. The board (iCEBreaker) has a
// 12 MHz oscillator: kBoardOscillatorHz.
#include <optional>

namespace ranging {

inline constexpr double kBoardOscillatorHz = 12e6;

struct Ice40Pll {
  int divr = 0, divf = 0, divq = 0, filter_range = 0;
  double f_pfd = 0, f_vco = 0, f_out = 0;
};
std::optional<Ice40Pll> find_ice40_pll(double f_in, double f_out);
Ice40Pll ice40_pll(double f_in, double f_out);

}  // namespace ranging
