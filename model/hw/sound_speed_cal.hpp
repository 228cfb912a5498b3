#pragma once
// Sound-velocity compensation (paper section 3.1, issue 14 §6): the bit-exact model of
// rtl/sound_speed_cal.v. A reference path at the calibrated distance D (micrometres) gives the
// time of flight ToF (full-rate samples, frac_w fraction bits, rtl/tof_distance.v); the speed
// register of tof_distance (micrometres per full-rate sample, c_frac fraction bits) becomes
//     C = floor((D 2^SH + floor(ToF / 2)) / ToF),   SH = frac_w + c_frac
// (D / ToF rounded half up), saturated at 2^32 - 1. Afterwards tof_distance's distance
// (ToF C + 2^(SH-1)) >> SH reads D on the reference path and scales every other ToF by the
// measured speed: the distance error of a path d with the channel's c != the assumed one is
// then d (ToF_ref quantization and latency-calibration error) instead of d (c_assumed/c - 1).
#include <cstdint>

namespace ranging {

// In the RTL's units; *saturated (if given) tells C clipped at 2^32 - 1. tof_q must be > 0.
std::uint32_t calibrated_speed_register(std::uint32_t tof_q, std::uint64_t distance_um, int sh,
                                        bool* saturated = nullptr);

// The speed of sound (m/s) that a register value stands for at fs: C 2^-c_frac um per sample.
double speed_of_register(std::uint32_t c, double fs, int c_frac);

}  // namespace ranging
