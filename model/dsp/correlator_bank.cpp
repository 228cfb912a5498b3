#include "model/dsp/correlator_bank.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <string>

#include "model/base/error.hpp"
#include "model/dsp/bank_lanes.hpp"
#include "model/dsp/front_end_run.hpp"

namespace ranging {
namespace {

int ceil_log2(std::int64_t v) {
  int b = 0;
  while ((std::int64_t{1} << b) < v) ++b;
  return b;
}

int bits_for_magnitude(double bound) {  // signed width holding [-bound, bound]
  return static_cast<int>(std::ceil(std::log2(bound + 1.0))) + 1;
}

void check_reference(const CorrelatorReference& r) {
  require_in_range("correlator: samples per carrier cycle (fs/f)", r.period, 2, 4096);
  require_in_range("correlator: samples per chip", r.chip_samples, r.period, 1 << 16);
  if (r.chip_samples % r.period != 0) {
    throw InputError("correlator: samples per chip must be a whole number of carrier cycles");
  }
  require_in_range("correlator.decimation", r.decimation, 1, r.chip_samples);
  if (r.chip_samples % r.decimation != 0) {
    throw InputError("correlator.decimation: " + std::to_string(r.decimation) +
                     " must divide the samples per chip (" + std::to_string(r.chip_samples) + ")");
  }
  require_in_range("correlator: chip template taps", static_cast<double>(r.chip_taps.size()), 1, 4096);
  if (r.codes.empty()) throw InputError("correlator: the code family has no codes");
  for (const auto& c : r.codes) {
    if (c.size() != r.codes.front().size() || c.empty()) {
      throw InputError("correlator: all codes must have the same, non-zero length");
    }
  }
  if (r.code_gain.size() != r.codes.size()) {
    throw InputError("correlator: one normalization gain per code is required");
  }
  for (double k : r.code_gain) require_in_range("correlator: code normalization gain", k, 1e-30, 1e30);
  require_in_range("correlator: energy window", r.window, 1, 1 << 24);
}

std::vector<std::vector<int>> code_signs(const std::vector<std::vector<std::uint8_t>>& codes) {
  std::vector<std::vector<int>> signs;
  for (const auto& c : codes) {
    std::vector<int> s;
    for (std::uint8_t chip : c) s.push_back(chip ? 1 : -1);
    signs.push_back(std::move(s));
  }
  return signs;
}

// F outputs the combiner reaches back: L - 1 chips of Nc / D outputs, and the current one.
std::size_t combiner_history(std::size_t chips, int chip_samples, int decimation) {
  return (chips - 1) * static_cast<std::size_t>(chip_samples / decimation) + 1;
}
std::size_t combiner_history(const CorrelatorReference& r) {
  return combiner_history(r.codes.front().size(), r.chip_samples, r.decimation);
}

// A mirrored ring of n complex values, zeroed: re and im are 2 n long, so every read of the
// last n is one contiguous window. Returns the index of its newest slot.
template <class T>
std::size_t reset_ring(std::vector<T>& re, std::vector<T>& im, std::size_t n) {
  re.assign(2 * n, T{});
  im.assign(2 * n, T{});
  return n - 1;
}

}  // namespace

std::uint64_t correlation_score(std::uint64_t weighted_power, std::uint64_t norm, int score_bits) {
  const std::uint64_t cap = (std::uint64_t{1} << score_bits) - 1;
  const std::uint64_t q = weighted_power / std::max<std::uint64_t>(norm, 1);
  return q > cap ? cap : q;
}

// ---------------------------------------------------------------------------------------
// Layout: every exact node's width follows from its bound, so no exact node can overflow.

CorrelatorFixedLayout resolve_correlator_layout(const CorrelatorReference& ref,
                                                const CorrelatorFixedConfig& cfg) {
  check_reference(ref);
  require_in_range("correlator_fixed.data_bits", cfg.data_bits, 2, 32);
  require_in_range("correlator_fixed.data_frac", cfg.data_frac, 0, cfg.data_bits - 1);
  require_in_range("correlator_fixed.lo_bits", cfg.lo_bits, 3, 24);
  require_in_range("correlator_fixed.mix_bits", cfg.mix_bits, 2, 32);
  require_in_range("correlator_fixed.tap_bits", cfg.tap_bits, 2, 24);
  require_in_range("correlator_fixed.chip_bits", cfg.chip_bits, 2, 40);
  require_in_range("correlator_fixed.corr_bits", cfg.corr_bits, 2, 31);
  require_in_range("correlator_fixed.weight_bits", cfg.weight_bits, 2, 24);
  require_in_range("correlator_fixed.score_bits", cfg.score_bits, 4, 24);

  CorrelatorFixedLayout l;
  l.period = ref.period;
  l.chip_samples = ref.chip_samples;
  l.decimation = ref.decimation;
  l.chips = static_cast<int>(ref.codes.front().size());
  l.codes = static_cast<int>(ref.codes.size());
  l.taps = static_cast<int>(ref.chip_taps.size());
  l.window = ref.window;
  const int int_bits = cfg.data_bits - cfg.data_frac;  // integer bits of y, sign included
  l.mix_frac = cfg.mix_bits - int_bits;
  l.mix_shift = cfg.data_frac + cfg.lo_bits - 1 - l.mix_frac;
  if (l.mix_shift < 0) {
    throw InputError("correlator_fixed.mix_bits: " + std::to_string(cfg.mix_bits) +
                     " keeps more fraction bits than the product has; valid range is [2, " +
                     std::to_string(cfg.data_bits + cfg.lo_bits - 1) + "]");
  }
  l.dec_bits = cfg.mix_bits + ceil_log2(ref.period);

  // Tables: LO and taps scaled to the largest odd-symmetric code, 2^(bits-1) - 1.
  const double lo_amp = std::exp2(cfg.lo_bits - 1) - 1.0;
  for (int k = 0; k < ref.period; ++k) {
    const double w = 2.0 * std::numbers::pi * k / ref.period;
    l.lo_cos.push_back(std::llround(lo_amp * std::cos(w)));
    l.lo_sin.push_back(std::llround(lo_amp * std::sin(w)));
  }
  const double tap_amp = std::exp2(cfg.tap_bits - 1) - 1.0;
  double peak = 0;
  for (double g : ref.chip_taps) peak = std::max(peak, std::abs(g));
  if (peak <= 0) throw InputError("correlator: the chip template is all zero");
  std::int64_t tap_l1 = 0;
  for (double g : ref.chip_taps) {
    l.taps_q.push_back(std::llround(tap_amp * g / peak));
    tap_l1 += std::abs(l.taps_q.back());
  }

  // F: |F| <= sum |g_q| * 2^(dec_bits-1). Quantize so that bound fits chip_bits (no saturation).
  l.fir_bits = bits_for_magnitude(static_cast<double>(tap_l1) * std::exp2(l.dec_bits - 1));
  if (l.fir_bits > 62) throw InputError("correlator: chip filter accumulator exceeds 62 bits");
  // F and C scale: fixed = float * 2^mix_frac * lo_amp/2^(lo_bits-1) * tap_amp/peak / 2^shift.
  // A full-scale input (peak 1) peaks 6 dB below the top of chip_bits and corr_bits.
  const double front = (lo_amp / std::exp2(cfg.lo_bits - 1)) * std::exp2(l.mix_frac) * (tap_amp / peak);
  if (!(ref.chip_peak > 0) || !(ref.corr_peak > 0)) {
    throw InputError("correlator: the reference has no chip/corr peak (design it with design_receiver)");
  }
  l.chip_shift = std::max(0, static_cast<int>(std::ceil(std::log2(ref.chip_peak * front))) -
                                 (cfg.chip_bits - 2));
  l.chip_shift = std::min(l.chip_shift, l.fir_bits);
  l.comb_bits = cfg.chip_bits + ceil_log2(l.chips);
  l.corr_shift = cfg.corr_shift >= 0
                     ? cfg.corr_shift
                     : std::max(0, static_cast<int>(std::ceil(std::log2(
                                       ref.corr_peak * front * std::exp2(-l.chip_shift)))) -
                                       (cfg.corr_bits - 2));
  require_in_range("correlator_fixed.corr_shift", l.corr_shift, 0, l.comb_bits);
  l.power_bits = 2 * cfg.corr_bits;  // Re = Im = -2^(corr_bits-1) gives P = 2^(2 corr_bits - 1)
  l.weighted_bits = l.power_bits + cfg.weight_bits;
  l.energy_bits = 2 * cfg.data_bits - 1 + ceil_log2(ref.window);
  if (l.energy_bits > 63 || l.weighted_bits > 63) {
    throw InputError("correlator: energy or weighted power exceeds 63 bits; lower "
                     "correlator_fixed.data_bits, corr_bits or weight_bits");
  }

  // Scale from float P to fixed P: the float bank computes with the unscaled LO and taps.
  const double amp = front * std::exp2(-(l.chip_shift + l.corr_shift));
  const double s_p = amp * amp;
  double max_raw = 0;
  std::vector<double> raw;
  for (double k : ref.code_gain) {
    raw.push_back(std::exp2(cfg.score_bits + 2.0 * cfg.data_frac) / (k * s_p));
    max_raw = std::max(max_raw, raw.back());
  }
  if (cfg.energy_shift >= 0) {
    l.energy_shift = cfg.energy_shift;
  } else {
    // Largest weight in [2^(weight_bits-1), 2^weight_bits): the most precision that fits.
    l.energy_shift = std::max(0, static_cast<int>(std::floor(std::log2(max_raw))) - (cfg.weight_bits - 1));
  }
  require_in_range("correlator_fixed.energy_shift", l.energy_shift, 0, l.energy_bits);
  for (double r : raw) {
    const double w = std::round(r * std::exp2(-l.energy_shift));
    if (w < 1 || w >= std::exp2(cfg.weight_bits)) {
      throw InputError("correlator_fixed.energy_shift: " + std::to_string(l.energy_shift) +
                       " gives a code weight of " + std::to_string(w) +
                       "; valid range keeps every weight in [1, 2^weight_bits)");
    }
    l.weights.push_back(static_cast<std::int64_t>(w));
  }
  return l;
}

std::vector<std::complex<double>> baseband_decimate(std::span<const double> x, int period,
                                                    int decimation) {
  std::vector<std::complex<double>> b(x.size()), out;
  std::complex<double> acc = 0;
  for (std::size_t n = 0; n < x.size(); ++n) {
    const double w = 2.0 * std::numbers::pi * static_cast<double>(n % period) / period;
    b[n] = x[n] * std::polar(1.0, -w);
    acc += b[n];
    if (n >= static_cast<std::size_t>(period)) acc -= b[n - period];
    if ((n + 1) % decimation == 0) out.push_back(acc);
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// Float reference.

CorrelatorBankFloat::CorrelatorBankFloat(const CorrelatorReference& ref)
    : ref_(ref), chips_(static_cast<int>(ref.codes.empty() ? 0 : ref.codes.front().size())) {
  check_reference(ref_);
  for (const auto& code : ref_.codes) {
    for (int c = 0; c < chips_; ++c) signs_.push_back(code[static_cast<std::size_t>(c)] ? 1.0 : -1.0);
  }
  reset();
}

void CorrelatorBankFloat::reset() {
  n_ = 0;
  dec_phase_ = 0;
  acc_re_ = acc_im_ = energy_ = 0;
  ready_ = false;
  b_re_.assign(static_cast<std::size_t>(ref_.period), 0.0);
  b_im_.assign(b_re_.size(), 0.0);
  b_idx_ = 0;
  lo_cos_.clear();
  lo_sin_.clear();
  for (int p = 0; p < ref_.period; ++p) {  // the same expression the per-sample form evaluated
    const double w = 2.0 * std::numbers::pi * static_cast<double>(p) / ref_.period;
    lo_cos_.push_back(std::cos(w));
    lo_sin_.push_back(std::sin(w));
  }
  bd_n_ = ref_.chip_taps.size();
  bd_idx_ = reset_ring(bd_re_, bd_im_, bd_n_);
  f_n_ = combiner_history(ref_);
  f_idx_ = reset_ring(f_re_, f_im_, f_n_);
  y2_.assign(static_cast<std::size_t>(ref_.window), 0.0);
  y_idx_ = y2_.size() - 1;
  q_.assign(ref_.codes.size(), 0.0);
  c_re_.assign(q_.size(), 0.0);
  c_im_.assign(q_.size(), 0.0);
  f_last_re_ = f_last_im_ = 0;
}

double CorrelatorBankFloat::chip_magnitude() const { return std::hypot(f_last_re_, f_last_im_); }

double CorrelatorBankFloat::max_corr_magnitude() const {
  double m = 0;
  for (std::size_t j = 0; j < q_.size(); ++j) m = std::max(m, std::hypot(c_re_[j], c_im_[j]));
  return m;
}

bool CorrelatorBankFloat::execute(double y) {
  feed(std::span<const double>(&y, 1));
  return ready_;
}

// The front end (mixer, one-cycle moving sum, energy window, decimation) over in[0..], its
// state in locals: at every sample that completes a decimated output, at_output(i, B_re, B_im,
// E) (i its index in `in`); stops after that sample when it returns true. Returns how many
// samples were consumed. The state is stored back at the end.
template <class AtOutput>
std::size_t CorrelatorBankFloat::front_end(std::span<const double> in, AtOutput&& at_output) {
  const double* lo_cos = lo_cos_.data();
  const double* lo_sin = lo_sin_.data();
  double* b_re = b_re_.data();
  double* b_im = b_im_.data();
  double* y2h = y2_.data();
  const std::size_t period = b_re_.size(), window = y2_.size();
  const int decimation = ref_.decimation;
  std::size_t b_idx = b_idx_, y_idx = y_idx_;
  int dec_phase = dec_phase_;
  double acc_re = acc_re_, acc_im = acc_im_, energy = energy_;
  std::size_t i = 0;
  const std::size_t n = in.size();
  while (i < n) {
    // a run with no wrap and no output inside (front_end_run.hpp)
    const FrontEndRun r = front_end_run(n - i, b_idx, period, y_idx, window, dec_phase, decimation);
    const double* x = in.data() + i;
    const double* lc = lo_cos + b_idx;
    const double* ls = lo_sin + b_idx;
    double* br = b_re + b_idx;
    double* bi = b_im + b_idx;
    double* yh = y2h + r.y0;
    for (std::size_t u = 0; u < r.len; ++u) {
      const double y = x[u];
      const double bre = y * lc[u], bim = -y * ls[u];
      acc_re += bre - br[u];
      acc_im += bim - bi[u];
      br[u] = bre;
      bi[u] = bim;
      energy += y * y - yh[u];
      yh[u] = y * y;
      energy = std::max(energy, 0.0);  // running-sum rounding in double
    }
    i += r.len;
    if (front_end_advance(r, b_idx, period, y_idx, dec_phase, decimation)) {
      if (at_output(i - 1, acc_re, acc_im, energy)) break;
    }
  }
  b_idx_ = b_idx;
  y_idx_ = y_idx;
  dec_phase_ = dec_phase;
  acc_re_ = acc_re;
  acc_im_ = acc_im;
  energy_ = energy;
  return i;
}

std::size_t CorrelatorBankFloat::feed(std::span<const double> in) {
  ready_ = false;
  const std::size_t i = front_end(in, [this](std::size_t, double, double, double) { return ready_ = true; });
  n_ += static_cast<std::int64_t>(i);
  if (ready_) decimated_output();
  return i;
}

void CorrelatorBankFloat::decimated_output() {
  if (++bd_idx_ == bd_n_) bd_idx_ = 0;
  bd_re_[bd_idx_] = bd_re_[bd_idx_ + bd_n_] = acc_re_;
  bd_im_[bd_idx_] = bd_im_[bd_idx_ + bd_n_] = acc_im_;
  double fre = 0, fim = 0;
  const std::size_t m = bd_n_;
  const double* bre_h = bd_re_.data() + bd_idx_ + m;  // Bd[k - i] = bre_h[-i]
  const double* bim_h = bd_im_.data() + bd_idx_ + m;
  for (std::size_t i = 0; i < m; ++i) {
    fre += ref_.chip_taps[i] * bre_h[-static_cast<std::ptrdiff_t>(i)];
    fim += ref_.chip_taps[i] * bim_h[-static_cast<std::ptrdiff_t>(i)];
  }
  if (++f_idx_ == f_n_) f_idx_ = 0;
  f_re_[f_idx_] = f_re_[f_idx_ + f_n_] = fre;
  f_im_[f_idx_] = f_im_[f_idx_ + f_n_] = fim;
  f_last_re_ = fre;
  f_last_im_ = fim;

  const std::size_t step = static_cast<std::size_t>(ref_.chip_samples / ref_.decimation);
  for (std::size_t j = 0; j < q_.size(); ++j) {
    double cre = 0, cim = 0;
    for (int c = 0; c < chips_; ++c) {
      const std::size_t k = f_idx_ + f_n_ - static_cast<std::size_t>(chips_ - 1 - c) * step;
      const double s = ref_.codes[j][c] ? 1.0 : -1.0;
      cre += s * f_re_[k];
      cim += s * f_im_[k];
    }
    q_[j] = (cre * cre + cim * cim) / ref_.code_gain[j];
    c_re_[j] = cre;
    c_im_[j] = cim;
  }
}

namespace {
#if defined(__x86_64__)
#define RANGING_BANK_CLONES [[gnu::target_clones("default", "arch=x86-64-v4")]]
#else
#define RANGING_BANK_CLONES
#endif

// The chip filter of k consecutive outputs: f[u] = sum over i < m of taps[i] bd[u + m - 1 - i],
// each sum from 0.0 in i order, product then sum (decimated_output's operations per output;
// one output per SIMD lane in the AVX-512 clone, picked at load time: the same doubles).
RANGING_BANK_CLONES void chip_fir_run(const double* taps, std::size_t m, const double* bd, std::size_t k, double* f) {
  for (std::size_t u = 0; u < k; ++u) f[u] = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    const double t = taps[i];
    const double* b = bd + (m - 1 - i);
    for (std::size_t u = 0; u < k; ++u) f[u] += t * b[u];
  }
}

// The combiner of one code over k consecutive outputs: C[u] = sum over chips c of
// sign[c] f[u + c step] (from 0.0 in chip order, oldest chip first), Q[u] = (Cre^2 + Cim^2) / gain.
RANGING_BANK_CLONES void combine_run(const double* sign, std::size_t chips, std::size_t step, const double* fre,
                                     const double* fim, std::size_t k, double gain, double* cre, double* cim,
                                     double* q) {
  for (std::size_t u = 0; u < k; ++u) cre[u] = cim[u] = 0.0;
  for (std::size_t c = 0; c < chips; ++c) {
    const double s = sign[c];
    const double* a = fre + c * step;
    const double* b = fim + c * step;
    for (std::size_t u = 0; u < k; ++u) {
      cre[u] += s * a[u];
      cim[u] += s * b[u];
    }
  }
  for (std::size_t u = 0; u < k; ++u) q[u] = (cre[u] * cre[u] + cim[u] * cim[u]) / gain;
}

constexpr std::size_t kOutputRun = 256;  // outputs computed together by feed_outputs
}  // namespace

void CorrelatorBankFloat::feed_outputs(std::span<const double> in, const OutputSink& out) {
  if (in.empty()) return;  // as a feed() loop over nothing: nothing changes
  const std::size_t m = bd_n_, h = f_n_ - 1;  // Bd and F history before a run's first output
  run_bd_re_.resize(m - 1 + kOutputRun);
  run_bd_im_.resize(run_bd_re_.size());
  run_f_re_.resize(h + kOutputRun);
  run_f_im_.resize(run_f_re_.size());
  run_e_.resize(kOutputRun);
  run_n_.resize(kOutputRun);
  std::size_t k = 0;  // outputs in the run
  front_end(in, [&](std::size_t i, double acc_re, double acc_im, double energy) {
    run_bd_re_[m - 1 + k] = acc_re;
    run_bd_im_[m - 1 + k] = acc_im;
    run_e_[k] = energy;
    run_n_[k] = n_ + static_cast<std::int64_t>(i);
    if (++k == kOutputRun) {  // (output_run reads none of the front end's state)
      output_run(k, out);
      k = 0;
    }
    return false;
  });
  if (k > 0) output_run(k, out);
  n_ += static_cast<std::int64_t>(in.size());
  ready_ = dec_phase_ == 0;  // the last sample completed an output
}

// The k outputs whose decimator values are in run_bd_*[m - 1 ..]: the histories before them
// come from the rings, the rings take the new values after.
void CorrelatorBankFloat::output_run(std::size_t k, const OutputSink& out) {
  const std::size_t m = bd_n_, h = f_n_ - 1, codes = q_.size();
  const auto chips = static_cast<std::size_t>(chips_);
  const auto step = static_cast<std::size_t>(ref_.chip_samples / ref_.decimation);
  // the last m - 1 Bd and h F values, oldest first (each ring's newest slot is idx + n)
  std::copy_n(bd_re_.data() + bd_idx_ + 2, m - 1, run_bd_re_.data());
  std::copy_n(bd_im_.data() + bd_idx_ + 2, m - 1, run_bd_im_.data());
  std::copy_n(f_re_.data() + f_idx_ + 2, h, run_f_re_.data());
  std::copy_n(f_im_.data() + f_idx_ + 2, h, run_f_im_.data());
  chip_fir_run(ref_.chip_taps.data(), m, run_bd_re_.data(), k, run_f_re_.data() + h);
  chip_fir_run(ref_.chip_taps.data(), m, run_bd_im_.data(), k, run_f_im_.data() + h);
  run_cre_.resize(k);
  run_cim_.resize(k);
  run_q_.resize(codes * k);
  for (std::size_t j = 0; j < codes; ++j) {
    combine_run(signs_.data() + j * chips, chips, step, run_f_re_.data(), run_f_im_.data(), k, ref_.code_gain[j],
                run_cre_.data(), run_cim_.data(), run_q_.data() + j * k);
    c_re_[j] = run_cre_[k - 1];
    c_im_[j] = run_cim_[k - 1];
  }
  for (std::size_t u = 0; u < k; ++u) {
    if (++bd_idx_ == bd_n_) bd_idx_ = 0;
    bd_re_[bd_idx_] = bd_re_[bd_idx_ + bd_n_] = run_bd_re_[m - 1 + u];
    bd_im_[bd_idx_] = bd_im_[bd_idx_ + bd_n_] = run_bd_im_[m - 1 + u];
    if (++f_idx_ == f_n_) f_idx_ = 0;
    f_re_[f_idx_] = f_re_[f_idx_ + f_n_] = run_f_re_[h + u];
    f_im_[f_idx_] = f_im_[f_idx_ + f_n_] = run_f_im_[h + u];
  }
  f_last_re_ = run_f_re_[h + k - 1];
  f_last_im_ = run_f_im_[h + k - 1];
  // row 0: the previous output's Q_j, row u + 1: output u's
  run_rows_.resize((k + 1) * codes);
  std::copy(q_.begin(), q_.end(), run_rows_.begin());
  for (std::size_t u = 0; u < k; ++u) {
    for (std::size_t j = 0; j < codes; ++j) run_rows_[(u + 1) * codes + j] = run_q_[j * k + u];
  }
  std::copy_n(run_rows_.begin() + static_cast<std::ptrdiff_t>(k * codes), codes, q_.begin());
  for (std::size_t u = 0; u < k; ++u) {
    const double* prev = run_rows_.data() + u * codes;
    out(std::span<const double>(prev + codes, codes), std::span<const double>(prev, codes), run_n_[u], run_e_[u]);
  }
}

// ---------------------------------------------------------------------------------------
// Bit-accurate model.

CorrelatorBankFixed::CorrelatorBankFixed(const CorrelatorReference& ref,
                                         const CorrelatorFixedConfig& cfg)
    : cfg_(cfg), layout_(resolve_correlator_layout(ref, cfg)), signs_(code_signs(ref.codes)) {
  mix_fmt_ = FixedFormat{cfg.mix_bits, layout_.mix_frac, true, Rounding::RoundHalfUp, Overflow::Saturate};
  chip_fmt_ = FixedFormat{cfg.chip_bits, 0, true, Rounding::RoundHalfUp, Overflow::Saturate};
  corr_fmt_ = FixedFormat{cfg.corr_bits, 0, true, Rounding::RoundHalfUp, Overflow::Saturate};
  mix_range_ = fx_range(mix_fmt_);
  chip_range_ = fx_range(chip_fmt_);
  corr_range_ = fx_range(corr_fmt_);
  for (const auto& row : signs_) {
    for (int sg : row) sign_mask_.push_back(sg < 0 ? -1 : 0);
  }
  taps_rev_.assign(layout_.taps_q.rbegin(), layout_.taps_q.rend());
  reset();
}

void CorrelatorBankFixed::reset() {
  n_ = 0;
  clear_state();
  mix_events_ = chip_events_ = corr_events_ = {};
}

void CorrelatorBankFixed::clear_state() {
  const auto& l = layout_;
  phase_ = 0;
  dec_phase_ = 0;
  ready_ = false;
  mix_re_ = mix_im_ = acc_re_ = acc_im_ = 0;
  b_re_.assign(static_cast<std::size_t>(l.period), 0);
  b_im_.assign(b_re_.size(), 0);
  bd_n_ = static_cast<std::size_t>(l.taps);
  bd_idx_ = reset_ring(bd_re_, bd_im_, bd_n_);
  f_n_ = combiner_history(static_cast<std::size_t>(l.chips), l.chip_samples, l.decimation);
  f_idx_ = reset_ring(f_re_, f_im_, f_n_);
  y2_.assign(static_cast<std::size_t>(l.window), 0);
  y_idx_ = y2_.size() - 1;
  energy_ = 0;
  corr_re_.assign(l.codes, 0);
  corr_im_.assign(l.codes, 0);
  p_.assign(l.codes, 0);
  q_.assign(l.codes, 0);
  comb_re_.assign(l.codes, 0);
  comb_im_.assign(l.codes, 0);
  chip_acc_re_ = chip_acc_im_ = 0;
}

bool CorrelatorBankFixed::execute(std::int64_t y) {
  feed(std::span<const std::int64_t>(&y, 1));
  return ready_;
}

std::size_t CorrelatorBankFixed::feed(std::span<const std::int64_t> in) {
  using enum Rounding;
  const auto& l = layout_;
  // Exact int64 bounds: |y| < 2^(data_bits-1) <= 2^31 and |lo| < 2^(lo_bits-1) <= 2^23, so
  // |y lo| < 2^54; |acc| < 2^(dec_bits-1) <= 2^37; y^2 < 2^62 and E < 2^energy_bits <= 2^63
  // (resolve_correlator_layout refuses wider), so E is exact in uint64.
  const int mix_shift = l.mix_shift;
  const std::int64_t* lo_cos = l.lo_cos.data();
  const std::int64_t* lo_sin = l.lo_sin.data();
  std::int64_t* b_re = b_re_.data();
  std::int64_t* b_im = b_im_.data();
  std::uint64_t* y2h = y2_.data();
  const int period = l.period;
  const std::size_t window = y2_.size();
  int phase = phase_, dec_phase = dec_phase_;
  std::size_t y_idx = y_idx_;
  std::int64_t acc_re = acc_re_, acc_im = acc_im_, mre = mix_re_, mim = mix_im_;
  std::uint64_t energy = energy_;
  std::size_t i = 0;
  ready_ = false;
  const std::size_t n = in.size();
  while (i < n) {
    // a run with no wrap and no output inside (front_end_run.hpp)
    const FrontEndRun r = front_end_run(n - i, phase, period, y_idx, window, dec_phase, l.decimation);
    for (std::size_t u = 0; u < r.len; ++u) {
      const std::int64_t y = in[i + u];
      const std::size_t ph = static_cast<std::size_t>(phase) + u;
      // 1. mixer: exact product, round half up into the mixer format.
      mre = fx_quantize_fast<RoundHalfUp, Overflow::Saturate>(y * lo_cos[ph], mix_shift, mix_range_, mix_events_);
      mim = fx_quantize_fast<RoundHalfUp, Overflow::Saturate>(-y * lo_sin[ph], mix_shift, mix_range_, mix_events_);
      // 2. moving sum over one carrier cycle (exact; dec_bits hold it).
      acc_re += mre - b_re[ph];
      acc_im += mim - b_im[ph];
      b_re[ph] = mre;
      b_im[ph] = mim;
      // 7. energy: running sum of y^2 over the window, exact.
      const std::uint64_t y2 = static_cast<std::uint64_t>(y * y);
      energy = energy + y2 - y2h[r.y0 + u];
      y2h[r.y0 + u] = y2;
    }
    i += r.len;
    if (front_end_advance(r, phase, period, y_idx, dec_phase, l.decimation)) {
      ready_ = true;
      break;
    }
  }
  n_ += static_cast<std::int64_t>(i);
  phase_ = phase;
  dec_phase_ = dec_phase;
  y_idx_ = y_idx;
  acc_re_ = acc_re;
  acc_im_ = acc_im;
  mix_re_ = mre;
  mix_im_ = mim;
  energy_ = energy;
  if (ready_) decimated_output();
  return i;
}

void CorrelatorBankFixed::decimated_output() {
  using enum Rounding;
  const auto& l = layout_;
  // decimator output: every D-th moving sum, written to both copies of the ring.
  if (++bd_idx_ == bd_n_) bd_idx_ = 0;
  bd_re_[bd_idx_] = bd_re_[bd_idx_ + bd_n_] = acc_re_;
  bd_im_[bd_idx_] = bd_im_[bd_idx_ + bd_n_] = acc_im_;
  // 3. chip filter: exact accumulation (fir_bits <= 62), then round half up by chip_shift.
  // The window Bd[k], Bd[k-1], ..., Bd[k-M+1] is slots bd_idx_ + M, ..., bd_idx_ + 1.
  std::int64_t fre = 0, fim = 0;
  const std::int64_t* bre = bd_re_.data() + bd_idx_ + 1;
  const std::int64_t* bim = bd_im_.data() + bd_idx_ + 1;
  const std::int64_t* taps = taps_rev_.data();
  for (std::size_t i = 0; i < bd_n_; ++i) {
    fre += taps[i] * bre[i];
    fim += taps[i] * bim[i];
  }
  if (++f_idx_ == f_n_) f_idx_ = 0;
  const std::int64_t fq_re = fx_quantize_fast<RoundHalfUp, Overflow::Saturate>(fre, l.chip_shift, chip_range_, chip_events_);
  const std::int64_t fq_im = fx_quantize_fast<RoundHalfUp, Overflow::Saturate>(fim, l.chip_shift, chip_range_, chip_events_);
  chip_acc_re_ = fre;
  chip_acc_im_ = fim;
  f_re_[f_idx_] = f_re_[f_idx_ + f_n_] = fq_re;
  f_im_[f_idx_] = f_im_[f_idx_ + f_n_] = fq_im;

  // 4-6. combiner (exact, comb_bits), quantize, power, weight. Chip c of every code reads
  // F[k - (L-1-c) Nc/D], slot f_idx_ + f_n_ - (L-1-c) step of the doubled ring.
  const std::size_t step = static_cast<std::size_t>(l.chip_samples / l.decimation);
  const std::size_t chips = static_cast<std::size_t>(l.chips);
  std::int64_t g_re[64], g_im[64];
  std::vector<std::int64_t> g_heap;
  std::int64_t* gr = g_re;
  std::int64_t* gi = g_im;
  if (chips > 64) {
    g_heap.resize(2 * chips);
    gr = g_heap.data();
    gi = g_heap.data() + chips;
  }
  for (std::size_t c = 0; c < chips; ++c) {
    const std::size_t k = f_idx_ + f_n_ - (chips - 1 - c) * step;
    gr[c] = f_re_[k];
    gi[c] = f_im_[k];
  }
  // s g as (g ^ m) - m with the sign's mask m (0: +g, -1: ~g + 1 = -g), exact for |g| < 2^62:
  // adds instead of multiplies.
  const std::int64_t* sm = sign_mask_.data();
  for (std::size_t j = 0; j < q_.size(); ++j, sm += chips) {
    std::int64_t cre = 0, cim = 0;
    for (std::size_t c = 0; c < chips; ++c) {
      cre += (gr[c] ^ sm[c]) - sm[c];
      cim += (gi[c] ^ sm[c]) - sm[c];
    }
    comb_re_[j] = cre;
    comb_im_[j] = cim;
    corr_re_[j] = fx_quantize_fast<RoundHalfUp, Overflow::Saturate>(cre, l.corr_shift, corr_range_, corr_events_);
    corr_im_[j] = fx_quantize_fast<RoundHalfUp, Overflow::Saturate>(cim, l.corr_shift, corr_range_, corr_events_);
    p_[j] = static_cast<std::uint64_t>(corr_re_[j] * corr_re_[j] + corr_im_[j] * corr_im_[j]);
    q_[j] = p_[j] * static_cast<std::uint64_t>(l.weights[j]);
  }
}

// ---- the bank on the SIMD lanes ---------------------------------------------------------

FixedBankLanes::FixedBankLanes(const CorrelatorBankFixed& bank) {
  const CorrelatorFixedLayout& l = bank.layout_;
  b.period = l.period;
  b.decimation = l.decimation;
  b.taps = l.taps;
  b.chips = l.chips;
  b.codes = l.codes;
  b.step = l.chip_samples / l.decimation;
  b.mix_shift = l.mix_shift;
  b.chip_shift = l.chip_shift;
  b.corr_shift = l.corr_shift;
  b.mix_range = bank.mix_range_;
  b.chip_range = bank.chip_range_;
  b.corr_range = bank.corr_range_;
  // taps < 2^(tap_bits-1) <= 2^23; Bd < 2^(dec_bits-1); C_q < 2^(corr_bits-1)
  b.fir_narrow = bank.cfg_.tap_bits <= 32 && l.dec_bits <= 32;
  b.power_narrow = bank.cfg_.corr_bits <= 32;
  // P < 2^power_bits and 0 <= w < 2^weight_bits
  b.weight_narrow = l.power_bits <= 32 && bank.cfg_.weight_bits <= 32;
  lo_cos = l.lo_cos;
  for (std::int64_t v : l.lo_sin) lo_nsin.push_back(-v);
  taps_rev = bank.taps_rev_;
  sign_mask = bank.sign_mask_;
  weights = l.weights;
  b.lo_cos = lo_cos.data();
  b.lo_nsin = lo_nsin.data();
  b.taps_rev = taps_rev.data();
  b.sign_mask = sign_mask.data();
  b.weights = weights.data();
  b.window = static_cast<std::size_t>(l.window);
  b.bd_n = bank.bd_n_;
  b.f_n = bank.f_n_;
  b.mix_events = mix_events;
  b.chip_events = chip_events;
  b.corr_events = corr_events;
  reset();
}

void FixedBankLanes::reset() {
  arrays.reset(b);  // CorrelatorBankFixed::reset's positions
  b.phase = 0;
  for (int l = 0; l < batch::kBatchLanes; ++l) mix_events[l] = chip_events[l] = corr_events[l] = {};
}

std::size_t CorrelatorBankFixed::split_memory() const {
  const auto& l = layout_;
  const std::size_t P = static_cast<std::size_t>(l.period), D = static_cast<std::size_t>(l.decimation);
  // The oldest sample the state reads: the energy window, or the oldest F's oldest Bd's moving
  // sum (D - 1 samples since the last output, f_n - 1 outputs, bd_n - 1 outputs, P samples).
  const std::size_t h = std::max(y2_.size(), D * (f_n_ + bd_n_ - 1) + P);
  const std::size_t a = std::lcm(P, D);
  return (h + a - 1) / a * a;
}

std::size_t CorrelatorBankFixed::split_min_samples() const {
  // Segments of at least 2 H (the warm-up at most a third of the lanes' work: a lane sample
  // costs about a third of a plain one), and not under 16 Ki.
  const std::size_t h = split_memory(), a = std::lcm<std::size_t>(layout_.period, layout_.decimation);
  return std::max<std::size_t>(std::size_t{1} << 14, h + batch::kBatchLanes * (2 * h + a));
}

std::size_t CorrelatorBankFixed::split_max_samples() const {
  // The lanes' outputs wait in memory: L (T / D + 1) (codes + 2) words for T lockstep steps,
  // at most kSplitBufferWords.
  constexpr std::size_t L = batch::kBatchLanes, kSplitBufferWords = std::size_t{1} << 22;  // 32 MiB
  const std::size_t per_lane = kSplitBufferWords / (L * (q_.size() + 2));
  if (per_lane < 2) return 0;
  const std::size_t steps = (per_lane - 1) * static_cast<std::size_t>(layout_.decimation), h = split_memory();
  return steps > h ? h + L * (steps - h) : 0;
}

bool CorrelatorBankFixed::feed_split(std::span<const std::int64_t> y, const OutputSink& out) {
  const std::size_t lo = split_min_samples(), hi = split_max_samples();
  if (y.size() < lo || hi < 2 * lo || !batch::batch_kernels_available()) return false;
  while (y.size() > hi) {  // pieces of lo .. hi samples
    const std::size_t m = y.size() - hi >= lo ? hi : y.size() - lo;
    split_piece(y.first(m), out);
    y = y.subspan(m);
  }
  split_piece(y, out);
  return true;
}

void CorrelatorBankFixed::split_piece(std::span<const std::int64_t> y, const OutputSink& out) {
  constexpr std::size_t L = batch::kBatchLanes, kStep = 2048;  // lockstep samples at a time
  const std::size_t H = split_memory(), a = std::lcm<std::size_t>(layout_.period, layout_.decimation);
  const std::size_t S = (y.size() - H) / (L * a) * a;  // segment: a whole number of lcm(P, D)
  const std::size_t T = H + S;                          // lockstep steps
  const std::size_t codes = q_.size();
  const std::int64_t n0 = n_;
  const std::vector<std::uint64_t> before = q_;  // the output before the block's first
  const std::uint64_t* prev = before.data();

  FixedBankLanes k(*this);
  // Lane 0: this bank's state (the lanes share the positions and the phases).
  batch::BankBatch& b = k.b;
  b.phase = phase_;
  b.dec_phase = dec_phase_;
  b.y_idx = y_idx_;
  b.bd_idx = bd_idx_;
  b.f_idx = f_idx_;
  b.acc_re.v[0] = acc_re_;
  b.acc_im.v[0] = acc_im_;
  b.energy.v[0] = static_cast<std::int64_t>(energy_);
  const auto lane0 = [](std::vector<batch::Lanes>& dst, const auto& src) {
    for (std::size_t i = 0; i < src.size(); ++i) dst[i].v[0] = static_cast<std::int64_t>(src[i]);
  };
  lane0(k.arrays.b_re, b_re_);
  lane0(k.arrays.b_im, b_im_);
  lane0(k.arrays.y2h, y2_);
  lane0(k.arrays.bd_re, bd_re_);
  lane0(k.arrays.bd_im, bd_im_);
  lane0(k.arrays.f_re, f_re_);
  lane0(k.arrays.f_im, f_im_);

  // Every lane's outputs: at most T / D + 1 each. They come every D steps, the first at step
  // f0 (the shared decimation phase) for lane 0 and H + f0 for the others (H is a multiple of D).
  const std::size_t D = static_cast<std::size_t>(layout_.decimation);
  const std::size_t f0 = (D - 1 - static_cast<std::size_t>(dec_phase_)) % D;
  const std::size_t cap = T / D + 1;
  split_q_.resize(L * cap * codes);
  split_norm_.resize(L * cap);
  std::size_t count[L] = {};
  std::vector<batch::Lanes> in(kStep);
  for (std::size_t t0 = 0; t0 < T;) {
    const std::size_t m = std::min(kStep, (t0 < H ? H : T) - t0);
    const std::int64_t* src[L];
    for (std::size_t l = 0; l < L; ++l) src[l] = y.data() + l * S + t0;
    std::int64_t lo = 0, hi = 0;
    batch::interleave_batch(src, in.data(), m, &lo, &hi);
    const std::size_t keep = t0 < H ? 1 : L;  // lanes >= 1 keep no output of their warm-up
    for (std::size_t i = 0; i < m;) {
      bool ready = false;
      i += batch::bank_feed_batch(b, in.data() + i, m - i, &ready);
      if (!ready) continue;
      for (std::size_t l = 0; l < keep; ++l) {
        const std::size_t o = l * cap + count[l]++;
        std::uint64_t* q = split_q_.data() + o * codes;
        for (std::size_t j = 0; j < codes; ++j) q[j] = static_cast<std::uint64_t>(b.q[j].v[l]);
        split_norm_[o] = static_cast<std::uint64_t>(b.energy.v[l]) >> layout_.energy_shift;
      }
    }
    t0 += m;
    if (t0 == H) {  // the warm-up is over: lanes >= 1 count from here
      for (std::size_t l = 1; l < L; ++l) k.mix_events[l] = k.chip_events[l] = k.corr_events[l] = {};
    }
  }
  for (std::size_t l = 0; l < L; ++l) {
    mix_events_ += k.mix_events[l];
    chip_events_ += k.chip_events[l];
    corr_events_ += k.corr_events[l];
    const std::size_t start = l * S + (l ? H : 0) + f0;  // block offset of lane l's first output
    for (std::size_t i = 0; i < count[l]; ++i) {
      const std::size_t o = l * cap + i;
      const std::uint64_t* q = split_q_.data() + o * codes;
      out(std::span<const std::uint64_t>(q, codes), std::span<const std::uint64_t>(prev, codes),
          n0 + static_cast<std::int64_t>(start + i * D), split_norm_[o]);
      prev = q;
    }
  }

  // The state after the last segment (sample L S + H - 1): re-run its H samples from reset,
  // in phase (L S is a whole number of lcm(P, D)), their overflows not counted again.
  const std::size_t done = L * S + H;
  const OverflowCounter mix = mix_events_, chip = chip_events_, corr = corr_events_;
  const int phase = phase_, dec_phase = dec_phase_;
  clear_state();
  phase_ = phase;
  dec_phase_ = dec_phase;
  n_ = n0 + static_cast<std::int64_t>(done - H);
  for (std::span<const std::int64_t> rest = y.subspan(done - H, H); !rest.empty();) rest = rest.subspan(feed(rest));
  mix_events_ = mix;
  chip_events_ = chip;
  corr_events_ = corr;
  // The rest of the block, plainly (q_ now the last lane output's: the re-run ends there).
  std::vector<std::uint64_t> last = q_;
  for (std::span<const std::int64_t> rest = y.subspan(done); !rest.empty();) {
    rest = rest.subspan(feed(rest));
    if (ready_) {
      out(q_, last, sample_index(), norm());
      last = q_;
    }
  }
  ++split_blocks_;
}

}  // namespace ranging
