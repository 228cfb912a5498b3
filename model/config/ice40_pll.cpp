#include "model/config/ice40_pll.hpp"

#include <cmath>
#include <sstream>

#include "model/base/error.hpp"

namespace ranging {

std::optional<Ice40Pll> find_ice40_pll(double f_in, double f_out) {
  for (int divr = 0; divr <= 15; ++divr) {
    const double pfd = f_in / (divr + 1);
    if (pfd < 10e6 || pfd > 133e6) continue;
    for (int divf = 0; divf <= 127; ++divf) {
      const double vco = pfd * (divf + 1);
      if (vco < 533e6 || vco > 1066e6) continue;
      for (int divq = 1; divq <= 6; ++divq) {
        const double out = vco / static_cast<double>(1 << divq);
        if (std::abs(out - f_out) > 1e-3) continue;
        Ice40Pll p{divr, divf, divq, 0, pfd, vco, out};
        // icepll's loop filter ranges by F_PFD
        p.filter_range = pfd < 17e6 ? 1 : pfd < 26e6 ? 2 : pfd < 44e6 ? 3 : pfd < 66e6 ? 4 : pfd < 101e6 ? 5 : 6;
        return p;
      }
    }
  }
  return std::nullopt;
}

Ice40Pll ice40_pll(double f_in, double f_out) {
  if (const auto p = find_ice40_pll(f_in, f_out)) return *p;
  std::ostringstream os;
  os << "clk_hz: " << f_out << " Hz cannot be made exactly from the " << f_in
     << " Hz oscillator by the iCE40 PLL (e.g. 30 MHz or 45 MHz from 12 MHz can)";
  throw InputError(os.str());
}

}  // namespace ranging
