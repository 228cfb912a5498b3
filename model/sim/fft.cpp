#include "model/sim/fft.hpp"

#include <algorithm>
#include <initializer_list>
#include <new>
#include <string>

#include <fftw3.h>

#include "model/base/error.hpp"

namespace ranging {

std::mutex& fftw_planner_mutex() {
  static std::mutex m;
  return m;
}

namespace {
// FFTW_MEASURE wisdom of each correlation size (generated: bench/fft_wisdom_gen.cpp), so a plan
// imports its own size's entries only (about 1 KB; all sizes at once took 0.5 ms a plan).
struct SizeWisdom {
  std::size_t n;
  const char* wisdom;
};
constexpr SizeWisdom kCorrelationWisdom[] = {
#include "model/sim/fft_wisdom.inc"
};

const char* wisdom_of(std::size_t nfft) {
  for (const auto& w : kCorrelationWisdom) {
    if (w.n == nfft) return w.wisdom;
  }
  return nullptr;
}
}  // namespace

bool correlation_wisdom_applies() {
  const std::lock_guard<std::mutex> lock(fftw_planner_mutex());
  bool ok = true;
  for (const auto& w : kCorrelationWisdom) {
    fftw_forget_wisdom();
    ok = ok && fftw_import_wisdom_from_string(w.wisdom) != 0;
  }
  fftw_forget_wisdom();
  return ok;
}

CorrelationPlans plan_correlation(std::size_t nfft, double* in, fftw_complex* spec, fftw_complex* prod, double* out) {
  if (nfft < 1 || nfft > (std::size_t{1} << 30)) {
    throw InputError("plan_correlation: " + std::to_string(nfft) + " points; valid 1..2^30");
  }
  const int n = static_cast<int>(nfft);
  CorrelationPlans p;
  const std::lock_guard<std::mutex> lock(fftw_planner_mutex());
  // Only the wisdom's entries, then nothing: FFTW keeps wisdom process-wide, and what other plans
  // left there must not decide these two, nor these entries any later plan.
  fftw_forget_wisdom();
  const char* wisdom = wisdom_of(nfft);
  if (wisdom && fftw_import_wisdom_from_string(wisdom) != 0) {
    p.fwd = fftw_plan_dft_r2c_1d(n, in, spec, FFTW_MEASURE | FFTW_WISDOM_ONLY);
    p.inv = fftw_plan_dft_c2r_1d(n, prod, out, FFTW_MEASURE | FFTW_WISDOM_ONLY);
  }
  fftw_forget_wisdom();
  const auto complete = [&] {
    if (p.fwd && p.inv) return true;
    if (p.fwd) fftw_destroy_plan(p.fwd);
    if (p.inv) fftw_destroy_plan(p.inv);
    p.fwd = p.inv = nullptr;
    return false;
  };
  p.measured = complete();
  if (!p.measured) {
    p.fwd = fftw_plan_dft_r2c_1d(n, in, spec, FFTW_ESTIMATE);
    p.inv = fftw_plan_dft_c2r_1d(n, prod, out, FFTW_ESTIMATE);
    if (!complete()) throw std::bad_alloc();
  }
  return p;
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

std::size_t fft_size(std::size_t n) {
  if (n > (std::size_t{1} << 40)) throw InputError("fft_size: " + std::to_string(n) + " points; valid up to 2^40");
  if (n <= 1) return 1;
  std::size_t best = 1;
  while (best < n) best *= 2;  // the next power of two: < 2n
  // every 2^a 3^b 5^c 7^d >= n below best: the products of 3, 5, 7 powers, then doubled up to n
  for (std::size_t p7 = 1; p7 < best; p7 *= 7) {
    for (std::size_t p5 = p7; p5 < best; p5 *= 5) {
      for (std::size_t p3 = p5; p3 < best; p3 *= 3) {
        std::size_t v = p3;
        while (v < n) v *= 2;
        best = std::min(best, v);
      }
    }
  }
  return best;
}

std::size_t correlation_fft_size(std::size_t n) {
  if (n > 16384) return fft_size(n);
  std::size_t best = 1;
  while (best < n) best *= 2;
  for (std::size_t m : {3, 5}) {
    std::size_t v = m;
    while (v < n) v *= 2;
    best = std::min(best, v);
  }
  return best;
}

}  // namespace ranging
