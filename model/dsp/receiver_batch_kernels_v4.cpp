// AVX-512 (x86-64-v4) kernels of ReceiverFixedBatch: see receiver_batch_kernels.hpp.
//
// Built with -march=x86-64-v4 when the compiler takes it (model/CMakeLists.txt); otherwise the
// kernels are absent and batch_kernels_available() says so. Nothing here may be an inline
// function shared with other translation units (they would carry AVX-512 code onto CPUs
// without it): the helpers are in an anonymous namespace, the only outside call is
// fx_overflow_slow (compiled for the baseline ISA in fixed_point.cpp).
//
// Word lengths and exactness: every lane computes what the scalar model computes on the same
// int64 values, with the scalar model's bounds (BandpassFixed: |acc| < 2^63 by acc_bits <= 64;
// CorrelatorBankFixed: the layout's widths <= 62 bits), so no lane overflows int64. A 32 x 32
// -> 64 multiply (vpmuldq) is used only where the owner proved both factors fit int32
// (BandpassBatch::narrow, BankBatch::fir_narrow / power_narrow; unsigned, vpmuludq, where
// BankBatch::weight_narrow proved both fit uint32); otherwise the full 64-bit
// multiply (vpmullq), whose low 64 bits are the exact product under those bounds. Rounding is
// fx_round_shift's, overflow fx_overflow_slow's (saturate or wrap, counted per lane).
#include "model/dsp/receiver_batch_kernels.hpp"
#include "model/base/transpose8.hpp"
#include "model/dsp/front_end_run.hpp"

#if defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__AVX512VL__)
#include <immintrin.h>
#define RANGING_BATCH_V4 1
#endif

namespace ranging::batch {

#ifdef RANGING_BATCH_V4

namespace {

typedef std::int64_t V __attribute__((vector_size(64)));

inline V load(const Lanes& l) { return *reinterpret_cast<const V*>(l.v); }
inline void store(Lanes& l, V v) { *reinterpret_cast<V*>(l.v) = v; }
inline V splat(std::int64_t x) { return V{} + x; }

// Exact products: Narrow when both factors are known to fit int32 (vpmuldq), else vpmullq.
template <bool Narrow>
inline V mul(V a, V b) {
  if constexpr (Narrow) {
    // the zero-masked form: the plain one trips GCC 12's -Wmaybe-uninitialized in its header
    return reinterpret_cast<V>(
        _mm512_maskz_mul_epi32(__mmask8(0xFF), reinterpret_cast<__m512i>(a), reinterpret_cast<__m512i>(b)));
  } else {
    return a * b;
  }
}

// fx_round_shift<R>(raw, shift) per lane: floor(raw / 2^shift) adjusted by R; shift 0: raw.
template <Rounding R>
inline V round_shift(V raw, int shift) {
  if (shift == 0) return raw;
  const V q = raw >> shift;  // arithmetic
  if constexpr (R == Rounding::Truncate) {
    return q;
  } else if constexpr (R == Rounding::RoundHalfUp) {
    return q + ((raw >> (shift - 1)) & 1);
  } else {
    const V rem = raw & splat(static_cast<std::int64_t>((std::uint64_t{1} << shift) - 1));
    const V half = splat(static_cast<std::int64_t>(std::uint64_t{1} << (shift - 1)));
    // comparisons give -1 (true) or 0 per lane; rem and half are non-negative
    return q - ((rem > half) | ((rem == half) & ((q & 1) != 0)));
  }
}

// Brings out-of-range lanes into r by o, counting each in its lane's counter.
inline V overflow(V y, const FxRange& r, Overflow o, OverflowCounter* events) {
  const __m512i yi = reinterpret_cast<__m512i>(y);
  const __mmask8 bad = _mm512_cmplt_epi64_mask(yi, _mm512_set1_epi64(r.lo)) |
                       _mm512_cmpgt_epi64_mask(yi, _mm512_set1_epi64(r.hi));
  if (bad) [[unlikely]] {
    for (int l = 0; l < kBatchLanes; ++l) {
      if ((bad >> l) & 1) y[l] = fx_overflow_slow(y[l], r, o, events[l]);
    }
  }
  return y;
}

template <int N, Rounding R, bool Narrow, bool Sym>
void bandpass_kernel(BandpassBatch& s, const Lanes* in, Lanes* out, std::size_t n) {
  V b0[N], b1[N], b2[N], a1[N], a2[N], y1[N], y2[N];
  for (int k = 0; k < N; ++k) {
    b0[k] = splat(s.coef[k][0]);
    b1[k] = splat(s.coef[k][1]);
    b2[k] = splat(s.coef[k][2]);
    a1[k] = splat(s.coef[k][3]);
    a2[k] = splat(s.coef[k][4]);
    y1[k] = load(s.y1[k]);
    y2[k] = load(s.y2[k]);
  }
  V in1 = load(s.x1), in2 = load(s.x2);
  const int ish = s.input_shift, qs = s.qshift;
  for (std::size_t i = 0; i < n; ++i) {
    V x = load(in[i]) << ish;  // = code * 2^input_shift (two's complement, exact in range)
    V x1 = in1, x2 = in2;
    in2 = in1;
    in1 = x;
    for (int k = 0; k < N; ++k) {
      V part;
      if constexpr (Sym) {
        part = mul<Narrow>(b0[k], x - x2) - mul<Narrow>(a2[k], y2[k]);
      } else {
        part = mul<Narrow>(b0[k], x) + mul<Narrow>(b1[k], x1) + mul<Narrow>(b2[k], x2) - mul<Narrow>(a2[k], y2[k]);
      }
      const V acc = part - mul<Narrow>(a1[k], y1[k]);
      const V y = overflow(round_shift<R>(acc, qs), s.range, s.overflow, s.events);
      x1 = y1[k];
      x2 = y2[k];
      y2[k] = y1[k];
      y1[k] = y;
      x = y;
    }
    store(out[i], x);
  }
  store(s.x1, in1);
  store(s.x2, in2);
  for (int k = 0; k < N; ++k) {
    store(s.y1[k], y1[k]);
    store(s.y2[k], y2[k]);
  }
}

template <int N, Rounding R>
void bandpass_forms(BandpassBatch& s, const Lanes* in, Lanes* out, std::size_t n) {
  if (s.narrow) {
    s.sym ? bandpass_kernel<N, R, true, true>(s, in, out, n) : bandpass_kernel<N, R, true, false>(s, in, out, n);
  } else {
    s.sym ? bandpass_kernel<N, R, false, true>(s, in, out, n) : bandpass_kernel<N, R, false, false>(s, in, out, n);
  }
}

template <Rounding R>
void bandpass_sections(BandpassBatch& s, const Lanes* in, Lanes* out, std::size_t n) {
  switch (s.sections) {
    case 1: return bandpass_forms<1, R>(s, in, out, n);
    case 2: return bandpass_forms<2, R>(s, in, out, n);
    case 3: return bandpass_forms<3, R>(s, in, out, n);
    case 4: return bandpass_forms<4, R>(s, in, out, n);
    case 5: return bandpass_forms<5, R>(s, in, out, n);
    case 6: return bandpass_forms<6, R>(s, in, out, n);
    case 7: return bandpass_forms<7, R>(s, in, out, n);
    default: return bandpass_forms<8, R>(s, in, out, n);
  }
}

// The bank's quantizers are all round half up and saturate (CorrelatorBankFixed).
inline V quantize_rhu_sat(V raw, int shift, const FxRange& r, OverflowCounter* events) {
  return overflow(round_shift<Rounding::RoundHalfUp>(raw, shift), r, Overflow::Saturate, events);
}

template <bool FirNarrow, bool PowerNarrow>
void decimated_output(BankBatch& s) {
  // decimator output: every D-th moving sum, into both copies of the Bd ring
  if (++s.bd_idx == s.bd_n) s.bd_idx = 0;
  s.bd_re[s.bd_idx] = s.bd_re[s.bd_idx + s.bd_n] = s.acc_re;
  s.bd_im[s.bd_idx] = s.bd_im[s.bd_idx + s.bd_n] = s.acc_im;
  // 3. chip filter: exact accumulation over the window Bd[k] .. Bd[k-M+1], then round half up
  V fre{}, fim{};
  const Lanes* bre = s.bd_re + s.bd_idx + 1;
  const Lanes* bim = s.bd_im + s.bd_idx + 1;
  for (std::size_t i = 0; i < s.bd_n; ++i) {
    const V t = splat(s.taps_rev[i]);
    fre += mul<FirNarrow>(t, load(bre[i]));
    fim += mul<FirNarrow>(t, load(bim[i]));
  }
  if (++s.f_idx == s.f_n) s.f_idx = 0;
  const V fq_re = quantize_rhu_sat(fre, s.chip_shift, s.chip_range, s.chip_events);
  const V fq_im = quantize_rhu_sat(fim, s.chip_shift, s.chip_range, s.chip_events);
  store(s.f_re[s.f_idx], fq_re);
  store(s.f_re[s.f_idx + s.f_n], fq_re);
  store(s.f_im[s.f_idx], fq_im);
  store(s.f_im[s.f_idx + s.f_n], fq_im);
  // 4-6. combiner (exact), quantize, power, weight. Chip c reads F[k - (L-1-c) Nc/D]; a -1
  // chip subtracts: (g ^ m) - m is -g for m = -1 and g for m = 0.
  const std::size_t chips = static_cast<std::size_t>(s.chips);
  const std::size_t step = static_cast<std::size_t>(s.step);
  const std::int64_t* sg = s.sign_mask;
  for (int j = 0; j < s.codes; ++j, sg += chips) {
    V cre{}, cim{};
    for (std::size_t c = 0; c < chips; ++c) {
      const std::size_t k = s.f_idx + s.f_n - (chips - 1 - c) * step;
      const V m = splat(sg[c]);
      cre += (load(s.f_re[k]) ^ m) - m;
      cim += (load(s.f_im[k]) ^ m) - m;
    }
    const V cr = quantize_rhu_sat(cre, s.corr_shift, s.corr_range, s.corr_events);
    const V ci = quantize_rhu_sat(cim, s.corr_shift, s.corr_range, s.corr_events);
    const V p = mul<PowerNarrow>(cr, cr) + mul<PowerNarrow>(ci, ci);
    // Q = P w: the layout proves it fits 64 bits; vpmuludq when both fit 32 (vpmullq is three
    // micro-ops and 15 cycles on Intel cores)
    const V w = splat(s.weights[j]);
    // (the zero-masked form: the plain one trips GCC 12's -Wmaybe-uninitialized in its header)
    store(s.q[j], s.weight_narrow ? reinterpret_cast<V>(_mm512_maskz_mul_epu32(__mmask8(0xFF), reinterpret_cast<__m512i>(p),
                                                                                reinterpret_cast<__m512i>(w)))
                                  : p * w);
  }
}

// ---- float ----------------------------------------------------------------------------------

typedef double D __attribute__((vector_size(64)));

inline D loadf(const LanesF& l) { return *reinterpret_cast<const D*>(l.v); }
inline void storef(LanesF& l, D v) { *reinterpret_cast<D*>(l.v) = v; }
inline D splatf(double x) { return D{} + x; }

template <int N>
void bandpass_kernel_float(FloatBandpassBatch& s, const LanesF* in, LanesF* out, std::size_t n) {
  D b0[N], b1[N], b2[N], a1[N], a2[N], x1[N], x2[N], y1[N], y2[N];
  for (int k = 0; k < N; ++k) {
    b0[k] = splatf(s.coef[k][0]);
    b1[k] = splatf(s.coef[k][1]);
    b2[k] = splatf(s.coef[k][2]);
    a1[k] = splatf(s.coef[k][3]);
    a2[k] = splatf(s.coef[k][4]);
    x1[k] = loadf(s.x1[k]);
    x2[k] = loadf(s.x2[k]);
    y1[k] = loadf(s.y1[k]);
    y2[k] = loadf(s.y2[k]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    D x = loadf(in[i]);
    for (int k = 0; k < N; ++k) {
      // BandpassFloat::execute's expression, left to right
      const D y = b0[k] * x + b1[k] * x1[k] + b2[k] * x2[k] - a1[k] * y1[k] - a2[k] * y2[k];
      x2[k] = x1[k];
      x1[k] = x;
      y2[k] = y1[k];
      y1[k] = y;
      x = y;
    }
    storef(out[i], x);
  }
  for (int k = 0; k < N; ++k) {
    storef(s.x1[k], x1[k]);
    storef(s.x2[k], x2[k]);
    storef(s.y1[k], y1[k]);
    storef(s.y2[k], y2[k]);
  }
}

void decimated_output_float(FloatBankBatch& s) {
  if (++s.bd_idx == s.bd_n) s.bd_idx = 0;
  s.bd_re[s.bd_idx] = s.bd_re[s.bd_idx + s.bd_n] = s.acc_re;
  s.bd_im[s.bd_idx] = s.bd_im[s.bd_idx + s.bd_n] = s.acc_im;
  D fre{}, fim{};
  const std::size_t m = s.bd_n;
  const LanesF* bre_h = s.bd_re + s.bd_idx + m;  // Bd[k - i] = bre_h[-i]
  const LanesF* bim_h = s.bd_im + s.bd_idx + m;
  for (std::size_t i = 0; i < m; ++i) {
    const D t = splatf(s.taps[i]);
    fre += t * loadf(*(bre_h - i));
    fim += t * loadf(*(bim_h - i));
  }
  if (++s.f_idx == s.f_n) s.f_idx = 0;
  storef(s.f_re[s.f_idx], fre);
  storef(s.f_re[s.f_idx + s.f_n], fre);
  storef(s.f_im[s.f_idx], fim);
  storef(s.f_im[s.f_idx + s.f_n], fim);
  const std::size_t chips = static_cast<std::size_t>(s.chips);
  const std::size_t step = static_cast<std::size_t>(s.step);
  const double* sg = s.signs;
  for (int j = 0; j < s.codes; ++j, sg += chips) {
    D cre{}, cim{};
    for (std::size_t c = 0; c < chips; ++c) {
      const std::size_t k = s.f_idx + s.f_n - (chips - 1 - c) * step;
      const D sv = splatf(sg[c]);
      cre += sv * loadf(s.f_re[k]);
      cim += sv * loadf(s.f_im[k]);
    }
    storef(s.q[j], (cre * cre + cim * cim) / splatf(s.gain[j]));
  }
}

template <class T, class E>
T load_unaligned(const E* p) {
  T v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}

// ---- the wavefront: one stream, section k on lane k (receiver_batch_kernels.hpp) ------------

// The lanes of sections whose sample at step i is in the block [0, n): 0 <= i - kWaveSkew k < n.
inline __mmask8 wave_active(std::size_t i, std::size_t n, int sections) {
  unsigned m = 0;
  for (int k = 0; k < sections; ++k) {
    const std::size_t lag = static_cast<std::size_t>(kWaveSkew) * static_cast<std::size_t>(k);
    if (i >= lag && i - lag < n) m |= 1u << k;
  }
  return static_cast<__mmask8>(m);
}

// Lane 0 = x, lane k = v[k - 1]: the previous section's output moves one lane up. (The
// zero-masked forms of the intrinsics: the plain ones trip GCC 12's -Wmaybe-uninitialized.)
inline V shift_in(V v, std::int64_t x) {
  return reinterpret_cast<V>(
      _mm512_maskz_alignr_epi64(__mmask8(0xFF), reinterpret_cast<__m512i>(v), _mm512_set1_epi64(x), 7));
}
inline D shift_in(D v, double x) {
  return reinterpret_cast<D>(_mm512_maskz_alignr_epi64(__mmask8(0xFF), reinterpret_cast<__m512i>(v),
                                                       reinterpret_cast<__m512i>(_mm512_set1_pd(x)), 7));
}
// Lane `lane` of v.
inline std::int64_t lane_of(V v, int lane) {
  return reinterpret_cast<V>(_mm512_maskz_permutexvar_epi64(__mmask8(0xFF), _mm512_set1_epi64(lane),
                                                            reinterpret_cast<__m512i>(v)))[0];
}
inline double lane_of(D v, int lane) {
  return _mm512_cvtsd_f64(
      _mm512_maskz_permutexvar_pd(__mmask8(0xFF), _mm512_set1_epi64(lane), reinterpret_cast<__m512d>(v)));
}
template <class T>
inline T keep(__mmask8 m, T old, T nw) {  // lanes in m from nw, the others from old
  return reinterpret_cast<T>(
      _mm512_mask_blend_epi64(m, reinterpret_cast<__m512i>(old), reinterpret_cast<__m512i>(nw)));
}

// The wavefront's registers: every section's state (lane k: section k) and the output vectors
// of the last kWaveSkew steps (p[j]: step i - 1 - j).
template <class T>
struct Wave {
  T x1, x2, y1, y2, p[kWaveSkew];
};

// After a step with input x and output y: the lanes in act (every lane unless Masked) take the
// new sample into their histories, the others keep theirs; y becomes the newest output vector.
template <bool Masked, class T>
inline void wave_advance(__mmask8 act, T x, T y, T& x1, T& x2, T& y1, T& y2, T (&p)[kWaveSkew]) {
  if constexpr (Masked) {
    x2 = keep(act, x2, x1);
    x1 = keep(act, x1, x);
    y2 = keep(act, y2, y1);
    y1 = keep(act, y1, y);
  } else {
    x2 = x1;
    x1 = x;
    y2 = y1;
    y1 = y;
  }
  for (int j = kWaveSkew - 1; j > 0; --j) p[j] = p[j - 1];
  p[0] = y;
}

// The lanes in `bad` brought into range by c.overflow, each counted (out of line: the loop keeps
// its vectors in registers).
// (y by value and returned: a reference would keep y in memory, stored at every step.)
[[gnu::noinline]] V wave_overflow(V y, __mmask8 bad, const BandpassBatch& c, OverflowCounter& events) {
  for (int l = 0; l < kBatchLanes; ++l) {
    if ((bad >> l) & 1) y[l] = fx_overflow_slow(y[l], c.range, c.overflow, events);
  }
  return y;
}

// The steps [i0, i1) of the wavefront over in[0, n). Masked for the first and last steps: the
// lanes outside the block get input 0, keep their state and count no overflow.
template <Rounding R, bool Narrow, bool Sym, bool Bias, bool Masked>
void wave_steps(const BandpassBatch& c, const V (&co)[5], Wave<V>& w, const std::int64_t* in, std::int64_t* out,
                std::size_t n, std::size_t i0, std::size_t i1, OverflowCounter& events) {
  const std::size_t lat = static_cast<std::size_t>(kWaveSkew) * static_cast<std::size_t>(c.sections - 1);
  const int ish = c.input_shift, qs = c.qshift, last = c.sections - 1;
  const V bias = splat(Bias ? (std::int64_t{1} << (qs - 1)) : 0);
  const __m512i lo = _mm512_set1_epi64(c.range.lo), hi = _mm512_set1_epi64(c.range.hi);
  const V b0 = co[0], b1 = co[1], b2 = co[2], a1 = co[3], a2 = co[4];
  V x1 = w.x1, x2 = w.x2, y1 = w.y1, y2 = w.y2;  // in registers
  V p[kWaveSkew];
  for (int j = 0; j < kWaveSkew; ++j) p[j] = w.p[j];
  for (std::size_t i = i0; i < i1; ++i) {
    // = code * 2^input_shift (two's complement, exact in range); 0 past the block's end
    V x = shift_in(p[kWaveSkew - 1], i < n ? in[i] * (std::int64_t{1} << ish) : 0);
    __mmask8 act = 0xFF;  // lanes >= sections: coefficients 0, y = 0, never out of range
    if constexpr (Masked) {
      act = wave_active(i, n, c.sections);
      x = reinterpret_cast<V>(_mm512_maskz_mov_epi64(act, reinterpret_cast<__m512i>(x)));
    }
    V part;
    if constexpr (Sym) {
      part = mul<Narrow>(b0, x - x2) - mul<Narrow>(a2, y2) + bias;
    } else {
      part = mul<Narrow>(b0, x) + mul<Narrow>(b1, x1) + mul<Narrow>(b2, x2) - mul<Narrow>(a2, y2) + bias;
    }
    const V acc = part - mul<Narrow>(a1, y1);
    V y = Bias ? acc >> qs : round_shift<R>(acc, qs);
    const __m512i yi = reinterpret_cast<__m512i>(y);
    const __mmask8 below = _mm512_mask_cmplt_epi64_mask(act, yi, lo), above = _mm512_mask_cmpgt_epi64_mask(act, yi, hi);
    // (kortest: one micro-op tests both masks; moving them to integer registers took three)
    if (!_kortestz_mask8_u8(below, above)) [[unlikely]] y = wave_overflow(y, below | above, c, events);
    wave_advance<Masked>(act, x, y, x1, x2, y1, y2, p);
    if (i >= lat) out[i - lat] = lane_of(y, last);  // the last section's sample i - lat
  }
  w.x1 = x1, w.x2 = x2, w.y1 = y1, w.y2 = y2;
  for (int j = 0; j < kWaveSkew; ++j) w.p[j] = p[j];
}

template <Rounding R, bool Narrow, bool Sym, bool Bias>
void wave_kernel(const BandpassBatch& c, WaveState& s, const std::int64_t* in, std::int64_t* out, std::size_t n,
                 OverflowCounter& events) {
  V co[5];
  for (int t = 0; t < 5; ++t) {
    co[t] = V{};
    for (int k = 0; k < c.sections; ++k) co[t][k] = c.coef[k][t];  // lanes >= sections: 0
  }
  Wave<V> w{load(s.x1), load(s.x2), load(s.y1), load(s.y2), {}};
  const std::size_t lat = static_cast<std::size_t>(kWaveSkew) * static_cast<std::size_t>(c.sections - 1);
  // every lane is in the block for the steps [lat, n)
  const std::size_t m0 = std::min(lat, n + lat), m1 = std::max(lat, n);
  wave_steps<R, Narrow, Sym, Bias, true>(c, co, w, in, out, n, 0, m0, events);
  if (n > lat) wave_steps<R, Narrow, Sym, Bias, false>(c, co, w, in, out, n, lat, n, events);
  wave_steps<R, Narrow, Sym, Bias, true>(c, co, w, in, out, n, m1, n + lat, events);
  store(s.x1, w.x1);
  store(s.x2, w.x2);
  store(s.y1, w.y1);
  store(s.y2, w.y2);
}

template <bool Masked>
void wave_steps_float(const D (&co)[5], Wave<D>& w, int sections, const double* in, double* out, std::size_t n,
                      std::size_t i0, std::size_t i1) {
  const std::size_t lat = static_cast<std::size_t>(kWaveSkew) * static_cast<std::size_t>(sections - 1);
  const int last = sections - 1;
  const D b0 = co[0], b1 = co[1], b2 = co[2], a1 = co[3], a2 = co[4];
  D x1 = w.x1, x2 = w.x2, y1 = w.y1, y2 = w.y2;
  D p[kWaveSkew];
  for (int j = 0; j < kWaveSkew; ++j) p[j] = w.p[j];
  for (std::size_t i = i0; i < i1; ++i) {
    D x = shift_in(p[kWaveSkew - 1], i < n ? in[i] : 0.0);
    __mmask8 act = 0xFF;
    if constexpr (Masked) {
      act = wave_active(i, n, sections);
      x = reinterpret_cast<D>(_mm512_maskz_mov_pd(act, reinterpret_cast<__m512d>(x)));
    }
    // BandpassFloat::execute's expression, left to right
    const D y = b0 * x + b1 * x1 + b2 * x2 - a1 * y1 - a2 * y2;
    wave_advance<Masked>(act, x, y, x1, x2, y1, y2, p);
    if (i >= lat) out[i - lat] = lane_of(y, last);
  }
  w.x1 = x1, w.x2 = x2, w.y1 = y1, w.y2 = y2;
  for (int j = 0; j < kWaveSkew; ++j) w.p[j] = p[j];
}

}  // namespace

void interleave_batch_float(const double* const* src, double gain, LanesF* out, std::size_t n) {
  const D g = splatf(gain);
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    D r[8];
    for (int l = 0; l < 8; ++l) r[l] = load_unaligned<D>(src[l] + i) * g;
    transpose8(r);
    for (int k = 0; k < 8; ++k) storef(out[i + k], r[k]);
  }
  for (; i < n; ++i) {
    for (int l = 0; l < kBatchLanes; ++l) out[i].v[l] = src[l][i] * gain;
  }
}

void interleave_batch(const std::int64_t* const* src, Lanes* out, std::size_t n, std::int64_t* lo, std::int64_t* hi) {
  V mn = splat(*lo), mx = splat(*hi);
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    V r[8];
    for (int l = 0; l < 8; ++l) {
      r[l] = load_unaligned<V>(src[l] + i);
      mn = r[l] < mn ? r[l] : mn;
      mx = r[l] > mx ? r[l] : mx;
    }
    transpose8(r);
    for (int k = 0; k < 8; ++k) store(out[i + k], r[k]);
  }
  std::int64_t a = *lo, b = *hi;
  for (int l = 0; l < kBatchLanes; ++l) {
    a = mn[l] < a ? mn[l] : a;
    b = mx[l] > b ? mx[l] : b;
  }
  for (; i < n; ++i) {
    for (int l = 0; l < kBatchLanes; ++l) {
      const std::int64_t v = src[l][i];
      out[i].v[l] = v;
      a = v < a ? v : a;
      b = v > b ? v : b;
    }
  }
  *lo = a;
  *hi = b;
}

namespace {
// dst[l][i] = in[i].v[l]: 8 x 8 transposes, then the last n % 8 rows one by one.
template <class Vec, class Row, class E>
void deinterleave_rows(const Row* in, E* const* dst, std::size_t n) {
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    Vec r[8];
    for (int k = 0; k < 8; ++k) __builtin_memcpy(&r[k], in[i + k].v, sizeof r[k]);
    transpose8(r);
    for (int l = 0; l < 8; ++l) __builtin_memcpy(dst[l] + i, &r[l], sizeof r[l]);
  }
  for (; i < n; ++i) {
    for (int l = 0; l < kBatchLanes; ++l) dst[l][i] = in[i].v[l];
  }
}
}  // namespace

void deinterleave_batch(const Lanes* in, std::int64_t* const* dst, std::size_t n) { deinterleave_rows<V>(in, dst, n); }

void deinterleave_batch_float(const LanesF* in, double* const* dst, std::size_t n) {
  deinterleave_rows<D>(in, dst, n);
}

unsigned gate_batch_float(const FloatBankBatch& s, double threshold, double min_energy) {
  D top = loadf(s.q[0]);
  for (int j = 1; j < s.codes; ++j) {
    const D q = loadf(s.q[j]);
    top = q > top ? q : top;
  }
  const D e = loadf(s.energy);
  const D rho2 = e > 0 ? top / e : D{};
  // rho2 >= threshold && e >= min_energy per lane, as a bit mask (ordered compares: false for
  // NaN, as C's >=)
  const __mmask8 open = _mm512_cmp_pd_mask(reinterpret_cast<__m512d>(rho2), _mm512_set1_pd(threshold), _CMP_GE_OQ) &
                        _mm512_cmp_pd_mask(reinterpret_cast<__m512d>(e), _mm512_set1_pd(min_energy), _CMP_GE_OQ);
  return open;
}

void bandpass_batch_float(FloatBandpassBatch& s, const LanesF* in, LanesF* out, std::size_t n) {
  switch (s.sections) {
    case 1: return bandpass_kernel_float<1>(s, in, out, n);
    case 2: return bandpass_kernel_float<2>(s, in, out, n);
    case 3: return bandpass_kernel_float<3>(s, in, out, n);
    case 4: return bandpass_kernel_float<4>(s, in, out, n);
    case 5: return bandpass_kernel_float<5>(s, in, out, n);
    case 6: return bandpass_kernel_float<6>(s, in, out, n);
    case 7: return bandpass_kernel_float<7>(s, in, out, n);
    default: return bandpass_kernel_float<8>(s, in, out, n);
  }
}

std::size_t bank_feed_batch_float(FloatBankBatch& s, const LanesF* in, std::size_t n, bool* ready) {
  const std::size_t period = static_cast<std::size_t>(s.period), window = s.window;
  const int decimation = s.decimation;
  std::size_t b_idx = s.b_idx, y_idx = s.y_idx;
  int dec_phase = s.dec_phase;
  D acc_re = loadf(s.acc_re), acc_im = loadf(s.acc_im), energy = loadf(s.energy);
  const D zero{};
  std::size_t i = 0;
  *ready = false;
  while (i < n) {
    // a run with no wrap and no output inside (front_end_run.hpp)
    const FrontEndRun r = front_end_run(n - i, b_idx, period, y_idx, window, dec_phase, decimation);
    for (std::size_t u = 0; u < r.len; ++u) {
      const D y = loadf(in[i + u]);
      const std::size_t b = b_idx + u;
      const D bre = y * splatf(s.lo_cos[b]), bim = -y * splatf(s.lo_sin[b]);
      acc_re += bre - loadf(s.b_re[b]);
      acc_im += bim - loadf(s.b_im[b]);
      storef(s.b_re[b], bre);
      storef(s.b_im[b], bim);
      energy += y * y - loadf(s.y2h[r.y0 + u]);
      storef(s.y2h[r.y0 + u], y * y);
      energy = energy < zero ? zero : energy;  // std::max(energy, 0.0)
    }
    i += r.len;
    if (front_end_advance(r, b_idx, period, y_idx, dec_phase, decimation)) {
      *ready = true;
      break;
    }
  }
  s.b_idx = b_idx;
  s.y_idx = y_idx;
  s.dec_phase = dec_phase;
  storef(s.acc_re, acc_re);
  storef(s.acc_im, acc_im);
  storef(s.energy, energy);
  if (*ready) decimated_output_float(s);
  return i;
}

bool batch_kernels_available() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
         __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw");
}

void bandpass_batch(BandpassBatch& s, const Lanes* in, Lanes* out, std::size_t n) {
  switch (s.rounding) {
    case Rounding::Truncate: return bandpass_sections<Rounding::Truncate>(s, in, out, n);
    case Rounding::RoundHalfUp: return bandpass_sections<Rounding::RoundHalfUp>(s, in, out, n);
    default: return bandpass_sections<Rounding::Convergent>(s, in, out, n);
  }
}

std::size_t bank_feed_batch(BankBatch& s, const Lanes* in, std::size_t n, bool* ready) {
  // Exact int64 (CorrelatorBankFixed::feed's bounds): |y| < 2^31 and |lo| < 2^23 fit int32, so
  // the mixer's and the energy's products are 32 x 32 -> 64.
  const int mix_shift = s.mix_shift;
  const int period = s.period, decimation = s.decimation;
  const std::size_t window = s.window;
  int phase = s.phase, dec_phase = s.dec_phase;
  std::size_t y_idx = s.y_idx;
  V acc_re = load(s.acc_re), acc_im = load(s.acc_im), energy = load(s.energy);
  std::size_t i = 0;
  *ready = false;
  while (i < n) {
    // a run with no wrap and no output inside (front_end_run.hpp)
    const FrontEndRun r = front_end_run(n - i, phase, period, y_idx, window, dec_phase, decimation);
    for (std::size_t u = 0; u < r.len; ++u) {
      const V y = load(in[i + u]);
      const std::size_t ph = static_cast<std::size_t>(phase) + u;
      // 1. mixer, round half up, saturate (counted)
      const V mre = quantize_rhu_sat(mul<true>(y, splat(s.lo_cos[ph])), mix_shift, s.mix_range, s.mix_events);
      const V mim = quantize_rhu_sat(mul<true>(y, splat(s.lo_nsin[ph])), mix_shift, s.mix_range, s.mix_events);
      // 2. moving sum over one carrier cycle (exact)
      acc_re += mre - load(s.b_re[ph]);
      acc_im += mim - load(s.b_im[ph]);
      store(s.b_re[ph], mre);
      store(s.b_im[ph], mim);
      // 7. energy: running sum of y^2 over the window (uint64 arithmetic: the same bits)
      const V y2 = mul<true>(y, y);
      energy = energy + y2 - load(s.y2h[r.y0 + u]);
      store(s.y2h[r.y0 + u], y2);
    }
    i += r.len;
    if (front_end_advance(r, phase, period, y_idx, dec_phase, decimation)) {
      *ready = true;
      break;
    }
  }
  s.phase = phase;
  s.dec_phase = dec_phase;
  s.y_idx = y_idx;
  store(s.acc_re, acc_re);
  store(s.acc_im, acc_im);
  store(s.energy, energy);
  if (*ready) {
    if (s.fir_narrow) {
      s.power_narrow ? decimated_output<true, true>(s) : decimated_output<true, false>(s);
    } else {
      s.power_narrow ? decimated_output<false, true>(s) : decimated_output<false, false>(s);
    }
  }
  return i;
}

void bandpass_wave(const BandpassBatch& c, bool bias, WaveState& s, const std::int64_t* in, std::int64_t* out,
                   std::size_t n, OverflowCounter& events) {
  auto forms = [&]<Rounding R, bool B>() {
    if (c.narrow) {
      c.sym ? wave_kernel<R, true, true, B>(c, s, in, out, n, events)
            : wave_kernel<R, true, false, B>(c, s, in, out, n, events);
    } else {
      c.sym ? wave_kernel<R, false, true, B>(c, s, in, out, n, events)
            : wave_kernel<R, false, false, B>(c, s, in, out, n, events);
    }
  };
  switch (c.rounding) {
    case Rounding::Truncate: return forms.template operator()<Rounding::Truncate, false>();
    case Rounding::RoundHalfUp:
      return bias ? forms.template operator()<Rounding::RoundHalfUp, true>()
                  : forms.template operator()<Rounding::RoundHalfUp, false>();
    default: return forms.template operator()<Rounding::Convergent, false>();
  }
}

void bandpass_wave_float(const FloatBandpassBatch& c, WaveStateF& s, const double* in, double* out, std::size_t n) {
  D co[5];
  for (int t = 0; t < 5; ++t) {
    co[t] = D{};
    for (int k = 0; k < c.sections; ++k) co[t][k] = c.coef[k][t];  // lanes >= sections: 0
  }
  Wave<D> w{loadf(s.x1), loadf(s.x2), loadf(s.y1), loadf(s.y2), {}};
  const std::size_t lat = static_cast<std::size_t>(kWaveSkew) * static_cast<std::size_t>(c.sections - 1);
  const std::size_t m0 = std::min(lat, n + lat), m1 = std::max(lat, n);
  wave_steps_float<true>(co, w, c.sections, in, out, n, 0, m0);
  if (n > lat) wave_steps_float<false>(co, w, c.sections, in, out, n, lat, n);
  wave_steps_float<true>(co, w, c.sections, in, out, n, m1, n + lat);
  storef(s.x1, w.x1);
  storef(s.x2, w.x2);
  storef(s.y1, w.y1);
  storef(s.y2, w.y2);
}

#else  // no AVX-512 build: the kernels are absent

void bandpass_batch_float(FloatBandpassBatch&, const LanesF*, LanesF*, std::size_t) {}
std::size_t bank_feed_batch_float(FloatBankBatch&, const LanesF*, std::size_t, bool* ready) {
  *ready = false;
  return 0;
}

bool batch_kernels_available() { return false; }
void bandpass_wave(const BandpassBatch&, bool, WaveState&, const std::int64_t*, std::int64_t*, std::size_t,
                   OverflowCounter&) {}
void bandpass_wave_float(const FloatBandpassBatch&, WaveStateF&, const double*, double*, std::size_t) {}
unsigned gate_batch_float(const FloatBankBatch&, double, double) { return ~0u; }
void interleave_batch_float(const double* const*, double, LanesF*, std::size_t) {}
void interleave_batch(const std::int64_t* const*, Lanes*, std::size_t, std::int64_t*, std::int64_t*) {}
void deinterleave_batch(const Lanes*, std::int64_t* const*, std::size_t) {}
void deinterleave_batch_float(const LanesF*, double* const*, std::size_t) {}
void bandpass_batch(BandpassBatch&, const Lanes*, Lanes*, std::size_t) {}
std::size_t bank_feed_batch(BankBatch&, const Lanes*, std::size_t, bool* ready) {
  *ready = false;
  return 0;
}

#endif

}  // namespace ranging::batch
