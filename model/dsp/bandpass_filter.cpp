#include "model/dsp/bandpass_filter.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstring>
#include <limits>
#include <sstream>

#include "model/base/error.hpp"
#include "model/dsp/receiver_batch_kernels.hpp"
#include "model/dsp/quantize.hpp"

namespace ranging {

namespace {

const char* const kCoefNames[5] = {"b0", "b1", "b2", "a1", "a2"};

void require_sections(const SosFilter& filter) {
  if (filter.sections.empty()) throw InputError("bandpass filter sections: none given; need at least 1");
}

std::vector<std::vector<std::int64_t>> quantize_sections(const BandpassFixedConfig& c, const SosFilter& filter) {
  std::vector<std::vector<std::int64_t>> q;
  for (std::size_t k = 0; k < filter.sections.size(); ++k) {
    const Biquad& s = filter.sections[k];
    const double v[5] = {s.b0, s.b1, s.b2, s.a1, s.a2};
    std::vector<std::int64_t> row(5);
    for (int i = 0; i < 5; ++i) {
      row[i] = quantize_coefficient(v[i], c.coef_bits, c.coef_frac,
                                    "section " + std::to_string(k + 1) + " " + kCoefNames[i]);
    }
    q.push_back(std::move(row));
  }
  return q;
}

void validate_words(const BandpassFixedConfig& c) {
  require_in_range("input_bits", c.input_bits, 2, 32);
  require_in_range("coef_bits", c.coef_bits, 2, 62);
  require_in_range("coef_frac", c.coef_frac, 0, 62);
  require_in_range("data_bits", c.data_bits, 2, 64);
  require_in_range("data_frac", c.data_frac, c.input_bits - 1, 62);
  require_in_range("acc_bits", c.acc_bits, 2, 64);
}

int128_t abs128(std::int64_t v) { return v < 0 ? -static_cast<int128_t>(v) : static_cast<int128_t>(v); }

// Minimum signed accumulator width, from the quantized coefficients (requires valid words,
// so every magnitude below is < 2^63 and the sum < 2^127).
int min_acc_bits(const BandpassFixedConfig& c, const std::vector<std::vector<std::int64_t>>& coef) {
  const int128_t x0_max = static_cast<int128_t>(1) << c.data_frac;      // input -1 aligned
  const int128_t data_max = static_cast<int128_t>(1) << (c.data_bits - 1);  // |most negative code|
  int128_t worst = 0;
  for (std::size_t k = 0; k < coef.size(); ++k) {
    const auto& q = coef[k];
    const int128_t x_max = (k == 0) ? x0_max : data_max;
    const int128_t bound = (abs128(q[0]) + abs128(q[1]) + abs128(q[2])) * x_max + (abs128(q[3]) + abs128(q[4])) * data_max;
    worst = std::max(worst, bound);
  }
  int bits = 1;  // sign bit; then magnitude bits until 2^(bits-1) - 1 >= worst
  while (bits < 128 && (static_cast<int128_t>(1) << (bits - 1)) - 1 < worst) ++bits;
  return bits;
}

double pole_radius_of(const Biquad& s) {
  const double d = s.a1 * s.a1 - 4.0 * s.a2;
  if (d < 0) return std::sqrt(s.a2);
  const double r = std::sqrt(d);
  return std::max(std::abs(-s.a1 + r), std::abs(-s.a1 - r)) / 2.0;
}

// ||h||_1 of the chain of sections (a section may be a pure all-pole 1/A), by simulation
// until the response has decayed by 1e-15 of its start; +inf if a pole is on or outside
// the unit circle.
double l1_norm(const std::vector<Biquad>& chain) {
  double r = 0;
  for (const Biquad& s : chain) r = std::max(r, pole_radius_of(s));
  if (!(r < 1.0)) return std::numeric_limits<double>::infinity();
  // A repeated pole decays like n^m r^n; three time constants past 1e-15 covers it.
  const double n_decay = std::log(1e-15) / std::log(std::max(r, 0.5));
  const auto length = static_cast<std::size_t>(std::min(3.0 * n_decay + 256.0, 4e6));
  BandpassFloat f(SosFilter{FilterType::Butterworth, 0, 1.0, chain});
  double sum = 0;
  for (std::size_t n = 0; n < length; ++n) sum += std::abs(f.execute(n == 0 ? 1.0 : 0.0));
  return sum;
}

Biquad all_pole(const Biquad& s) { return Biquad{1, 0, 0, s.a1, s.a2}; }

}  // namespace

void validate(const BandpassFixedConfig& config, const SosFilter& filter) {
  validate_words(config);
  require_sections(filter);
  const auto coef = quantize_sections(config, filter);
  const int need = min_acc_bits(config, coef);
  if (config.acc_bits < need) {
    std::ostringstream os;
    os << "acc_bits: " << config.acc_bits << " can overflow for this filter and these word lengths; "
       << "valid range is [" << need << ", 64] (worst case sum of products needs " << need << " bits)";
    throw InputError(os.str());
  }
}

BandpassFixedLayout resolve_bandpass_layout(const SosFilter& filter, const BandpassFixedConfig& config) {
  validate(config, filter);
  return BandpassFixedLayout{quantize_sections(config, filter)};
}

std::vector<std::int64_t> BandpassFixedLayout::flat() const {
  std::vector<std::int64_t> out;
  for (const auto& c : coefficients) out.insert(out.end(), c.begin(), c.end());
  return out;
}

int bandpass_min_acc_bits(const BandpassFixedConfig& config, const SosFilter& filter) {
  validate_words(config);
  require_sections(filter);
  return min_acc_bits(config, quantize_sections(config, filter));
}

BandpassHeadroom bandpass_headroom(const BandpassFixedConfig& config, const SosFilter& filter) {
  validate(config, filter);
  const auto coef = quantize_sections(config, filter);
  std::vector<Biquad> q;
  for (const auto& c : coef) {
    const double s = std::ldexp(1.0, -config.coef_frac);
    q.push_back(Biquad{c[0] * s, c[1] * s, c[2] * s, c[3] * s, c[4] * s});
  }
  const double lsb = std::ldexp(1.0, -config.data_frac);
  const double max_error = (config.rounding == Rounding::Truncate) ? lsb : lsb / 2;
  BandpassHeadroom h;
  h.limit = std::ldexp(static_cast<double>(fx_max_raw(FixedFormat{config.data_bits, config.data_frac})), -config.data_frac);
  h.no_overflow = true;
  for (std::size_t k = 0; k < q.size(); ++k) {
    const std::vector<Biquad> to_k(q.begin(), q.begin() + static_cast<std::ptrdiff_t>(k) + 1);
    double noise = 0;
    for (std::size_t j = 0; j <= k; ++j) {
      std::vector<Biquad> from_j{all_pole(q[j])};
      from_j.insert(from_j.end(), q.begin() + static_cast<std::ptrdiff_t>(j) + 1,
                    q.begin() + static_cast<std::ptrdiff_t>(k) + 1);
      noise += max_error * l1_norm(from_j);
    }
    // The most negative input, -1, is the largest magnitude the input word holds.
    const double gain = l1_norm(to_k);
    h.signal_gain.push_back(gain);
    h.noise_bound.push_back(noise);
    h.peak_bound.push_back(gain + noise);
    // Tiny relative margin for the double-precision evaluation of the norms.
    if (!((gain + noise) * (1 + 1e-9) <= h.limit)) h.no_overflow = false;
  }
  return h;
}

BandpassFilter::~BandpassFilter() = default;

void BandpassFilter::execute_block(std::span<const double> in, std::span<double> out) {
  if (in.size() != out.size()) {
    throw InputError("bandpass execute_block: output size " + std::to_string(out.size()) +
                     " differs from input size " + std::to_string(in.size()) + "; they must be equal");
  }
  for (std::size_t i = 0; i < in.size(); ++i) out[i] = execute(in[i]);
}

// ---- double precision reference ------------------------------------------------------------

BandpassFloat::BandpassFloat(const SosFilter& filter) : sections_(filter.sections) {
  require_sections(filter);
  for (const Biquad& s : sections_) {
    for (double v : {s.b0, s.b1, s.b2, s.a1, s.a2}) require_finite("bandpass coefficient", v);
  }
  reset();
}

void BandpassFloat::reset() {
  state_.assign(sections_.size(), State{});
  out_.assign(sections_.size(), 0.0);
}

double BandpassFloat::execute(double x) {
  for (std::size_t k = 0; k < sections_.size(); ++k) {
    const Biquad& c = sections_[k];
    State& s = state_[k];
    const double y = c.b0 * x + c.b1 * s.x1 + c.b2 * s.x2 - c.a1 * s.y1 - c.a2 * s.y2;
    s.x2 = s.x1;
    s.x1 = x;
    s.y2 = s.y1;
    s.y1 = y;
    out_[k] = y;
    x = y;
  }
  return x;
}

namespace {

// y = b0 x + b1 x1 + b2 x2 - a1 y1 - a2 y2, left to right: execute()'s expression exactly.
template <int S>
void float_kernel(const double* in, double* out, std::size_t len, const std::vector<Biquad>& c,
                  std::vector<BandpassFloat::State>& st) {
  double b0[S], b1[S], b2[S], a1[S], a2[S], x1[S], x2[S], y1[S], y2[S];
  for (int k = 0; k < S; ++k) {
    b0[k] = c[k].b0, b1[k] = c[k].b1, b2[k] = c[k].b2, a1[k] = c[k].a1, a2[k] = c[k].a2;
    x1[k] = st[k].x1, x2[k] = st[k].x2, y1[k] = st[k].y1, y2[k] = st[k].y2;
  }
  for (std::size_t i = 0; i < len; ++i) {
    double x = in[i];
    for (int k = 0; k < S; ++k) {
      const double y = b0[k] * x + b1[k] * x1[k] + b2[k] * x2[k] - a1[k] * y1[k] - a2[k] * y2[k];
      x2[k] = x1[k];
      x1[k] = x;
      y2[k] = y1[k];
      y1[k] = y;
      x = y;
    }
    out[i] = x;
  }
  for (int k = 0; k < S; ++k) st[k] = {x1[k], x2[k], y1[k], y2[k]};
}

bool ranges_overlap(const void* a, const void* b, std::size_t bytes) {
  const auto x = reinterpret_cast<std::uintptr_t>(a), y = reinterpret_cast<std::uintptr_t>(b);
  return x < y + bytes && y < x + bytes;
}

// The wavefront (batch::bandpass_wave*) pays from this many samples on (its first and last
// kWaveSkew (N - 1) steps are partly idle).
constexpr std::size_t kWaveMin = 64;

bool wave_available() {
  static const bool ok = batch::batch_kernels_available();
  return ok;
}

// The wavefront runs a block whose input and output are the same array or do not overlap
// (it writes out[i] after reading in[i + kWaveSkew (N - 1)]).
bool wave_fits(const void* in, const void* out, std::size_t bytes, std::size_t len, std::size_t sections) {
  return len >= kWaveMin && sections <= static_cast<std::size_t>(batch::kBatchMaxSections) &&
         (in == out || !ranges_overlap(in, out, bytes)) && wave_available();
}

void float_dispatch(const double* in, double* out, std::size_t len, const std::vector<Biquad>& c,
                    std::vector<BandpassFloat::State>& st) {
  if (wave_fits(in, out, len * sizeof(double), len, c.size())) {
    const batch::FloatBandpassBatch k = bandpass_batch_constants(c);
    batch::WaveStateF w;
    for (std::size_t j = 0; j < c.size(); ++j) {
      w.x1.v[j] = st[j].x1, w.x2.v[j] = st[j].x2, w.y1.v[j] = st[j].y1, w.y2.v[j] = st[j].y2;
    }
    batch::bandpass_wave_float(k, w, in, out, len);
    for (std::size_t j = 0; j < c.size(); ++j) st[j] = {w.x1.v[j], w.x2.v[j], w.y1.v[j], w.y2.v[j]};
    return;
  }
  switch (c.size()) {
    case 1: return float_kernel<1>(in, out, len, c, st);
    case 2: return float_kernel<2>(in, out, len, c, st);
    case 3: return float_kernel<3>(in, out, len, c, st);
    case 4: return float_kernel<4>(in, out, len, c, st);
    case 5: return float_kernel<5>(in, out, len, c, st);
    case 6: return float_kernel<6>(in, out, len, c, st);
    case 7: return float_kernel<7>(in, out, len, c, st);
    default: return float_kernel<8>(in, out, len, c, st);
  }
}

// ---- time split: one long block on the SIMD lanes ------------------------------------------
//
// A block of n >= kBandpassSplitMin (fixed) or kBandpassFloatSplitMin (float) samples is cut into
// kBatchLanes segments that run in lockstep on the lanes of the SIMD-across-streams kernels
// (receiver_batch_kernels.hpp, the very arithmetic of the scalar kernels, bit for bit). Lane 0
// starts at sample 0 from the filter's state; lane l >= 1 starts W (the warm-up) samples before
// its segment, from the zero state, and its outputs count only from the segment's first sample
// b_l on. The cascade is stable, so the warm-up lane forgets its start: in practice its state at
// b_l is already, bit for bit, the true one (the state after sample b_l - 1 of the plain run).
// That is checked, never assumed: the true state at b_l is lane l-1's final state (itself
// checked), and a lane whose state at b_l differs is recomputed by the scalar kernel from the
// true state. So the output, the final state and the overflow counts are those of the plain loop
// in every case; only the time depends on the data.
// The lanes run W + (n - W) / 8 steps for n samples: the warm-up adds W / segment to their
// work, at most 1/4 for the fixed cascade (W = 16384, n >= 540672; its lanes must meet the
// true state on its rounding grid), at most 1 for the float one (W = 8192, n >= 73728: 16384
// lockstep steps instead of 73728 scalar ones, which pays; measured in docs/results/speed.md).
constexpr std::size_t kSplitLanes = batch::kBatchLanes;
constexpr std::size_t kFixedSplitWarmup = 16384;
constexpr std::size_t kFloatSplitWarmup = 8192;
constexpr std::size_t kSplitStep = 2048;  // lockstep samples interleaved at a time
static_assert(kFixedSplitWarmup + kSplitLanes * 4 * kFixedSplitWarmup == kBandpassSplitMin);
static_assert(kFloatSplitWarmup + kSplitLanes * kFloatSplitWarmup == kBandpassFloatSplitMin);
static_assert(kFixedSplitWarmup % kSplitStep == 0 && kFloatSplitWarmup % kSplitStep == 0);

// The states are plain structs of four 64-bit words: equal means the same bits (a -0.0 is not
// taken for a +0.0, a NaN is itself).
template <class St>
bool same_state(const std::vector<St>& a, const std::vector<St>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(St)) == 0;
}

// Ops: set_lane(l, state), get_lane(l) -> state, interleave(src, lanes, m), run(in, out, m),
// deinterleave(lanes, dst, m), verify(in, n, done) (after the lockstep, before anything is
// committed: may throw on the input, the lanes having read in[0, done)),
// snapshot() (overflow counts at the end of the warm-up), commit(l) (lane l's counts of its
// own outputs into the filter's counters) and scalar(in, out, m, state) (the plain kernel,
// counting into the filter's counters). Returns how many lanes were recomputed.
template <std::size_t W, class T, class St, class LaneT, class Ops>
std::size_t time_split(const T* in, T* out, std::size_t n, std::vector<St>& state, Ops& ops) {
  constexpr std::size_t L = kSplitLanes;
  const std::size_t seg = (n - W) / L, steps = W + seg;
  const T* src[L];
  for (std::size_t l = 0; l < L; ++l) src[l] = in + l * seg;  // lane l's first input (b_l - W for l >= 1)
  const std::vector<St> zero(state.size(), St{});
  ops.set_lane(0, state);
  for (std::size_t l = 1; l < L; ++l) ops.set_lane(l, zero);
  std::vector<std::vector<St>> at_b(L);  // lane l's state at b_l
  std::vector<LaneT> ib(kSplitStep), ob(kSplitStep);
  std::vector<T> discard(kSplitStep);  // where the warm-up outputs go
  for (std::size_t t0 = 0; t0 < steps;) {
    const std::size_t m = std::min(kSplitStep, (t0 < W ? W : steps) - t0);
    const T* p[L];
    T* o[L];
    for (std::size_t l = 0; l < L; ++l) {
      p[l] = src[l] + t0;
      o[l] = l > 0 && t0 < W ? discard.data() : out + l * seg + t0;
    }
    ops.interleave(p, ib.data(), m);
    ops.run(ib.data(), ob.data(), m);
    ops.deinterleave(ob.data(), o, m);
    t0 += m;
    if (t0 == W) {
      for (std::size_t l = 1; l < L; ++l) at_b[l] = ops.get_lane(l);
      ops.snapshot();
    }
  }
  ops.verify(in, n, L * seg + W);  // may throw: nothing is committed yet
  std::vector<St> truth = ops.get_lane(0);  // the state at b_1: lane 0 ran from the true state
  ops.commit(0);
  std::size_t redone = 0;
  for (std::size_t l = 1; l < L; ++l) {
    const std::size_t b = l * seg + W;
    if (same_state(at_b[l], truth)) {
      truth = ops.get_lane(l);
      ops.commit(l);
    } else {
      ++redone;
      ops.scalar(in + b, out + b, seg, truth);
    }
  }
  const std::size_t done = L * seg + W;
  if (done < n) ops.scalar(in + done, out + done, n - done, truth);
  state = std::move(truth);
  return redone;
}

// Runs split() (a time_split, returning the lanes redone) unless the filter is backing off after
// a failed split; false when it did not run (the caller runs the plain kernel).
template <class Split>
bool try_split(BandpassSplitBackoff& b, BandpassSplitStats& st, Split&& split) {
  if (b.skip > 0) {
    --b.skip;
    ++st.skipped;
    return false;
  }
  const std::size_t redone = split();
  ++st.blocks;
  st.recomputed += redone;
  if (redone >= 2) {  // about what the split saves: back off, longer each time it fails again
    b.backoff = std::min<std::size_t>(64, b.backoff ? 2 * b.backoff : 1);
    b.skip = b.backoff;
  } else {
    b.backoff = 0;
  }
  return true;
}

// The float cascade on the lanes: batch::bandpass_batch_float (BandpassFloat's expression).
struct FloatSplitOps {
  using St = BandpassFloat::State;
  const std::vector<Biquad>& c;
  batch::FloatBandpassBatch b;
  explicit FloatSplitOps(const std::vector<Biquad>& sections)
      : c(sections), b(bandpass_batch_constants(sections)) {}
  void set_lane(std::size_t l, const std::vector<St>& s) {
    for (std::size_t k = 0; k < s.size(); ++k) {
      b.x1[k].v[l] = s[k].x1, b.x2[k].v[l] = s[k].x2, b.y1[k].v[l] = s[k].y1, b.y2[k].v[l] = s[k].y2;
    }
  }
  std::vector<St> get_lane(std::size_t l) const {
    std::vector<St> s(c.size());
    for (std::size_t k = 0; k < s.size(); ++k) s[k] = {b.x1[k].v[l], b.x2[k].v[l], b.y1[k].v[l], b.y2[k].v[l]};
    return s;
  }
  void interleave(const double* const* src, batch::LanesF* o, std::size_t m) {
    batch::interleave_batch_float(src, 1.0, o, m);  // x * 1.0 == x, bit for bit
  }
  void run(const batch::LanesF* i, batch::LanesF* o, std::size_t m) { batch::bandpass_batch_float(b, i, o, m); }
  void deinterleave(const batch::LanesF* i, double* const* dst, std::size_t m) {
    batch::deinterleave_batch_float(i, dst, m);
  }
  void verify(const double*, std::size_t, std::size_t) {}
  void snapshot() {}
  void commit(std::size_t) {}
  void scalar(const double* i, double* o, std::size_t m, std::vector<St>& s) { float_dispatch(i, o, m, c, s); }
};

}  // namespace

void BandpassFloat::execute_block(std::span<const double> in, std::span<double> out) {
  if (in.size() != out.size()) throw InputError("BandpassFloat::execute_block: input and output sizes differ");
  if (in.empty()) return;
  if (sections_.size() > static_cast<std::size_t>(batch::kBatchMaxSections)) {
    for (std::size_t i = 0; i < in.size(); ++i) out[i] = execute(in[i]);
    return;
  }
  const bool long_block = in.size() >= kBandpassFloatSplitMin &&
                          !ranges_overlap(in.data(), out.data(), in.size() * sizeof(double)) &&
                          batch::batch_kernels_available();
  const bool split = long_block && try_split(backoff_, split_, [&] {
    FloatSplitOps ops(sections_);
    return time_split<kFloatSplitWarmup, double, State, batch::LanesF>(in.data(), out.data(), in.size(), state_, ops);
  });
  if (!split) float_dispatch(in.data(), out.data(), in.size(), sections_, state_);
  for (std::size_t k = 0; k < sections_.size(); ++k) out_[k] = state_[k].y1;  // the last sample's
}

// ---- bit-accurate fixed point --------------------------------------------------------------

BandpassFixed::BandpassFixed(const SosFilter& filter, const BandpassFixedConfig& config)
    : filter_(filter), config_(config) {
  coef_ = resolve_bandpass_layout(filter, config).coefficients;  // validates
  input_fmt_ = FixedFormat{config.input_bits, config.input_bits - 1, true, Rounding::RoundHalfUp, Overflow::Saturate};
  data_fmt_ = FixedFormat{config.data_bits, config.data_frac, true, config.rounding, config.overflow};
  input_shift_ = config.data_frac - (config.input_bits - 1);
  data_range_ = fx_range(data_fmt_);
  // The folded rounding bias needs |acc| < 2^61 (see bandpass_kernel) and a dropped bit.
  bias_ok_ = min_acc_bits(config, coef_) <= 62 && config.coef_frac >= 1;
  sym_ok_ = config.data_bits <= 62 && config.data_frac <= 61;
  for (const auto& c : coef_) sym_ok_ = sym_ok_ && c[1] == 0 && c[2] == -c[0];
  reset();
}

void BandpassFixed::reset() {
  state_.assign(coef_.size(), State{});
  out_.assign(coef_.size(), 0);
  section_events_ = {};
  input_events_ = {};
}

void BandpassFixed::throw_input_range(std::int64_t x_in) const {
  std::ostringstream os;
  os << "bandpass input sample: " << x_in << " is out of range; valid range is [" << fx_min_raw(input_fmt_)
     << ", " << fx_max_raw(input_fmt_) << "] (signed " << config_.input_bits << "-bit)";
  throw InputError(os.str());
}

namespace {


// One block through N sections, sample-major, state in locals. Exact: every partial sum of the
// accumulator is bounded by sum |b_i| max|x| + sum |a_i| max|y| < 2^(acc_min - 1), acc_min =
// bandpass_min_acc_bits <= acc_bits <= 64 (validate()), so the int64 arithmetic never
// overflows; the aligned input |x| <= 2^data_frac <= 2^62. Section k's input history is
// section k-1's output history (x1[k] = y1[k-1], x2[k] = y2[k-1]), so only section 0 keeps
// its own. The a1 y1 term is added last: it is the only one on the loop-carried path.
// Bias (RoundHalfUp only, when acc_min <= 62): round half up of acc / 2^s is
// floor((acc + 2^(s-1)) / 2^s), and the constant 2^(s-1) <= 2^61 is folded into the terms off
// the critical path; |acc| + 2^(s-1) < 2^61 + 2^61 cannot overflow.
// Sym (every section's numerator is b0 [1, 0, -1], as a Butterworth/Chebyshev bandpass's are,
// and data_bits <= 62, data_frac <= 61 so every section input |x| < 2^61): b0 x + b2 x2 =
// b0 (x - x2) exactly, |x - x2| < 2^62, one multiply instead of three.
template <int N, Rounding R, Overflow O, bool Bias, bool Sym, class SectionState>
void bandpass_kernel(const std::int64_t* in, std::int64_t* out, std::size_t len, std::int64_t in_scale,
                     const std::vector<std::vector<std::int64_t>>& coef, std::vector<SectionState>& state,
                     int qshift, const FxRange& range, OverflowCounter& counter) {
  std::int64_t b0[N], b1[N], b2[N], a1[N], a2[N], y1[N], y2[N];
  for (int k = 0; k < N; ++k) {
    b0[k] = coef[k][0];
    b1[k] = coef[k][1];
    b2[k] = coef[k][2];
    a1[k] = coef[k][3];
    a2[k] = coef[k][4];
    y1[k] = state[k].y1;
    y2[k] = state[k].y2;
  }
  std::int64_t in1 = state[0].x1, in2 = state[0].x2;
  const std::int64_t bias = Bias ? (std::int64_t{1} << (qshift - 1)) : 0;
  for (std::size_t i = 0; i < len; ++i) {
    std::int64_t x = in[i] * in_scale;
    std::int64_t x1 = in1, x2 = in2;
    in2 = in1;
    in1 = x;
    for (int k = 0; k < N; ++k) {
      std::int64_t part;
      if constexpr (Sym) {
        part = b0[k] * (x - x2) - a2[k] * y2[k] + bias;
      } else {
        part = b0[k] * x + b1[k] * x1 + b2[k] * x2 - a2[k] * y2[k] + bias;
      }
      const std::int64_t acc = part - a1[k] * y1[k];
      std::int64_t y;
      if constexpr (Bias) {
        y = acc >> qshift;
        if (y < range.lo || y > range.hi) [[unlikely]] y = fx_overflow_slow(y, range, O, counter);
      } else {
        y = fx_quantize_fast<R, O>(acc, qshift, range, counter);
      }
      x1 = y1[k];
      x2 = y2[k];
      y2[k] = y1[k];
      y1[k] = y;
      x = y;
    }
    out[i] = x;
  }
  state[0].x1 = in1;
  state[0].x2 = in2;
  state[0].y1 = y1[0];
  state[0].y2 = y2[0];
  for (int k = 1; k < N; ++k) state[k] = SectionState{y1[k - 1], y2[k - 1], y1[k], y2[k]};
}

// Any section count (more than the specialized ones): the same arithmetic from memory.
template <Rounding R, Overflow O, class SectionState>
void bandpass_kernel_any(const std::int64_t* in, std::int64_t* out, std::size_t len, std::int64_t in_scale,
                         const std::vector<std::vector<std::int64_t>>& coef, std::vector<SectionState>& state,
                         int qshift, const FxRange& range, OverflowCounter& counter) {
  for (std::size_t i = 0; i < len; ++i) {
    std::int64_t x = in[i] * in_scale;
    for (std::size_t k = 0; k < coef.size(); ++k) {
      const std::int64_t* c = coef[k].data();
      SectionState& s = state[k];
      const std::int64_t part = c[0] * x + c[1] * s.x1 + c[2] * s.x2 - c[4] * s.y2;
      const std::int64_t y = fx_quantize_fast<R, O>(part - c[3] * s.y1, qshift, range, counter);
      s = SectionState{x, s.x1, y, s.y1};
      x = y;
    }
    out[i] = x;
  }
}

template <Rounding R, Overflow O, class SectionState>
void bandpass_dispatch_sections(const std::int64_t* in, std::int64_t* out, std::size_t len, std::int64_t in_scale,
                                const std::vector<std::vector<std::int64_t>>& coef,
                                std::vector<SectionState>& state, int qshift, const FxRange& range,
                                OverflowCounter& counter, bool bias, bool sym) {
#define RANGING_BP_CASE(n)                                                                         \
  case n:                                                                                          \
    if (bias && sym)                                                                               \
      return bandpass_kernel<n, R, O, R == Rounding::RoundHalfUp, true>(in, out, len, in_scale, coef, state, \
                                                                        qshift, range, counter);   \
    if (bias)                                                                                      \
      return bandpass_kernel<n, R, O, R == Rounding::RoundHalfUp, false>(in, out, len, in_scale, coef, state, \
                                                                         qshift, range, counter);  \
    if (sym)                                                                                       \
      return bandpass_kernel<n, R, O, false, true>(in, out, len, in_scale, coef, state, qshift, range, counter); \
    return bandpass_kernel<n, R, O, false, false>(in, out, len, in_scale, coef, state, qshift, range, counter);
  switch (coef.size()) {
    RANGING_BP_CASE(1)
    RANGING_BP_CASE(2)
    RANGING_BP_CASE(3)
    RANGING_BP_CASE(4)
    RANGING_BP_CASE(5)
    RANGING_BP_CASE(6)
    RANGING_BP_CASE(7)
    RANGING_BP_CASE(8)
    default: return bandpass_kernel_any<R, O>(in, out, len, in_scale, coef, state, qshift, range, counter);
  }
#undef RANGING_BP_CASE
}

// One block of one stream on the wavefront (batch::bandpass_wave) when it fits; false (nothing
// done) otherwise. constants(): the filter's (bandpass_batch_constants; asked only when the
// block fits, so never for more sections than the kernels hold), s: its state.
template <class St, class Constants>
bool fixed_wave(Constants&& constants, bool bias, const std::int64_t* in, std::int64_t* out, std::size_t m,
                std::vector<St>& s, OverflowCounter& counter) {
  if (!wave_fits(in, out, m * sizeof(std::int64_t), m, s.size())) return false;
  const batch::BandpassBatch k = constants();
  batch::WaveState w;
  for (std::size_t j = 0; j < s.size(); ++j) {
    w.x1.v[j] = s[j].x1, w.x2.v[j] = s[j].x2, w.y1.v[j] = s[j].y1, w.y2.v[j] = s[j].y2;
  }
  batch::bandpass_wave(k, bias, w, in, out, m, counter);
  for (std::size_t j = 0; j < s.size(); ++j) s[j] = St{w.x1.v[j], w.x2.v[j], w.y1.v[j], w.y2.v[j]};
  return true;
}

// The fixed cascade on the lanes: batch::bandpass_batch (BandpassFixed's arithmetic, exact
// integers, the same rounding and overflow, counted per lane). St: BandpassFixed::State.
template <class St>
struct FixedSplitOps {
  const std::vector<std::vector<std::int64_t>>& coef;
  const BandpassFixedConfig& cfg;
  std::int64_t in_scale;
  FxRange range;
  bool bias, sym;
  OverflowCounter& target;  // the filter's section counters
  batch::BandpassBatch b;
  OverflowCounter ev[batch::kBatchLanes] = {}, snap[batch::kBatchLanes] = {};
  FixedSplitOps(const BandpassFixed& f, int input_shift, bool bias_ok, OverflowCounter& counter)
      : coef(f.coefficients()), cfg(f.config()), in_scale(std::int64_t{1} << input_shift),
        range(fx_range(f.data_format())), bias(bias_ok), sym(f.sym()), target(counter),
        b(bandpass_batch_constants(f)), filter(f) {
    b.events = ev;
  }
  void set_lane(std::size_t l, const std::vector<St>& s) {
    b.x1.v[l] = s[0].x1;
    b.x2.v[l] = s[0].x2;
    for (std::size_t k = 0; k < s.size(); ++k) b.y1[k].v[l] = s[k].y1, b.y2[k].v[l] = s[k].y2;
  }
  std::vector<St> get_lane(std::size_t l) const {  // the scalar kernel's layout of the state
    std::vector<St> s(coef.size());
    s[0] = St{b.x1.v[l], b.x2.v[l], b.y1[0].v[l], b.y2[0].v[l]};
    for (std::size_t k = 1; k < s.size(); ++k) s[k] = St{b.y1[k - 1].v[l], b.y2[k - 1].v[l], b.y1[k].v[l], b.y2[k].v[l]};
    return s;
  }
  // The input's range, checked on the lanes' reads (interleave) and the rest in verify().
  const BandpassFixed& filter;
  std::int64_t lo = 0, hi = 0;
  void interleave(const std::int64_t* const* src, batch::Lanes* o, std::size_t m) {
    batch::interleave_batch(src, o, m, &lo, &hi);
  }
  void verify(const std::int64_t* in, std::size_t n, std::size_t done) {
    if (lo < fx_min_raw(filter.input_format()) || hi > fx_max_raw(filter.input_format())) {
      filter.check_input(std::span<const std::int64_t>(in, n));  // throws, naming the first bad sample
    }
    filter.check_input(std::span<const std::int64_t>(in + done, n - done));
  }
  void run(const batch::Lanes* i, batch::Lanes* o, std::size_t m) { batch::bandpass_batch(b, i, o, m); }
  void deinterleave(const batch::Lanes* i, std::int64_t* const* dst, std::size_t m) {
    batch::deinterleave_batch(i, dst, m);
  }
  void snapshot() { std::copy(std::begin(ev), std::end(ev), std::begin(snap)); }
  void commit(std::size_t l) {
    target.saturations += ev[l].saturations - (l ? snap[l].saturations : 0);
    target.wraps += ev[l].wraps - (l ? snap[l].wraps : 0);
  }
  void scalar(const std::int64_t* i, std::int64_t* o, std::size_t m, std::vector<St>& s) {
    if (fixed_wave([this] { return b; }, bias, i, o, m, s, target)) return;
    fx_dispatch(cfg.rounding, cfg.overflow, [&]<Rounding R, Overflow O>() {
      bandpass_dispatch_sections<R, O>(i, o, m, in_scale, coef, s, cfg.coef_frac, range, target, bias, sym);
    });
  }
};

}  // namespace

void BandpassFixed::execute_block(std::span<const std::int64_t> in, std::span<std::int64_t> out) {
  if (in.size() != out.size()) {
    throw InputError("bandpass execute_block: output size " + std::to_string(out.size()) +
                     " differs from input size " + std::to_string(in.size()) + "; they must be equal");
  }
  if (in.empty()) return;
  const std::int64_t in_scale = std::int64_t{1} << input_shift_;
  const int qshift = config_.coef_frac;  // acc_frac - data_frac
  const bool long_block = coef_.size() <= static_cast<std::size_t>(batch::kBatchMaxSections) &&
                          in.size() >= kBandpassSplitMin &&
                          !ranges_overlap(in.data(), out.data(), in.size() * sizeof(std::int64_t)) &&
                          batch::batch_kernels_available();
  if (long_block && try_split(backoff_, split_, [&] {
        FixedSplitOps<State> ops(*this, input_shift_, bias_ok_, section_events_);
        return time_split<kFixedSplitWarmup, std::int64_t, State, batch::Lanes>(in.data(), out.data(), in.size(), state_, ops);
      })) {
    for (std::size_t k = 0; k < state_.size(); ++k) out_[k] = state_[k].y1;
    return;
  }
  check_input(in);  // once per block (the split checks on its lanes' reads)
  if (fixed_wave([this] { return bandpass_batch_constants(*this); }, bias_ok_, in.data(), out.data(), in.size(),
                 state_, section_events_)) {
    for (std::size_t k = 0; k < state_.size(); ++k) out_[k] = state_[k].y1;
    return;
  }
  fx_dispatch(config_.rounding, config_.overflow, [&]<Rounding R, Overflow O>() {
    bandpass_dispatch_sections<R, O>(in.data(), out.data(), in.size(), in_scale, coef_, state_, qshift, data_range_,
                                     section_events_, bias_ok_, sym_ok_);
  });
  for (std::size_t k = 0; k < state_.size(); ++k) out_[k] = state_[k].y1;
}

namespace {
// True when some value is outside [lo, hi]. An AVX-512 clone beside the baseline one (picked at
// load time): a compare per value, the same answer.
#if defined(__x86_64__)
[[gnu::target_clones("default", "arch=x86-64-v4")]]
#endif
bool any_outside(const std::int64_t* p, std::size_t n, std::int64_t lo, std::int64_t hi) {
  // v in [lo, hi] exactly when v - lo (mod 2^64) <= hi - lo: one unsigned maximum
  const auto ulo = static_cast<std::uint64_t>(lo);
  std::uint64_t m = 0;
  for (std::size_t i = 0; i < n; ++i) m = std::max(m, static_cast<std::uint64_t>(p[i]) - ulo);
  return m > static_cast<std::uint64_t>(hi) - ulo;
}
}  // namespace

void BandpassFixed::check_input(std::span<const std::int64_t> in) const {
  if (in.empty()) return;
  const std::int64_t lo = fx_min_raw(input_fmt_), hi = fx_max_raw(input_fmt_);
  if (any_outside(in.data(), in.size(), lo, hi)) {
    for (const std::int64_t v : in) {
      if (v < lo || v > hi) throw_input_range(v);
    }
  }
}

std::int64_t BandpassFixed::execute_raw(std::int64_t x_in) {
  // A block of one: the testbenches check the very kernel the block API runs.
  std::int64_t y = 0;
  execute_block(std::span<const std::int64_t>(&x_in, 1), std::span<std::int64_t>(&y, 1));
  return y;
}

double BandpassFixed::execute(double x) {
  require_finite("bandpass input sample", x);
  const std::int64_t in = quantize_input(x, config_.input_bits, &input_events_);  // the ADC model
  return std::ldexp(static_cast<double>(execute_raw(in)), -config_.data_frac);
}

SosFilter BandpassFixed::quantized_filter() const {
  SosFilter q = filter_;
  const double s = std::ldexp(1.0, -config_.coef_frac);
  for (std::size_t k = 0; k < coef_.size(); ++k) {
    const auto& c = coef_[k];
    q.sections[k] = Biquad{c[0] * s, c[1] * s, c[2] * s, c[3] * s, c[4] * s};
  }
  return q;
}

namespace {
void require_batch_sections(std::size_t n) {
  if (n > static_cast<std::size_t>(batch::kBatchMaxSections)) {
    throw InputError("bandpass_batch_constants: " + std::to_string(n) + " sections; the SIMD kernels hold 1.." +
                     std::to_string(batch::kBatchMaxSections));
  }
}
}  // namespace

batch::BandpassBatch bandpass_batch_constants(const BandpassFixed& filter) {
  const auto& cfg = filter.config();
  const auto& coef = filter.coefficients();
  require_batch_sections(coef.size());
  batch::BandpassBatch b;
  b.sections = static_cast<int>(coef.size());
  for (std::size_t k = 0; k < coef.size(); ++k) {
    for (int i = 0; i < 5; ++i) b.coef[k][i] = coef[k][static_cast<std::size_t>(i)];
  }
  b.input_shift = cfg.data_frac - (cfg.input_bits - 1);
  b.qshift = cfg.coef_frac;
  b.rounding = cfg.rounding;
  b.overflow = cfg.overflow;
  b.range = fx_range(filter.data_format());
  // 32 x 32 -> 64 multiplies when every factor fits int32: |coef| < 2^31, the section outputs
  // |y| <= 2^30 (data_bits <= 31), the aligned input |x| <= 2^data_frac <= 2^29, so also
  // |x - x2| < 2^31 (the one-multiply numerator).
  b.narrow = cfg.coef_bits <= 32 && cfg.data_bits <= 31 && cfg.data_frac <= 29;
  b.sym = filter.sym();
  return b;
}

batch::FloatBandpassBatch bandpass_batch_constants(const std::vector<Biquad>& sections) {
  require_batch_sections(sections.size());
  batch::FloatBandpassBatch b;
  b.sections = static_cast<int>(sections.size());
  for (std::size_t k = 0; k < sections.size(); ++k) {
    const Biquad& c = sections[k];
    const double v[5] = {c.b0, c.b1, c.b2, c.a1, c.a2};
    for (int i = 0; i < 5; ++i) b.coef[k][i] = v[i];
  }
  return b;
}

}  // namespace ranging
