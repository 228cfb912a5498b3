#include "model/dsp/limit_cycle_search.hpp"

#include <algorithm>
#include <cstdlib>
#include <string>
#include <vector>

#include "model/base/error.hpp"

namespace ranging {

LimitCycleSearch exhaustive_limit_cycles(std::int64_t a1, std::int64_t a2, int coef_frac, const FixedFormat& data) {
  require_in_range("data_bits", data.width, 2, 10);
  require_in_range("coef_frac", coef_frac, 0, 40);
  require_in_range("a1", static_cast<double>(a1), -1e15, 1e15);
  require_in_range("a2", static_cast<double>(a2), -1e15, 1e15);
  FixedFormat fmt = data;
  fmt.is_signed = true;
  fmt.frac = 0;  // codes are LSB units; the recursion is scale-free
  const int w = data.width;
  const std::int64_t lo = -(std::int64_t{1} << (w - 1)), n = std::int64_t{1} << w;
  const auto index = [&](std::int64_t y1, std::int64_t y2) { return static_cast<std::size_t>((y1 - lo) * n + (y2 - lo)); };
  const std::size_t total = static_cast<std::size_t>(n * n);
  LimitCycleSearch r;
  r.data_bits = w;
  r.states = total;
  OverflowCounter ovf;
  std::vector<std::uint32_t> next(total);
  for (std::int64_t y1 = lo; y1 < lo + n; ++y1) {
    for (std::int64_t y2 = lo; y2 < lo + n; ++y2) {
      const int128_t acc = -(static_cast<int128_t>(a1) * y1 + static_cast<int128_t>(a2) * y2);
      const std::int64_t y = fx_quantize(acc, coef_frac, fmt, &ovf);
      next[index(y1, y2)] = static_cast<std::uint32_t>(index(y, y1));
    }
  }
  r.overflows = ovf.total();
  // Colouring: 0 unvisited, 1 on the current path, 2 done. ends[s]: the cycle id s ends in.
  std::vector<std::uint8_t> colour(total, 0);
  std::vector<std::int32_t> ends(total, -1);
  std::vector<bool> cycle_nonzero;
  std::vector<std::size_t> path;
  const auto y_of = [&](std::size_t s) { return static_cast<std::int64_t>(s / static_cast<std::size_t>(n)) + lo; };
  for (std::size_t s0 = 0; s0 < total; ++s0) {
    if (colour[s0]) continue;
    path.clear();
    std::size_t s = s0;
    while (colour[s] == 0) {
      colour[s] = 1;
      path.push_back(s);
      s = next[s];
    }
    std::int32_t id;
    if (colour[s] == 1) {  // a new cycle: from s to the end of the path
      id = static_cast<std::int32_t>(cycle_nonzero.size());
      const auto at = std::find(path.begin(), path.end(), s);
      std::int64_t amp = 0;
      for (auto it = at; it != path.end(); ++it) amp = std::max(amp, std::abs(y_of(*it)));
      const int period = static_cast<int>(path.end() - at);
      cycle_nonzero.push_back(amp != 0);
      ++r.cycles;
      if (amp != 0) ++r.nonzero_cycles;
      if (amp > r.max_amplitude_lsb || (amp == r.max_amplitude_lsb && r.period_of_max == 0)) {
        r.max_amplitude_lsb = amp;
        r.period_of_max = period;
        r.start_y1 = y_of(s);
        r.start_y2 = static_cast<std::int64_t>(s % static_cast<std::size_t>(n)) + lo;
      }
    } else {
      id = ends[s];
    }
    for (std::size_t p : path) {
      colour[p] = 2;
      ends[p] = id;
    }
  }
  for (std::size_t s = 0; s < total; ++s) r.states_into_nonzero += cycle_nonzero[static_cast<std::size_t>(ends[s])];
  return r;
}

}  // namespace ranging
