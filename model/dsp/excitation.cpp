#include "model/dsp/excitation.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "model/base/error.hpp"

namespace ranging {

void validate(const ExcitationParams& p) {
  require_in_range("fs", p.fs, 1.0, 1e10);
  // Below Nyquist with margin: the carrier must be representable.
  require_in_range("carrier_hz", p.carrier_hz, 1e-3, p.fs / 2.0);
  require_in_range("cycles_per_chip", p.cycles_per_chip, 1, 1000);
  require_in_range("amplitude", p.amplitude, 0.0, 1e9);
  const double spc = p.cycles_per_chip * p.fs / p.carrier_hz;
  const double rounded = std::round(spc);
  if (std::abs(spc - rounded) > 1e-9 * spc || rounded < 2 || rounded > 1e7) {
    std::ostringstream os;
    os << "cycles_per_chip, fs, carrier_hz: samples per chip = cycles_per_chip*fs/carrier_hz = " << spc
       << " must be an integer in [2, 1e7]";
    throw InputError(os.str());
  }
}

int samples_per_chip(const ExcitationParams& p) {
  validate(p);
  return static_cast<int>(std::lround(p.cycles_per_chip * p.fs / p.carrier_hz));
}

namespace {
void check_chips(std::span<const std::uint8_t> chips) {
  if (chips.empty()) throw InputError("chips: code is empty; need at least 1 chip");
  for (std::size_t m = 0; m < chips.size(); ++m) {
    if (chips[m] > 1) {
      throw InputError("chips[" + std::to_string(m) + "]: " + std::to_string(chips[m]) +
                       " is out of range; valid values are 0 and 1");
    }
  }
}
}  // namespace

std::vector<double> bpsk_excitation(std::span<const std::uint8_t> chips, const ExcitationParams& p) {
  const int spc = samples_per_chip(p);
  check_chips(chips);
  const auto uspc = static_cast<std::size_t>(spc);
  const auto cycles = static_cast<std::uint64_t>(p.cycles_per_chip);
  // One chip of +U*sin; the phase is reduced exactly (cycles*n mod spc) so the zero
  // crossings are exact zeros. (s+1)*pi adds 2*pi (chip 1) or pi (chip 0): a sign.
  std::vector<double> chip_wave(uspc);
  for (std::size_t n = 0; n < uspc; ++n) {
    const double frac = static_cast<double>((cycles * n) % uspc) / static_cast<double>(uspc);
    chip_wave[n] = p.amplitude * std::sin(2.0 * std::numbers::pi * frac);
  }
  std::vector<double> out(chips.size() * uspc);
  for (std::size_t m = 0; m < chips.size(); ++m) {
    const double sign = chips[m] ? 1.0 : -1.0;
    for (std::size_t n = 0; n < uspc; ++n) out[m * uspc + n] = sign * chip_wave[n];
  }
  return out;
}

std::vector<std::int8_t> hbridge_drive(std::span<const std::uint8_t> chips, const ExcitationParams& p) {
  const int spc = samples_per_chip(p);
  check_chips(chips);
  const auto uspc = static_cast<std::uint64_t>(spc);
  const auto cycles = static_cast<std::uint64_t>(p.cycles_per_chip);
  std::vector<std::int8_t> out(chips.size() * uspc);
  for (std::size_t m = 0; m < chips.size(); ++m) {
    for (std::uint64_t n = 0; n < uspc; ++n) {
      // phase / (2*pi) = cycles*n/spc + (s+1)/2; scaled by 2*spc it is an exact integer.
      const std::uint64_t ph = (2 * cycles * n + (chips[m] + 1u) * uspc) % (2 * uspc);
      out[m * uspc + n] = ph < uspc ? std::int8_t{1} : std::int8_t{-1};
    }
  }
  return out;
}

}  // namespace ranging
