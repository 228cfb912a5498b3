#include "model/sim/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <complex>
#include <new>
#include <limits>
#include <mutex>
#include <sstream>
#include <string>

#include <fftw3.h>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "model/base/error.hpp"
#include "model/sim/fft.hpp"
#include "model/base/transpose8.hpp"

namespace ranging {

namespace {

// Valid lag range [lo, hi] of an N-sample reference over x, or InputError.
std::pair<long, long> valid_lags(std::size_t nx, std::size_t n, long lo, long hi) {
  if (n < 2) throw InputError("pearson search: reference has " + std::to_string(n) + " samples; needs >= 2");
  const long top = static_cast<long>(nx) - static_cast<long>(n);
  const long a = std::max(lo, 0L), b = std::min(hi, top);
  if (a > b) {
    throw InputError("pearson search: no lag of [" + std::to_string(lo) + ", " + std::to_string(hi) +
                     "] keeps a " + std::to_string(n) + "-sample reference inside a " + std::to_string(nx) +
                     "-sample signal");
  }
  return {a, b};
}

}  // namespace

LagRho pearson_over_lags(std::span<const double> x, std::span<const double> t, long lo, long hi) {
  const auto [a, b] = valid_lags(x.size(), t.size(), lo, hi);
  LagRho best{-2.0, a};
  for (long k = a; k <= b; ++k) {
    const double r = pearson(x.subspan(static_cast<std::size_t>(k), t.size()), t);
    if (r > best.rho) best = {r, k};
  }
  return best;
}

// Plans are made and destroyed under fftw_planner_mutex() (model/sim/fft.hpp), so PearsonBanks
// of different threads (sweep --jobs, SceneSimulator::set_jobs) coexist.
struct PearsonBank::Plan {
  std::size_t nfft = 0;
  // The transforms' arrays, 64-byte aligned (fftw_alloc gives 32: an AVX-512 loop over them
  // would then split every load across two cache lines; FFTW plans the same for either).
  AlignedVector<double> in, out;
  AlignedVector<std::complex<double>> spec, prod;
  fftw_plan fwd = nullptr, inv = nullptr;
  std::vector<AlignedVector<std::complex<double>>> tspec;  // conj FFT of each centred template
  ~Plan() {
    const std::lock_guard<std::mutex> lock(fftw_planner_mutex());
    if (fwd) fftw_destroy_plan(fwd);
    if (inv) fftw_destroy_plan(inv);
  }
};

PearsonBank::PearsonBank(std::vector<std::vector<double>> templates, std::size_t max_lags) : max_lags_(max_lags) {
  if (templates.empty()) throw InputError("PearsonBank: no references");
  n_ = templates.front().size();
  if (n_ < 2) throw InputError("PearsonBank: references have " + std::to_string(n_) + " samples; need >= 2");
  for (auto& t : templates) {
    if (t.size() != n_) {
      throw InputError("PearsonBank: references have lengths " + std::to_string(n_) + " and " +
                       std::to_string(t.size()) + "; they must be equal");
    }
    double m = 0;
    for (double v : t) m += v;
    m /= static_cast<double>(n_);
    double ss = 0;
    for (double& v : t) {
      v -= m;
      ss += v * v;
    }
    tnorm_.push_back(std::sqrt(ss));
    t_.push_back(std::move(t));
  }
}

PearsonBank::~PearsonBank() = default;

std::size_t PearsonBank::transform_size(std::size_t window) { return std::max<std::size_t>(64, correlation_fft_size(window)); }

void PearsonBank::prepare() {
  if (max_lags_ > 0) (void)plan(transform_size(max_lags_ + n_ - 1));
}

PearsonBank::Plan& PearsonBank::plan(std::size_t nfft) {
  if (auto it = plans_.find(nfft); it != plans_.end()) return *it->second;
  auto p = std::make_unique<Plan>();
  p->nfft = nfft;
  const std::size_t nc = nfft / 2 + 1;
  p->in.assign(nfft, 0.0);
  p->out.assign(nfft, 0.0);
  p->spec.assign(nc, 0.0);
  p->prod.assign(nc, 0.0);
  auto* spec = reinterpret_cast<fftw_complex*>(p->spec.data());
  auto* prod = reinterpret_cast<fftw_complex*>(p->prod.data());
  const CorrelationPlans made = plan_correlation(nfft, p->in.data(), spec, prod, p->out.data());
  p->fwd = made.fwd;
  p->inv = made.inv;
  for (const auto& t : t_) {
    std::fill(p->in.begin(), p->in.end(), 0.0);
    std::copy(t.begin(), t.end(), p->in.begin());
    fftw_execute(p->fwd);
    AlignedVector<std::complex<double>> c(nc);
    for (std::size_t i = 0; i < nc; ++i) c[i] = std::conj(p->spec[i]);
    p->tspec.push_back(std::move(c));
  }
  return *plans_.emplace(nfft, std::move(p)).first->second;
}

namespace {
// A function with an AVX-512 clone beside the baseline one, picked at load time by the CPU.
#if defined(__x86_64__)
#define RANGING_CLONE_V4 [[gnu::target_clones("default", "arch=x86-64-v4")]]
#else
#define RANGING_CLONE_V4
#endif

typedef double V8 __attribute__((vector_size(64)));
// The largest / smallest of the eight lanes, by blends and whole-vector shuffles (GCC 12 turns a
// vector of comparison masks into scalar inserts; blends it keeps in the vector unit). Inlined
// into each clone (no ISA of their own).
[[gnu::always_inline]] inline double lanes_max(V8 m) {
  V8 t = __builtin_shufflevector(m, m, 4, 5, 6, 7, 0, 1, 2, 3);
  m = m > t ? m : t;
  t = __builtin_shufflevector(m, m, 2, 3, 0, 1, 6, 7, 4, 5);
  m = m > t ? m : t;
  t = __builtin_shufflevector(m, m, 1, 0, 3, 2, 5, 4, 7, 6);
  m = m > t ? m : t;
  return m[0];
}
[[gnu::always_inline]] inline double lanes_min(V8 m) {
  V8 t = __builtin_shufflevector(m, m, 4, 5, 6, 7, 0, 1, 2, 3);
  m = m < t ? m : t;
  t = __builtin_shufflevector(m, m, 2, 3, 0, 1, 6, 7, 4, 5);
  m = m < t ? m : t;
  t = __builtin_shufflevector(m, m, 1, 0, 3, 2, 5, 4, 7, 6);
  m = m < t ? m : t;
  return m[0];
}

// The centred window's sums, in eight independent chains (a single running sum is one add per
// four cycles; eight keep the adder busy), every operation in a fixed order, so the AVX-512
// clone and the baseline give the same bits:
//   mean = (sum over lanes u = 0..7 in order of S_u) / w, S_u = sum of x[i], i = u mod 8, i ascending;
//   v_i = x_i - mean into in[i]; s1, s2 (w + 1 entries, s[0] = 0): the prefix sums of v and v^2
//   in eight chunks of ceil(w / 8) consecutive samples, each summed from its start, then each
//   chunk's entries plus the sum of the chunks before it (added chunk by chunk, in order).
RANGING_CLONE_V4 void centred_sums(const double* x, std::size_t w, double* in, double* s1, double* s2) {
  double lane[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  std::size_t i = 0;
  for (; i + 8 <= w; i += 8) {
    for (std::size_t u = 0; u < 8; ++u) lane[u] += x[i + u];
  }
  for (std::size_t u = 0; i < w; ++i, ++u) lane[u] += x[i];
  double total = 0;
  for (double v : lane) total += v;
  const double mean = total / static_cast<double>(w);
  const std::size_t len = (w + 7) / 8;
  double a1[8] = {0, 0, 0, 0, 0, 0, 0, 0}, a2[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  s1[0] = s2[0] = 0;
  // While every chunk has eight more samples: chunk c on lane c, eight steps per 8 x 8
  // transpose in and out (the scalar loop's operations, lane by lane).
  const std::size_t full = w > 7 * len ? w - 7 * len : 0;  // samples every chunk has
  const V8 m = V8{} + mean;
  V8 c1{}, c2{};
  std::size_t j = 0;
  for (; j + 8 <= full; j += 8) {
    V8 r[8], o1[8], o2[8];
    for (std::size_t c = 0; c < 8; ++c) std::memcpy(&r[c], x + c * len + j, sizeof(V8));
    transpose8(r);
    for (std::size_t t = 0; t < 8; ++t) {
      const V8 v = r[t] - m;
      r[t] = v;
      c1 += v;
      c2 += v * v;
      o1[t] = c1;
      o2[t] = c2;
    }
    transpose8(r);
    transpose8(o1);
    transpose8(o2);
    for (std::size_t c = 0; c < 8; ++c) {
      std::memcpy(in + c * len + j, &r[c], sizeof(V8));
      std::memcpy(s1 + c * len + j + 1, &o1[c], sizeof(V8));
      std::memcpy(s2 + c * len + j + 1, &o2[c], sizeof(V8));
    }
  }
  for (std::size_t c = 0; c < 8; ++c) a1[c] = c1[c], a2[c] = c2[c];
  for (; j < len; ++j) {
    for (std::size_t c = 0; c < 8; ++c) {
      const std::size_t k = c * len + j;
      if (k >= w) continue;
      const double v = x[k] - mean;
      in[k] = v;
      a1[c] += v;
      a2[c] += v * v;
      s1[k + 1] = a1[c];
      s2[k + 1] = a2[c];
    }
  }
  double o1 = 0, o2 = 0;
  for (std::size_t c = 1; c < 8 && c * len < w; ++c) {
    o1 += a1[c - 1];
    o2 += a2[c - 1];
    const std::size_t end = std::min(w, (c + 1) * len);
    for (std::size_t k = c * len; k < end; ++k) {
      s1[k + 1] += o1;
      s2[k + 1] += o2;
    }
  }
}

// Per lag k < lags of the window (prefix sums s1, s2 of x - mean): var_k = max(0, S2 - S1^2 / N)
// over x[k, k + N), into var; returns the floor: var_k <= floor (1e-24 of the largest, or 0)
// means a flat window, den_k = 0 and rho = 0 there; otherwise den_k = sqrt(var_k) (den_of()).
// Every lag on its own, IEEE operations only (divide, max), so the AVX-512 clone (picked at load
// time on a CPU that has it) gives the baseline's bits.
RANGING_CLONE_V4 double lag_variances(const double* s1, const double* s2, std::size_t n, std::size_t lags,
                                      double* var) {
  const auto nd = static_cast<double>(n);
  for (std::size_t k = 0; k < lags; ++k) {
    const double m1 = s1[k + n] - s1[k];
    var[k] = std::max(0.0, (s2[k + n] - s2[k]) - m1 * m1 / nd);
  }
  // the largest variance: max is exact and the variances are not NaN, so any order gives it
  double m8[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  std::size_t k = 0;
  for (; k + 8 <= lags; k += 8) {
    for (std::size_t u = 0; u < 8; ++u) m8[u] = std::max(m8[u], var[k + u]);
  }
  for (; k < lags; ++k) m8[0] = std::max(m8[0], var[k]);
  double var_max = 0;
  for (double v : m8) var_max = std::max(var_max, v);
  return 1e-24 * var_max;
}

// den_k from var_k and the floor (metrics.cpp is built with -fno-math-errno, so sqrt is the
// instruction; the argument is never negative, errno was never set).
inline double den_of(double v, double floor) { return v > floor && v > 0 ? std::sqrt(v) : 0.0; }

// The screen's inv_den_k, for k < lags: 1 / den_k, 0 where den_k = 0. The screen needs it to
// about 1e-13 (relative; search()'s margin is 1e-12), never its bits: rho is computed from den_k
// itself. Baseline: 1.0 / den_k (a sqrt and a divide per lag). AVX-512 (picked once, by the
// CPU): rsqrt14 (relative error < 2^-14) and two Newton steps y (3 - v y^2) / 2, relative error
// below 1e-15 for var_k in [1e-290, 1e290] (a group of eight with a lag outside that range takes
// the baseline's way); the lags at or below the floor get 0 either way.
void inv_den_scalar(const double* var, std::size_t k0, std::size_t k1, double floor, double* inv) {
  for (std::size_t k = k0; k < k1; ++k) {
    const double d = den_of(var[k], floor);
    inv[k] = d > 0 ? 1.0 / d : 0.0;
  }
}
#if defined(__x86_64__)
[[gnu::target("avx512f")]] void inv_den_avx512(const double* var, std::size_t lags, double floor, double* inv) {
  const __m512d half = _mm512_set1_pd(0.5), three_halves = _mm512_set1_pd(1.5), fl = _mm512_set1_pd(floor);
  const __m512d zero = _mm512_setzero_pd(), small = _mm512_set1_pd(1e-290), large = _mm512_set1_pd(1e290);
  std::size_t k = 0;
  for (; k + 8 <= lags; k += 8) {
    const __m512d v = _mm512_loadu_pd(var + k);
    const __mmask8 on = _mm512_cmp_pd_mask(v, fl, _CMP_GT_OQ) & _mm512_cmp_pd_mask(v, zero, _CMP_GT_OQ);
    const __mmask8 safe = _mm512_cmp_pd_mask(v, small, _CMP_GE_OQ) & _mm512_cmp_pd_mask(v, large, _CMP_LE_OQ);
    if ((on & ~safe) != 0) {
      inv_den_scalar(var, k, k + 8, floor, inv);
      continue;
    }
    const __m512d hv = _mm512_mul_pd(half, v);
    __m512d y = _mm512_maskz_rsqrt14_pd(0xFF, v);  // (the unmasked form trips GCC 12's -Wmaybe-uninitialized)
    for (int step = 0; step < 2; ++step) y = _mm512_mul_pd(y, _mm512_fnmadd_pd(_mm512_mul_pd(hv, y), y, three_halves));
    _mm512_storeu_pd(inv + k, _mm512_maskz_mov_pd(on, y));
  }
  inv_den_scalar(var, k, lags, floor, inv);
}
#endif
void inv_den(const double* var, std::size_t lags, double floor, double* inv) {
#if defined(__x86_64__)
  static const bool avx512 = __builtin_cpu_supports("avx512f");
  if (avx512) return inv_den_avx512(var, lags, floor, inv);
#endif
  inv_den_scalar(var, 0, lags, floor, inv);
}

// The screen's g_k = o_k inv_den_k (one IEEE multiply: both functions below compute the same
// bits, so g is not stored between them), in blocks of kScreenBlock = 64 lags.
// screen_max: the largest g_k, k < lags, and per block b its lanes' maxima bm[8 b, 8 b + 8) (lane
// u: the largest g_k of the block with k = u mod 8; a last partial block's scalar maximum in lane
// 0, the other lanes -inf). max is exact and the products are finite, so any order of the maximum
// gives the same bits (the AVX-512 clone, the baseline). bm holds 8 ceil(lags / 64) entries.
constexpr std::size_t kScreenBlock = 64;
RANGING_CLONE_V4 double screen_max(const double* o, const double* inv_den, std::size_t lags, double* bm) {
  V8 m = V8{} - HUGE_VAL;
  std::size_t k = 0, b = 0;
  for (; k + kScreenBlock <= lags; k += kScreenBlock, ++b) {
    V8 mb = V8{} - HUGE_VAL;
    for (std::size_t u = 0; u < kScreenBlock; u += 8) {
      V8 a, c;
      std::memcpy(&a, o + k + u, sizeof a);
      std::memcpy(&c, inv_den + k + u, sizeof c);
      const V8 p = a * c;
      mb = mb < p ? p : mb;  // std::max per lane
    }
    std::memcpy(bm + 8 * b, &mb, sizeof mb);
    m = m < mb ? mb : m;
  }
  double gmax = lanes_max(m);
  if (k < lags) {
    double t = -HUGE_VAL;
    for (; k < lags; ++k) t = std::max(t, o[k] * inv_den[k]);
    V8 mb = V8{} - HUGE_VAL;
    mb[0] = t;
    std::memcpy(bm + 8 * b, &mb, sizeof mb);
    gmax = std::max(gmax, t);
  }
  return gmax;
}

// The indices k < lags with g_k >= lo, in increasing order, into idx; returns how many. A block
// whose maxima bm (screen_max's) are all below lo (most: only lags near the peak pass) is skipped
// in one test; the others are read lag by lag.
RANGING_CLONE_V4 std::size_t lags_at_least(const double* o, const double* inv_den, std::size_t lags, double lo,
                                           const double* bm, std::size_t* idx) {
  std::size_t c = 0;
  for (std::size_t k = 0, b = 0; k < lags; k += kScreenBlock, ++b) {
    V8 mb;
    std::memcpy(&mb, bm + 8 * b, sizeof mb);
    if (!(lanes_max(mb) >= lo)) continue;
    const std::size_t end = std::min(lags, k + kScreenBlock);
    for (std::size_t u = k; u < end; ++u) {
      if (o[u] * inv_den[u] >= lo) idx[c++] = u;
    }
  }
  return c;
}

// prod_i = spec_i ts_i for i < nc, interleaved complex (re, im): (ac - bd) + i(ad + bc), each a
// product then a sum, never fused. Four products per step.
RANGING_CLONE_V4 void spectrum_product(const double* spec, const double* ts, double* prod, std::size_t nc) {
  typedef std::int64_t I8 __attribute__((vector_size(64)));
  constexpr std::int64_t s = std::numeric_limits<std::int64_t>::min();  // the sign bit
  const I8 neg_even = {s, 0, s, 0, s, 0, s, 0};
  auto four = [&](const V8& a, const V8& b, V8& r) {  // (references: no vector in the call ABI)
    const V8 ar = __builtin_shufflevector(a, a, 0, 0, 2, 2, 4, 4, 6, 6);
    const V8 ai = __builtin_shufflevector(a, a, 1, 1, 3, 3, 5, 5, 7, 7);
    const V8 bs = __builtin_shufflevector(b, b, 1, 0, 3, 2, 5, 4, 7, 6);
    const V8 t1 = ar * b;   // ar br, ar bi
    const V8 t2 = ai * bs;  // ai bi, ai br
    // x - y is x + (-y) exactly: the even lanes' sign flipped, one add (a subtract/add blend,
    // or scalar code, is what GCC 12 fused into vfmaddsub despite -ffp-contract=off)
    r = t1 + reinterpret_cast<V8>(reinterpret_cast<I8>(t2) ^ neg_even);
  };
  std::size_t i = 0;
  for (; i + 4 <= nc; i += 4) {
    V8 a, b;
    std::memcpy(&a, spec + 2 * i, sizeof a);
    std::memcpy(&b, ts + 2 * i, sizeof b);
    V8 r;
    four(a, b, r);
    std::memcpy(prod + 2 * i, &r, sizeof r);
  }
  if (i < nc) {  // the last 1..3 products, the rest of the vector zeros (not written back)
    V8 a{}, b{};
    for (std::size_t k = 0; k < 2 * (nc - i); ++k) a[k] = spec[2 * i + k], b[k] = ts[2 * i + k];
    V8 r;
    four(a, b, r);
    for (std::size_t k = 0; k < 2 * (nc - i); ++k) prod[2 * i + k] = r[k];
  }
}
}  // namespace

std::vector<LagRho> PearsonBank::search(std::span<const double> x, long lo, long hi) {
  const auto [a, b] = valid_lags(x.size(), n_, lo, hi);
  const std::size_t lags = static_cast<std::size_t>(b - a) + 1;
  const std::size_t w = lags + n_ - 1;  // window x[a, b + N)
  // any size >= w holds the lags' circular correlation without wrap: the next fast size (of the
  // bank's max_lags window when this one is shorter: one plan for every window of a stream)
  const std::size_t w_size = lags <= max_lags_ ? max_lags_ + n_ - 1 : w;
  const std::size_t nfft = transform_size(w_size);
  Plan& p = plan(nfft);
  const double* xw = x.data() + a;
  // Segment sums of (x - mean) and its square by prefix sums; x - mean is the transform's input.
  // s[0] 7 entries into the (64-byte aligned) buffers, so that s + 1, where centred_sums stores
  // its first vector of each chunk, is on a cache line boundary.
  s1_.resize(w + 8);
  s2_.resize(w + 8);
  double* const s1 = s1_.data() + 7;
  double* const s2 = s2_.data() + 7;
  centred_sums(xw, w, p.in.data(), s1, s2);
  std::fill(p.in.begin() + static_cast<std::ptrdiff_t>(w), p.in.end(), 0.0);
  var_.resize(lags);
  inv_den_.resize(lags);
  idx_.resize(lags);
  bm_.resize(8 * ((lags + kScreenBlock - 1) / kScreenBlock));
  const double* var = var_.data();
  const double floor = lag_variances(s1, s2, n_, lags, var_.data());
  inv_den(var, lags, floor, inv_den_.data());
  fftw_execute(p.fwd);
  const std::size_t nc = nfft / 2 + 1;
  // 1/nfft (rounded unless nfft is a power of two: rho's rounding stays a few ulps)
  const double inv_nfft = 1.0 / static_cast<double>(nfft);
  std::vector<LagRho> out;
  for (std::size_t j = 0; j < t_.size(); ++j) {
    // The spectrum product written out: (a + ib)(c + id) = (ac - bd) + i(ad + bc), the
    // expressions std::complex's multiplication computes for finite operands, without its
    // NaN recovery branch (both spectra are finite: FFTs of finite data).
    spectrum_product(reinterpret_cast<const double*>(p.spec.data()), reinterpret_cast<const double*>(p.tspec[j].data()),
                     reinterpret_cast<double*>(p.prod.data()), nc);
    fftw_execute(p.inv);  // unnormalized: out = nfft * correlation
    LagRho best{-2.0, a};
    const double tn = tnorm_[j];
    // rho_k = clamp(out_k / nfft / (den_k tn), -1, 1) (0 where den_k = 0), the first lag of the
    // largest wins. A division per lag is most of the search's time, so the lags are screened
    // first by g_k = out_k / den_k (a multiply: inv_den, itself within 1e-15 of 1 / den_k), which
    // orders them as rho_k does to a few ulps (rho_k = g_k / (nfft tn) up to rounding and that
    // 1e-15), and rho_k is computed exactly as above only for the lags that can be the first
    // maximum: g_k within 1e-12 (relative) of the largest g, or (when rho reaches the clamp at 1)
    // of g at rho = 1. So the result is the one of the plain loop, bit for bit. If the largest rho
    // is itself clamped at -1, every lag is.
    const double* o = p.out.data();
    const double g1 = tn / inv_nfft;  // g at rho = 1
    const double gmax = screen_max(o, inv_den_.data(), lags, bm_.data());
    const double lo = (screen_ && tn > 0 && gmax >= -g1 * (1 - 1e-9))
                          ? std::min(gmax, g1 * (1 - 1e-9)) - (std::abs(gmax) + g1) * 1e-12 - 1e-290
                          : -HUGE_VAL;
    const std::size_t nk = lags_at_least(o, inv_den_.data(), lags, lo, bm_.data(), idx_.data());
    for (std::size_t c = 0; c < nk; ++c) {
      const std::size_t k = idx_[c];
      double r = 0;
      const double den = den_of(var[k], floor);
      if (den > 0 && tn > 0) r = std::clamp(o[k] * inv_nfft / (den * tn), -1.0, 1.0);
      if (r > best.rho) best = {r, a + static_cast<long>(k)};
    }
    out.push_back(best);
  }
  return out;
}

double u_for_sent(std::span<const double> rhos, int sent) {
  if (rhos.size() < 2) {
    throw InputError("rhos: " + std::to_string(rhos.size()) + " correlation(s) given; u needs at least 2 codes");
  }
  if (sent < 1 || static_cast<std::size_t>(sent) > rhos.size()) {
    throw InputError("sent: code " + std::to_string(sent) + " is not in 1.." + std::to_string(rhos.size()));
  }
  double other = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < rhos.size(); ++i) {
    require_finite("rhos[" + std::to_string(i) + "]", rhos[i]);
    if (static_cast<int>(i) + 1 != sent) other = std::max(other, rhos[i]);
  }
  return rhos[static_cast<std::size_t>(sent - 1)] - other;
}

double pearson(std::span<const double> a, std::span<const double> b) {
  if (a.size() != b.size() || a.empty()) {
    throw InputError("pearson: signals have lengths " + std::to_string(a.size()) + " and " +
                     std::to_string(b.size()) + "; they must be equal and non-zero");
  }
  const auto n = static_cast<double>(a.size());
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ma += a[i];
    mb += b[i];
  }
  ma /= n;
  mb /= n;
  // Two-pass: subtracting the mean first keeps the sums accurate for offset signals.
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double da = a[i] - ma, db = b[i] - mb;
    sab += da * db;
    saa += da * da;
    sbb += db * db;
  }
  if (saa == 0.0 || sbb == 0.0) return 0.0;
  return std::clamp(sab / (std::sqrt(saa) * std::sqrt(sbb)), -1.0, 1.0);
}

Distinguishability distinguishability(std::span<const double> rhos) {
  if (rhos.size() < 2) {
    throw InputError("rhos: " + std::to_string(rhos.size()) +
                     " correlation(s) given; distinguishability needs at least 2 codes");
  }
  std::size_t best = 0;
  for (std::size_t i = 0; i < rhos.size(); ++i) {
    require_finite("rhos[" + std::to_string(i) + "]", rhos[i]);
    if (rhos[i] > rhos[best]) best = i;
  }
  double sub = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < rhos.size(); ++i) {
    if (i != best) sub = std::max(sub, rhos[i]);
  }
  return {static_cast<int>(best) + 1, rhos[best], sub, rhos[best] - sub};
}

double energy(std::span<const double> x) {
  double e = 0;
  for (double v : x) e += v * v;
  return e;
}

Duration duration_td(std::span<const double> x, double fs) {
  require_in_range("fs", fs, 1e-9, 1e12);
  if (x.empty()) throw InputError("duration_td: signal is empty; need at least 1 sample");
  double b = 0;
  for (double v : x) b = std::max(b, std::abs(v));
  require_finite("duration_td: peak |x|", b);
  if (b == 0.0) throw InputError("duration_td: signal is all zero; T_d needs a non-zero peak");
  const double a = b / 10.0;
  std::size_t first = x.size(), last = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (std::abs(x[i]) > a) {
      if (first == x.size()) first = i;
      last = i;
    }
  }
  return {first, last, static_cast<double>(last - first) / fs};
}

namespace {
// max(0, |x[i]|) over [a, b), NaN skipped: eight running maxima (blends; max is exact, so any
// order gives it).
RANGING_CLONE_V4 double max_abs(const double* x, std::size_t a, std::size_t b) {
  const V8 zero = V8{};
  V8 m = zero;
  std::size_t i = a;
  for (; i + 8 <= b; i += 8) {
    V8 v;
    std::memcpy(&v, x + i, sizeof v);
    v = v < zero ? zero - v : v;
    m = v > m ? v : m;
  }
  double r = 0;
  for (int u = 0; u < 8; ++u) r = std::max(r, m[u]);
  for (; i < b; ++i) r = std::max(r, std::abs(x[i]));
  return r;
}

// The first i in [a, b) with |x[i]| == v, else b.
RANGING_CLONE_V4 std::size_t first_abs_equal(const double* x, std::size_t a, std::size_t b, double v) {
  for (std::size_t i = a; i < b; ++i) {
    if (std::abs(x[i]) == v) return i;
  }
  return b;
}

}  // namespace

namespace {
// kth_smallest's pass: counts the m[i] < lo into below and keeps the m[i] in [lo, hi] in buf,
// in order (NaN in neither); returns how many it kept. buf holds n values.
std::size_t keep_between_scalar(const double* m, std::size_t n, double lo, double hi, double* buf, std::size_t& below) {
  std::size_t nb = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double v = m[i];
    below += v < lo;
    buf[nb] = v;  // branchless: kept when nb moves on
    nb += (v >= lo) & (v <= hi);
  }
  return nb;
}
#if defined(__x86_64__)
// The same, eight values per step: compare masks, a compress into a register (a compressing
// store is microcoded and slow on some AVX-512 CPUs) and a full store (buf has room: nb <= i).
[[gnu::target("avx512f")]] std::size_t keep_between_avx512(const double* m, std::size_t n, double lo, double hi,
                                                          double* buf, std::size_t& below) {
  const __m512d l = _mm512_set1_pd(lo), h = _mm512_set1_pd(hi);
  std::size_t nb = 0, i = 0;
  for (; i + 8 <= n; i += 8) {
    const __m512d v = _mm512_loadu_pd(m + i);
    const __mmask8 lt = _mm512_cmp_pd_mask(v, l, _CMP_LT_OQ);
    const __mmask8 in = _mm512_cmp_pd_mask(v, l, _CMP_GE_OQ) & _mm512_cmp_pd_mask(v, h, _CMP_LE_OQ);
    below += static_cast<std::size_t>(__builtin_popcount(lt));
    _mm512_storeu_pd(buf + nb, _mm512_maskz_compress_pd(in, v));
    nb += static_cast<std::size_t>(__builtin_popcount(in));
  }
  return nb + keep_between_scalar(m + i, n - i, lo, hi, buf + nb, below);
}
#endif
std::size_t keep_between(const double* m, std::size_t n, double lo, double hi, double* buf, std::size_t& below) {
#if defined(__x86_64__)
  static const bool avx512 = __builtin_cpu_supports("avx512f");
  if (avx512) return keep_between_avx512(m, n, lo, hi, buf, below);
#endif
  return keep_between_scalar(m, n, lo, hi, buf, below);
}
}  // namespace

double kth_smallest(double* m, std::size_t n, std::size_t k, double* buf) {
  if (n >= 512) {
    constexpr std::size_t kS = 128, kHalf = 12;
    double s[kS];
    for (std::size_t i = 0; i < kS; ++i) s[i] = m[i * n / kS];
    // the sample's ranks ilo < ihi (the sorted sample's s[ilo], s[ihi]) by two selections
    const std::size_t r = k * kS / n;
    const std::size_t ilo = r >= kHalf ? r - kHalf : 0, ihi = std::min(kS - 1, r + kHalf);
    std::nth_element(s, s + ilo, s + kS);
    std::nth_element(s + ilo + 1, s + ihi, s + kS);
    const double lo = s[ilo], hi = s[ihi];
    std::size_t below = 0;
    const std::size_t nb = keep_between(m, n, lo, hi, buf, below);
    if (below <= k && k < below + nb) {
      std::nth_element(buf, buf + (k - below), buf + nb);
      return buf[k - below];
    }
  }
  std::nth_element(m, m + k, m + n);
  return m[k];
}
StreamDuration duration_td_stream(std::span<const double> x, std::size_t lo, std::size_t hi, std::size_t p0,
                                  std::size_t p1, std::size_t guard, double fs) {
  require_in_range("fs", fs, 1e-9, 1e12);
  if (!(lo < hi && hi <= x.size() && p0 < p1 && p1 <= x.size())) {
    throw InputError("duration_td_stream: ranges [" + std::to_string(lo) + ", " + std::to_string(hi) + ") and [" +
                     std::to_string(p0) + ", " + std::to_string(p1) + ") must be non-empty and inside the " +
                     std::to_string(x.size()) + "-sample stream");
  }
  const double b = max_abs(x.data(), p0, p1);
  require_finite("duration_td_stream: peak |x|", b);
  if (b == 0.0) throw InputError("duration_td_stream: burst window is all zero; T_d needs a non-zero peak");
  StreamDuration d;
  const std::size_t n0 = lo > 2000 ? lo - 2000 : 0;
  if (lo - n0 >= 100) {
    double m[2000], buf[2000];  // lo - n0 <= 2000
    const std::size_t nm = lo - n0;
    for (std::size_t i = n0; i < lo; ++i) m[i - n0] = std::abs(x[i]);
    d.noise_rms = kth_smallest(m, nm, nm / 2, buf) / 0.6744897501960817;
  }
  d.threshold = b / 10.0;
  if (4.5 * d.noise_rms > d.threshold) {
    d.threshold = 4.5 * d.noise_rms;
    d.noise_limited = true;
  }
  // The burst's peak, then outwards until `guard` consecutive samples are at or below a.
  std::size_t pk = first_abs_equal(x.data(), p0, p1, b);  // the first of the largest
  pk = std::clamp(pk, lo, hi - 1);
  const std::size_t gap = std::max<std::size_t>(guard, 1);
  // From the peak outwards over n samples one way (step +1 or -1): `edge` becomes the outermost
  // sample above the threshold before `gap` quiet ones in a row; true when that quiet run was met.
  auto walk = [&](std::ptrdiff_t step, std::size_t n, std::size_t& edge) {
    std::size_t quiet = 0;
    for (std::size_t k = 1; k <= n; ++k) {
      const std::size_t i = pk + static_cast<std::size_t>(step * static_cast<std::ptrdiff_t>(k));
      if (std::abs(x[i]) > d.threshold) {
        edge = i;
        quiet = 0;
      } else if (++quiet >= gap) {
        return true;
      }
    }
    return false;
  };
  std::size_t last = pk, first = pk;
  const bool ended = walk(+1, hi - pk - 1, last);
  const bool began = walk(-1, pk - lo, first);
  if (std::abs(x[pk]) <= d.threshold) first = last = pk;  // the noise floor hides the whole burst
  d.first = first;
  d.last = last;
  d.seconds = static_cast<double>(last - first) / fs;
  d.clipped = !(ended && began);
  d.ended_forward = ended;
  return d;
}

namespace {
std::vector<double> ranks(std::span<const double> v) {
  std::vector<std::size_t> idx(v.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return v[a] < v[b]; });
  std::vector<double> r(v.size());
  for (std::size_t i = 0; i < idx.size();) {
    std::size_t j = i;
    while (j + 1 < idx.size() && v[idx[j + 1]] == v[idx[i]]) ++j;
    const double mean = 0.5 * static_cast<double>(i + j) + 1.0;
    for (std::size_t k = i; k <= j; ++k) r[idx[k]] = mean;
    i = j + 1;
  }
  return r;
}
}  // namespace

double spearman(std::span<const double> a, std::span<const double> b) {
  if (a.size() != b.size() || a.size() < 2) {
    throw InputError("spearman: samples have sizes " + std::to_string(a.size()) + " and " +
                     std::to_string(b.size()) + "; they must be equal and >= 2");
  }
  for (std::size_t i = 0; i < a.size(); ++i) {
    require_finite("spearman: a[" + std::to_string(i) + "]", a[i]);
    require_finite("spearman: b[" + std::to_string(i) + "]", b[i]);
  }
  const auto ra = ranks(a), rb = ranks(b);
  double va = 0, vb = 0;
  for (std::size_t i = 1; i < a.size(); ++i) {
    va += std::abs(ra[i] - ra[0]);
    vb += std::abs(rb[i] - rb[0]);
  }
  if (va == 0 || vb == 0) return std::numeric_limits<double>::quiet_NaN();
  return pearson(ra, rb);
}

int eta_required(double max_distance_m, double period_s, double c) {
  require_in_range("max_distance_m", max_distance_m, 1e-6, 1e6);
  require_in_range("period_s", period_s, 1e-12, 1e6);
  require_in_range("speed_of_sound", c, 1e-3, 1e6);
  const double r = max_distance_m / (period_s * c);
  if (r > 1e9) throw InputError("eta_required: L/(T*c) = " + std::to_string(r) + " exceeds 1e9 codes");
  const double n = std::round(r);
  const double eta = std::abs(r - n) <= 1e-9 * std::max(1.0, n) ? n + 1.0 : std::ceil(r);
  return std::max(1, static_cast<int>(eta));
}

namespace {
// The largest and smallest of x (n >= 1) eight lanes at a time; false (lo, hi unset) when x
// holds a NaN or the result is a zero (whose sign then depends on the order: the caller takes
// std::minmax_element's then).
RANGING_CLONE_V4 bool extremes(const double* x, std::size_t n, double& lo, double& hi) {
  V8 mx = V8{} + x[0], mn = mx, nan = V8{};
  std::size_t k = 0;
  for (; k + 8 <= n; k += 8) {
    V8 a;
    std::memcpy(&a, x + k, sizeof a);
    mx = a > mx ? a : mx;
    mn = a < mn ? a : mn;
    nan += a - a;  // NaN stays
  }
  double h = mx[0], l = mn[0], bad = 0;
  for (int u = 0; u < 8; ++u) h = std::max(h, mx[u]), l = std::min(l, mn[u]), bad += nan[u];
  for (; k < n; ++k) h = std::max(h, x[k]), l = std::min(l, x[k]), bad += x[k] - x[k];
  if (bad != 0 || h == 0 || l == 0) return false;
  lo = l, hi = h;
  return true;
}

// The first index i with x[i] == a or x[i] == b, else n (x, a, b finite: x - a is 0 exactly
// when x == a). Eight lanes per step: the group's smallest min(|x - a|, |x - b|), by blends and
// whole-vector shuffles, is tested against 0.
RANGING_CLONE_V4 std::size_t find_either(const double* x, std::size_t n, double a, double b) {
  const V8 av = V8{} + a, bv = V8{} + b, zero = V8{};
  std::size_t k = 0;
  for (; k + 8 <= n; k += 8) {
    V8 v;
    std::memcpy(&v, x + k, sizeof v);
    V8 da = v - av, db = v - bv;
    da = da < zero ? zero - da : da;
    db = db < zero ? zero - db : db;
    if (lanes_min(da < db ? da : db) == 0) break;
  }
  for (; k < n; ++k) {
    if (x[k] == a || x[k] == b) return k;
  }
  return n;
}
}  // namespace

void FlatTopScan::levels(std::span<const double> x) {
  if (x.empty()) return;
  double lo = 0, hi = 0;
  if (!extremes(x.data(), x.size(), lo, hi)) {
    const auto [l, h] = std::minmax_element(x.begin(), x.end());
    lo = *l, hi = *h;
  }
  t_.high = any_ ? std::max(t_.high, hi) : hi;
  t_.low = any_ ? std::min(t_.low, lo) : lo;
  any_ = true;
}

void FlatTopScan::merge_levels(const FlatTopScan& later) {
  if (!later.any_) return;
  t_.high = any_ ? std::max(t_.high, later.t_.high) : later.t_.high;
  t_.low = any_ ? std::min(t_.low, later.t_.low) : later.t_.low;
  any_ = true;
}

void FlatTopScan::runs(std::span<const double> x) {
  if (!any_ || (t_.high == 0.0 && t_.low == 0.0)) return;
  auto step = [&](std::size_t& run, bool at_level) {
    if (at_level) {
      ++run;
      return;
    }
    if (run >= min_run_) {
      t_.samples += run;
      ++t_.runs;
    }
    run = 0;
  };
  // Between samples at either level every step is a "not at level": the first closes the runs
  // in progress, the others find them closed (run 0 < min_run >= 1). So one such step stands
  // for all of them: a search jumps to the next sample at a level, and most blocks (no flat
  // top) cost one search.
  const double hi = t_.high, lo = t_.low;
  const std::size_t n = x.size();
  for (std::size_t i = 0; i < n;) {
    const std::size_t j = i + find_either(x.data() + i, n - i, hi, lo);
    if (j != i) {
      step(run_high_, false);
      if (hi != lo) step(run_low_, false);
    }
    for (i = j; i < n && (x[i] == hi || x[i] == lo); ++i) {
      step(run_high_, x[i] == hi);
      if (hi != lo) step(run_low_, x[i] == lo);
    }
  }
}

FlatTops FlatTopScan::result() const {
  FlatTops t = t_;
  if (!any_ || (t.high == 0.0 && t.low == 0.0)) return any_ ? FlatTops{0, 0, t.high, t.low} : FlatTops{};
  for (const std::size_t run : {run_high_, run_low_}) {  // runs that reach the end of the stream
    if (run >= min_run_) {
      t.samples += run;
      ++t.runs;
    }
  }
  return t;
}

FlatTops flat_top_clipping(std::span<const double> x, std::size_t min_run) {
  FlatTopScan scan(min_run);
  scan.levels(x);
  scan.runs(x);
  return scan.result();
}

double vmax(double td_max_s, int eta, double c, double max_distance_m) {
  require_in_range("td_max_s", td_max_s, 1e-12, 1e6);
  require_in_range("eta", eta, 1, 1e9);
  require_in_range("speed_of_sound", c, 1e-3, 1e6);
  require_in_range("max_distance_m", max_distance_m, 1e-6, 1e6);
  return std::min(1.0 / (1.5 * td_max_s), eta * c / max_distance_m);
}

double heron_vertical_distance(double h_m, double h_n, double s) {
  require_in_range("h_m", h_m, 0.0, 1e9);
  require_in_range("h_n", h_n, 0.0, 1e9);
  require_in_range("s", s, 0.0, 1e9);
  if (h_m <= 0 || h_n <= 0 || s <= 0) {
    throw InputError("h_m, h_n, s: every side must be > 0");
  }
  // Kahan: with a >= b >= c, 16*area^2 = (a+(b+c))(c-(a-b))(c+(a-b))(a+(b-c)).
  double side[3] = {h_m, h_n, s};
  std::sort(side, side + 3, [](double x, double y) { return x > y; });
  const double a = side[0], b = side[1], c = side[2];
  const double t = c - (a - b);  // 2*(p - a): negative iff a > b + c
  if (t < -1e-12 * a) {
    std::ostringstream os;
    os << "h_m, h_n, s: " << h_m << ", " << h_n << ", " << s
       << " do not form a triangle (the longest side must not exceed the sum of the others)";
    throw InputError(os.str());
  }
  const double prod = (a + (b + c)) * std::max(t, 0.0) * (c + (a - b)) * (a + (b - c));
  const double area = 0.25 * std::sqrt(prod);
  return 2.0 * area / s;
}

}  // namespace ranging
