#include "model/sim/fft.hpp"

#include <algorithm>
#include <new>

#include <fftw3.h>

namespace ranging {

std::mutex& fftw_planner_mutex() {
  static std::mutex m;
  return m;
}

namespace {

std::vector<double> convolve_direct(std::span<const double> a, std::span<const double> b) {
  std::vector<double> c(a.size() + b.size() - 1, 0.0);
  for (std::size_t n = 0; n < a.size(); ++n) {
    if (a[n] == 0.0) continue;
    const double an = a[n];
    double* cn = c.data() + n;
    for (std::size_t i = 0; i < b.size(); ++i) cn[i] += an * b[i];
  }
  return c;
}

// FFTW buffers and plans of one transform size, released (plans under the lock) on scope exit.
struct FftPair {
  std::size_t n;
  double* x = nullptr;
  fftw_complex* fa = nullptr;
  fftw_complex* fb = nullptr;
  fftw_plan fwd = nullptr, inv = nullptr;
  explicit FftPair(std::size_t size) : n(size) {
    x = fftw_alloc_real(n);
    fa = fftw_alloc_complex(n / 2 + 1);
    fb = fftw_alloc_complex(n / 2 + 1);
    if (!x || !fa || !fb) {
      release();
      throw std::bad_alloc();
    }
    const std::lock_guard<std::mutex> lock(fftw_planner_mutex());
    fwd = fftw_plan_dft_r2c_1d(static_cast<int>(n), x, fa, FFTW_ESTIMATE);
    inv = fftw_plan_dft_c2r_1d(static_cast<int>(n), fa, x, FFTW_ESTIMATE);
  }
  ~FftPair() { release(); }
  FftPair(const FftPair&) = delete;
  FftPair& operator=(const FftPair&) = delete;
  void release() {
    {
      const std::lock_guard<std::mutex> lock(fftw_planner_mutex());
      if (fwd) fftw_destroy_plan(fwd);
      if (inv) fftw_destroy_plan(inv);
    }
    fftw_free(x);
    fftw_free(fa);
    fftw_free(fb);
    fwd = inv = nullptr;
    x = nullptr;
    fa = fb = nullptr;
  }
  void forward(std::span<const double> v, fftw_complex* out) {
    std::fill(x, x + n, 0.0);
    std::copy(v.begin(), v.end(), x);
    fftw_execute_dft_r2c(fwd, x, out);
  }
};

}  // namespace

std::vector<double> convolve(std::span<const double> a, std::span<const double> b) {
  if (a.empty() || b.empty()) return {};
  if (std::min(a.size(), b.size()) <= kDirectTaps) {
    return a.size() >= b.size() ? convolve_direct(a, b) : convolve_direct(b, a);
  }
  const std::size_t len = a.size() + b.size() - 1;
  std::size_t n = 1;
  while (n < len) n *= 2;
  FftPair f(n);
  f.forward(a, f.fa);
  f.forward(b, f.fb);
  for (std::size_t k = 0; k <= n / 2; ++k) {
    const double re = f.fa[k][0] * f.fb[k][0] - f.fa[k][1] * f.fb[k][1];
    const double im = f.fa[k][0] * f.fb[k][1] + f.fa[k][1] * f.fb[k][0];
    f.fa[k][0] = re;
    f.fa[k][1] = im;
  }
  fftw_execute_dft_c2r(f.inv, f.fa, f.x);
  std::vector<double> c(f.x, f.x + len);
  const double scale = 1.0 / static_cast<double>(n);  // exact: n is a power of two
  for (double& v : c) v *= scale;
  return c;
}

}  // namespace ranging
