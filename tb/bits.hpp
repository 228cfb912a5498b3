#pragma once
// Bit helpers shared by every testbench (Verilator, Icarus, SystemC): no simulator headers.
#include <cstdint>

namespace ranging::tb {

// Two's complement value of the low `width` bits of `raw` (1 <= width <= 64; bits above
// `width` are ignored).
inline std::int64_t sign_extend(std::uint64_t raw, int width) {
  if (width >= 64) return static_cast<std::int64_t>(raw);
  const std::uint64_t m = std::uint64_t{1} << (width - 1);
  raw &= (std::uint64_t{1} << width) - 1;
  return static_cast<std::int64_t>(raw ^ m) - static_cast<std::int64_t>(m);
}

}  // namespace ranging::tb
