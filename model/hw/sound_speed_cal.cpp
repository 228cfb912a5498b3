#include "model/hw/sound_speed_cal.hpp"

#include <cmath>
#include <stdexcept>

namespace ranging {

std::uint32_t calibrated_speed_register(std::uint32_t tof_q, std::uint64_t distance_um, int sh, bool* saturated) {
  if (tof_q == 0) throw std::logic_error("calibrated_speed_register: ToF 0");
  if (sh < 0 || sh > 60) throw std::logic_error("calibrated_speed_register: shift out of range");
  const unsigned __int128 num = (static_cast<unsigned __int128>(distance_um) << sh) + (tof_q >> 1);
  const unsigned __int128 q = num / tof_q;
  const bool sat = q > 0xffffffffULL;
  if (saturated) *saturated = sat;
  return sat ? 0xffffffffU : static_cast<std::uint32_t>(q);
}

double speed_of_register(std::uint32_t c, double fs, int c_frac) {
  return std::ldexp(static_cast<double>(c), -c_frac) * 1e-6 * fs;
}

}  // namespace ranging
