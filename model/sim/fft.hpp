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

#include <fftw3.h>

namespace ranging {

std::mutex& fftw_planner_mutex();

inline constexpr std::size_t kDirectTaps = 64;

std::vector<double> convolve(std::span<const double> a, std::span<const double> b);

// The smallest n' >= n whose only prime factors are 2, 3, 5 and 7 (FFTW's fast sizes): a
// transform of n' points costs about what one of n does, where the next power of two may
// cost up to twice as much. n <= 2^40 (InputError beyond).
std::size_t fft_size(std::size_t n);

// The transform size of a correlation over n points (PearsonBank):
// n <= 16384: the smallest 2^a, 3 2^a or 5 2^a >= n (at most 4/3 n), whose estimated plans
// ran 1.1-4.8x faster than those of the fft_size() between them on the machine of
// docs/results/speed.md (measured plans too: 2560 points 2.3-2.4 us per transform, 2400 2.6-2.7,
// 2304 2.5); beyond, fft_size(n) (where the powers of two ran slower).
std::size_t correlation_fft_size(std::size_t n);

// The largest n for which correlation_fft_size(n) is one of the sizes the wisdom below covers.
inline constexpr std::size_t kCorrelationWisdomPoints = 16384;

// The real transform pair of a correlation over nfft points (PearsonBank): fwd r2c in -> spec,
// inv c2r prod -> out (prod is destroyed), made under fftw_planner_mutex(). The caller destroys
// them under the same lock.
// measured: both plans are FFTW_MEASURE plans taken from the project's wisdom
// (model/sim/fft_wisdom.inc, written by bench/fft_wisdom_gen.cpp for max(64, correlation_fft_size(n)),
// n <= kCorrelationWisdomPoints). It applies when this process's FFTW has the solvers it names
// (the same FFTW version and SIMD extensions as the machine that measured it); its plans ran
// 1.2-1.5x faster than FFTW_ESTIMATE's and cost no planning (an estimate of 2560 points: 4-6 ms).
// Otherwise (or for a size it lacks) both are FFTW_ESTIMATE plans. Either way the result is the
// correlation to the transforms' rounding (a few ulps of rho); which plans a process gets is fixed
// by its machine, so repeated runs and any thread count give the same bits. The wisdom is
// imported for these two plans only and forgotten after: no other plan of the process changes.
struct CorrelationPlans {
  fftw_plan fwd = nullptr, inv = nullptr;
  bool measured = false;
};
CorrelationPlans plan_correlation(std::size_t nfft, double* in, fftw_complex* spec, fftw_complex* prod, double* out);

// Whether the project's wisdom imports into this process's FFTW (see plan_correlation).
bool correlation_wisdom_applies();

}  // namespace ranging
