#pragma once
// The receiver's analog front end in every simulator (scenes, rotor crossings, the single-link
// channel): white Gaussian noise, then the ADC. One implementation of each, so that every
// simulator draws the same noise for the same seed and quantizes the same way.
//
// Noise: x[n] += sigma * g[n], g[n] ~ N(0, 1) i.i.d., drawn by Boost.Random's
// normal_distribution (a ziggurat, one 64-bit draw per value in ~99 % of the cases) from
// boost::random::mt19937_64 seeded with `seed`. Deterministic for a seed and a Boost version
// (Debian 12: 1.74); a stream's draws depend on its seed alone, so they never depend on threads
// or order. About 5 ns per sample (scripts/bench.sh: BM_WhiteNoise), 4x faster than
// std::normal_distribution's polar method it replaced.
//
// ADC (SceneAdc in model/sim/scene.hpp): code = clamp(round((v + dc_offset_v) / q),
// -2^(bits-1), 2^(bits-1) - 1), q = full_scale_v / 2^(bits-1), round = to nearest, ties away
// from zero (std::round); a stuck bit forces bit stuck_bit of the two's-complement code after
// clipping; the output is code * q volts. Every sample whose rounded code lay outside the range
// is clipped and its index appended to *clipped (when not null): a clipped ADC is always
// reported by the caller. bits in 2..24 (else InputError): the code is an int32, computed from
// the value clamped to [-2^(bits-1) - 1, 2^(bits-1)] before rounding (the same code and the
// same clipping as rounding first; NaN goes to the negative rail). About 3 ns per sample.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace ranging {

struct SceneAdc;

// x[n] += sigma * N(0, 1), drawn from `seed`: boost::random::normal_distribution<double>(0, 1)
// on boost::random::mt19937_64(seed), bit for bit (eight draws at a time); sigma <= 0 adds
// nothing (no draw).
void add_white_noise(std::span<double> x, double sigma, std::uint64_t seed);

// The ADC in place (volts in, quantized volts out: round half away from zero, the codes
// clamped to the rails, NaN on the low rail); returns the number of clipped samples and
// appends their indices to *clipped when it is not null.
std::size_t adc_quantize(std::span<double> x, const SceneAdc& adc, std::vector<std::size_t>* clipped);

}  // namespace ranging
