#pragma once
// FFTW helpers of the simulators: the planner lock and a linear convolution.
//
// FFTW's planner is not thread-safe (only fftw_execute is): every plan of the project is made
// and destroyed under fftw_planner_mutex(), so threads (sweep --jobs, SceneSimulator::set_jobs)
// can each own plans.
//
// convolve(a, b) = c, c[k] = sum_i a[i] b[k - i], length |a| + |b| - 1 (the full linear
// convolution). When the shorter operand has at most kDirectTaps entries it is the direct sum
// in double, in the order i = 0, 1, ... (entries of `a` that are exactly 0 are skipped: a
// sparse burst costs only its non-zero samples); otherwise it is an r2c / c2r FFTW transform
// pair on the next power of two >= |c| (FFTW_ESTIMATE plans), whose results differ from the
// direct sum by the transforms' rounding, about 1e-16 of the largest |c| (tested against the
// direct sum).
#include <cstddef>
#include <mutex>
#include <span>
#include <vector>

namespace ranging {

std::mutex& fftw_planner_mutex();

inline constexpr std::size_t kDirectTaps = 64;

std::vector<double> convolve(std::span<const double> a, std::span<const double> b);

// The smallest n' >= n whose only prime factors are 2, 3, 5 and 7 (FFTW's fast sizes): a
// transform of n' points costs about what one of n does, where the next power of two may
// cost up to twice as much. n <= 2^40 (InputError beyond).
std::size_t fft_size(std::size_t n);

// The transform size of a correlation over n points with FFTW_ESTIMATE plans (PearsonBank):
// n <= 16384: the smallest 2^a, 3 2^a or 5 2^a >= n (at most 4/3 n), whose estimated plans
// ran 1.1-4.8x faster than those of the fft_size() between them on the machine of
// docs/results/speed.md; beyond, fft_size(n) (where the powers of two ran slower).
std::size_t correlation_fft_size(std::size_t n);

}  // namespace ranging
