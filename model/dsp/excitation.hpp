#pragma once
// Coded BPSK excitation (paper eq. 5/6, with the erratum in NOTES.md): every chip of a
// code is q carrier cycles of U*sin(2*pi*f*n/fs + (s(m)+1)*pi), n = 0..spc-1, placed at
// sample m*spc. A chip 1 therefore sends +U*sin, a chip 0 sends -U*sin.
// Also the two-level H-bridge drive an FPGA would put on the transmitter: the sign of
// that carrier, +1/-1 per sample.
#include <cstdint>
#include <span>
#include <vector>

namespace ranging {

struct ExcitationParams {
  double carrier_hz = 200e3;  // f: transducer centre frequency
  int cycles_per_chip = 4;    // q: carrier cycles per chip
  double fs = 5e6;            // sample rate of the excitation (= ADC rate in the paper)
  double amplitude = 1.0;     // U
};

// InputError naming the field and its range. samples per chip = cycles*fs/carrier must be
// an integer (so every chip starts at carrier phase 0 and the chips tile the sample grid).
void validate(const ExcitationParams& p);

// cycles_per_chip * fs / carrier_hz (100 for the defaults). Validates p.
int samples_per_chip(const ExcitationParams& p);

// Eq. 5/6: length chips.size() * samples_per_chip. Chip values must be 0 or 1.
std::vector<double> bpsk_excitation(std::span<const std::uint8_t> chips, const ExcitationParams& p);

// Sign of the eq. 5 carrier: +1 where the carrier phase (mod 2*pi) is in [0, pi), -1 in
// [pi, 2*pi). The phase is computed exactly in integers, so the drive of a chip 0 is the
// exact negation of that of a chip 1. Never 0. Same length as bpsk_excitation.
std::vector<std::int8_t> hbridge_drive(std::span<const std::uint8_t> chips, const ExcitationParams& p);

}  // namespace ranging
