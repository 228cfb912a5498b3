#include "model/dsp/receiver.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <fstream>
#include <functional>
#include <map>
#include <set>
#include <sstream>

#include "model/base/error.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/stability.hpp"

namespace ranging {

// ---------------------------------------------------------------------------------------
// Configuration

int ReceiverConfig::period() const { return static_cast<int>(std::lround(fs / carrier_hz)); }
int ReceiverConfig::chip_samples() const { return cycles_per_chip * period(); }
int ReceiverConfig::sample_cycles() const { return static_cast<int>(std::lround(clock_hz / fs)); }

void fit_decimation_to_chip(ReceiverConfig& cfg) {
  if (cfg.fs <= 0 || cfg.carrier_hz <= 0 || cfg.decimation < 1) return;
  const int spc = cfg.chip_samples();
  if (spc < 1 || spc % cfg.decimation == 0) return;
  for (int d = std::min(cfg.decimation, spc); d >= 1; --d) {
    if (spc % d == 0) {
      cfg.decimation = d;
      return;
    }
  }
}

namespace {

void validate_system(const ReceiverConfig& cfg) {
  const SystemConfig& s = cfg.system;
  require_in_range("system.speed_of_sound", s.speed_of_sound, 100.0, 10000.0);
  require_in_range("system.max_range_m", s.max_range_m, 0.01, 100.0);
  require_in_range("system.baud", s.baud, 1200.0, 12e6);
  require_in_range("system.calibration_distance_m", s.calibration_distance_m, 0.01, 10.0);
  // ARR_W = time_w + frac_bits + 1 <= 63: the arrival fits int64 in the model and the HLS.
  require_in_range("system.time_w", s.time_w, 32, 46);
  require_in_range("system.off_w", s.off_w, 16, 48);
  // rtl/tof_distance.v: frac_bits + c_frac < 32 (the ToF and C registers are 32 bits).
  require_in_range("system.c_frac", s.c_frac, 1, 31 - cfg.detector.frac_bits);
  // clock_hz / baud (the UART divider) is checked where the system is designed (generate,
  // bitstream): a receiver-only study (simulate, sweep) may use any clock.
  const double c_reg = std::round(s.speed_of_sound / cfg.fs * 1e6 * std::ldexp(1.0, s.c_frac));
  if (!(c_reg >= 1 && c_reg < 4294967296.0)) {
    std::ostringstream os;
    os.precision(12);
    os << "system.c_frac: the speed register c / fs * 1e6 * 2^c_frac = " << c_reg
       << " does not fit 32 bits (valid: >= 1 and < 2^32); lower system.c_frac";
    throw InputError(os.str());
  }
}

}  // namespace

void validate(const ReceiverConfig& cfg) {
  require_in_range("signal.carrier_hz", cfg.carrier_hz, 1e3, 1e8);
  require_in_range("signal.fs", cfg.fs, 1e3, 1e9);
  require_in_range("signal.cycles_per_chip", cfg.cycles_per_chip, 1, 64);
  const double ratio = cfg.fs / cfg.carrier_hz;
  if (std::abs(ratio - std::round(ratio)) > 1e-9 * ratio || ratio < 4) {
    std::ostringstream os;
    os << "signal.fs / signal.carrier_hz = " << ratio
       << " must be an integer >= 4 (the LO table holds one carrier cycle)";
    throw InputError(os.str());
  }
  if (cfg.reference != "received" && cfg.reference != "ideal") {
    throw InputError("correlator.reference: '" + cfg.reference + "' is not valid; valid: received, ideal");
  }
  require_in_range("correlator.template_floor", cfg.template_floor, 1e-6, 0.5);
  require_in_range("correlator.decimation", cfg.decimation, 1, cfg.chip_samples());
  if (cfg.chip_samples() % cfg.decimation != 0) {
    throw InputError("correlator.decimation: " + std::to_string(cfg.decimation) +
                     " must divide the samples per chip (" + std::to_string(cfg.chip_samples()) + ")");
  }
  validate(cfg.reference_transducer, cfg.fs);
  validate(cfg.detector);
  require_in_range("hardware.clock_hz", cfg.clock_hz, 1e6, kMaxClockHz);
  const double cycles = cfg.clock_hz / cfg.fs;
  if (std::abs(cycles - std::round(cycles)) > 1e-9 * cycles || cycles < 1) {
    std::ostringstream os;
    os.precision(12);
    os << "hardware.clock_hz: " << cfg.clock_hz << " must be an integer multiple (>= 1) of signal.fs ("
       << cfg.fs << "): the RTL takes one sample every clock_hz / fs clocks";
    throw InputError(os.str());
  }
  validate_system(cfg);
  if (cfg.architecture != "baseband") {
    throw InputError("architecture: '" + cfg.architecture +
                     "' is not implemented by the fixed-point model; valid: baseband");
  }
  require_in_range("filter.order", cfg.filter_order, 0, 20);
  if (cfg.filter_structure == "direct") {
    throw InputError("filter.structure: 'direct' is a study structure (ranging stability, docs/results/stability.md: "
                     "it needs ~39-bit coefficients for this spec); the receiver and the hardware implement 'sos'");
  }
  if (cfg.filter_structure != "sos") {
    throw InputError("filter.structure: '" + cfg.filter_structure + "' is not valid; valid: sos, direct");
  }
  validate(cfg.filter);
  if (cfg.filter.fs != cfg.fs) {
    throw InputError("filter.fs must equal signal.fs");
  }
}


namespace {

// The waveform the bank is matched to for one chip 1 (chip 0 is its negative): the bare
// excitation, or its response through the TX and RX transducers and the bandpass filter,
// trimmed where it has decayed below template_floor of its peak.
std::vector<double> chip_waveform(const ReceiverConfig& cfg, const SosFilter& filter) {
  const ExcitationParams ex = receiver_excitation(cfg);
  const std::vector<std::uint8_t> one{1};
  std::vector<double> w = bpsk_excitation(one, ex);
  if (cfg.reference == "ideal") return w;
  w.resize(static_cast<std::size_t>(cfg.chip_samples()) * 20, 0.0);
  Transducer tx(cfg.reference_transducer, cfg.fs), rx(cfg.reference_transducer, cfg.fs);
  BandpassFloat bp(filter);
  double peak = 0;
  for (double& v : w) {
    v = bp.execute(rx.execute(tx.execute(v)));
    peak = std::max(peak, std::abs(v));
  }
  std::size_t last = 0;
  for (std::size_t n = 0; n < w.size(); ++n) {
    if (std::abs(w[n]) >= cfg.template_floor * peak) last = n;
  }
  w.resize(last + 1);
  return w;
}

}  // namespace

ReceiverDesign design_receiver(const ReceiverConfig& cfg_in) {
  ReceiverConfig cfg = cfg_in;
  cfg.filter.fs = cfg.fs;
  cfg.correlator.data_bits = cfg.bandpass.data_bits;
  cfg.correlator.data_frac = cfg.bandpass.data_frac;
  validate(cfg);
  ReceiverDesign d;
  d.config = cfg;
  d.family = code_family(cfg.family);
  d.filter = cfg.filter_order > 0 ? design_bandpass(cfg.filter, cfg.filter_type, cfg.filter_order)
                                  : design_bandpass(cfg.filter, cfg.filter_type);
  // The fixed filter's word lengths against the coefficients (InputError naming the field).
  validate(cfg.bandpass, d.filter);
  // The guard on what the integer coefficients implement (unstable / out of spec: refused).
  enforce_quantized_design(check_quantized_design(d), cfg);

  CorrelatorReference& ref = d.reference;
  ref.period = cfg.period();
  ref.chip_samples = cfg.chip_samples();
  ref.decimation = cfg.decimation;
  ref.codes = d.family.codes;
  const std::vector<double> chip = chip_waveform(cfg, d.filter);

  // Chip template in the bank's own domain: mixed to baseband, boxcar-decimated by D, rotated
  // to its dominant phase and made real (2 multiplies per tap instead of 4), time reversed.
  const int D = cfg.decimation;
  // Pad so the template's tail passes the whole one-cycle moving sum.
  std::vector<double> padded(chip);
  padded.resize(chip.size() + static_cast<std::size_t>(ref.period + D), 0.0);
  const std::vector<std::complex<double>> h = baseband_decimate(padded, ref.period, D);
  ref.chip_peak = ref.corr_peak = 0;
  std::complex<double> dominant = 0;
  double hmax = 0;
  for (const auto& v : h) {
    dominant += v * std::abs(v);
    hmax = std::max(hmax, std::abs(v));
  }
  std::size_t m = 0;
  for (std::size_t k = 0; k < h.size(); ++k) {
    if (std::abs(h[k]) >= cfg.template_floor * hmax) m = k + 1;
  }
  const std::complex<double> rot = std::polar(1.0, -std::arg(dominant));
  for (std::size_t i = 0; i < m; ++i) ref.chip_taps.push_back((h[m - 1 - i] * rot).real() / hmax);
  ref.window = (d.family.length - 1) * ref.chip_samples + static_cast<int>(m) * D;

  // Every code's full-rate template and its normalization K_j = P_j / E at its own peak,
  // measured by a one-code float bank (cost linear in the family size). chip_peak and
  // corr_peak (the fixed-point scaling) are the largest |F| and own |C_j| per unit input peak.
  ref.code_gain.assign(d.family.codes.size(), 1.0);
  for (std::size_t j = 0; j < d.family.codes.size(); ++j) {
    // Room for every chip's whole waveform (a slow transducer rings past the trimmed window).
    const std::size_t last_chip = (d.family.codes[j].size() - 1) * static_cast<std::size_t>(ref.chip_samples);
    std::vector<double> t(std::max(static_cast<std::size_t>(ref.window + 2 * ref.chip_samples), last_chip + chip.size()),
                          0.0);
    for (std::size_t c = 0; c < d.family.codes[j].size(); ++c) {
      const double s = d.family.codes[j][c] ? 1.0 : -1.0;
      for (std::size_t n = 0; n < chip.size(); ++n) t[c * ref.chip_samples + n] += s * chip[n];
    }
    CorrelatorReference one = ref;
    one.codes = {d.family.codes[j]};
    one.code_gain = {1.0};
    CorrelatorBankFloat probe(one);
    double best_p = -1, gain = 1, tpeak = 0;
    for (double v : t) tpeak = std::max(tpeak, std::abs(v));
    for (double v : t) {
      if (!probe.execute(v)) continue;
      ref.chip_peak = std::max(ref.chip_peak, probe.chip_magnitude() / tpeak);
      ref.corr_peak = std::max(ref.corr_peak, probe.max_corr_magnitude() / tpeak);
      if (probe.weighted_power()[0] > best_p && probe.energy() > 0) {
        best_p = probe.weighted_power()[0];
        gain = best_p / probe.energy();
      }
    }
    ref.code_gain[j] = gain;
    d.templates.push_back(std::move(t));
  }
  d.layout = resolve_correlator_layout(ref, cfg.correlator);
  return d;
}

// ---------------------------------------------------------------------------------------
// Receivers

ExcitationParams receiver_excitation(const ReceiverConfig& config, double amplitude) {
  return ExcitationParams{config.carrier_hz, config.cycles_per_chip, config.fs, amplitude};
}

ReceiverFloat::ReceiverFloat(const ReceiverDesign& d)
    : filter_(d.filter),
      bank_(d.reference),
      detector_(d.config.detector, d.reference) {}

void ReceiverFloat::reset() {
  filter_.reset();
  bank_.reset();
  detector_.reset();
  filtered_ = 0;
}

std::optional<Event> ReceiverFloat::execute(double x) {
  filtered_ = filter_.execute(x);
  if (!bank_.execute(filtered_)) return std::nullopt;
  return detector_.execute(bank_);
}

std::size_t ReceiverFloat::execute_block(std::span<const double> x, std::vector<Event>& events,
                                        std::span<double> filtered) {
  if (!filtered.empty() && filtered.size() != x.size()) {
    throw InputError("ReceiverFloat::execute_block: filtered output size differs from the input's");
  }
  // Short chunks stay in the cache; a long block is filtered in long chunks, which the
  // bandpass runs on its SIMD lanes (BandpassSplitStats), into `filtered` when given.
  constexpr std::size_t kChunk = 4096;
  const bool split = x.size() >= kBandpassFloatSplitMin;
  const std::size_t chunk = split ? std::min(x.size(), 2 * kBandpassSplitMin) : kChunk;
  double y_small[kChunk];
  if (split && filtered.empty()) long_chunk_.resize(chunk);
  const std::size_t before = events.size();
  // the bank's outputs in order, straight to the detector (the accessors it reads, handed over)
  const CorrelatorBankFloat::OutputSink detect = [&](std::span<const double> q, std::span<const double> prev,
                                                     std::int64_t n, double energy) {
    if (auto e = detector_.execute(q, prev, n, energy)) events.push_back(*e);
  };
  for (std::size_t n0 = 0; n0 < x.size(); n0 += chunk) {
    const std::size_t len = std::min(chunk, x.size() - n0);
    double* y = !filtered.empty() ? filtered.data() + n0 : split ? long_chunk_.data() : y_small;
    filter_.execute_block(x.subspan(n0, len), std::span<double>(y, len));
    bank_.feed_outputs(std::span<const double>(y, len), detect);
    filtered_ = y[len - 1];
  }
  detector_.set_previous(bank_.weighted_power());  // the last output's (zeros before any)
  return events.size() - before;
}

ReceiverFixed::ReceiverFixed(const ReceiverDesign& d)
    : input_bits_(d.config.bandpass.input_bits),
      frac_bits_(d.config.detector.frac_bits),
      score_bits_(d.config.correlator.score_bits),
      filter_(d.filter, d.config.bandpass),
      bank_(d.reference, d.config.correlator),
      detector_(d.config.detector, bank_.layout(), d.config.correlator) {}

void ReceiverFixed::reset() {
  filter_.reset();
  bank_.reset();
  detector_.reset();
  filtered_ = 0;
  input_counter_ = {};
}

std::optional<EventFixed> ReceiverFixed::execute_raw(std::int64_t x) {
  filtered_ = filter_.execute_raw(x);
  if (!bank_.execute(filtered_)) return std::nullopt;
  return detector_.execute(bank_);
}

std::size_t ReceiverFixed::execute_block(std::span<const std::int64_t> x, std::vector<EventFixed>& events) {
  // Short chunks stay in the cache; a long block is filtered in long chunks, which the
  // bandpass and the bank run on their SIMD lanes (BandpassSplitStats,
  // CorrelatorBankFixed::feed_split).
  const std::size_t chunk = x.size() >= std::min(kBandpassSplitMin, bank_.split_min_samples())
                                ? std::min(x.size(), 2 * kBandpassSplitMin)
                                : 1024;
  const std::size_t before = events.size();
  if (chunk_.size() < chunk) chunk_.resize(chunk);
  while (!x.empty()) {
    const std::size_t n = std::min(chunk, x.size());
    const std::span<std::int64_t> y(chunk_.data(), n);
    filter_.execute_block(x.first(n), y);
    std::span<const std::int64_t> rest(y);
    const auto detect = [&](std::span<const std::uint64_t> q, std::span<const std::uint64_t> prev, std::int64_t i,
                            std::uint64_t norm) {
      if (auto e = detector_.execute(q, prev, i, norm)) events.push_back(*e);
    };
    if (bank_.feed_split(y, detect)) {  // the bank's time split (long chunks only)
      rest = {};
      detector_.set_previous(bank_.weighted_power());  // the last output's
    }
    while (!rest.empty()) {
      rest = rest.subspan(bank_.feed(rest));
      if (bank_.output_ready()) {
        if (auto e = detector_.execute(bank_)) events.push_back(*e);
      }
    }
    filtered_ = y[n - 1];
    x = x.subspan(n);
  }
  return events.size() - before;
}

Event ReceiverFixed::to_float(const EventFixed& e) const { return e.to_float(frac_bits_, score_bits_); }

std::optional<Event> ReceiverFixed::execute(double x) {
  auto e = execute_raw(quantize_input(x, input_bits_, &input_counter_));
  if (!e) return std::nullopt;
  return to_float(*e);
}

std::optional<Event> ReceiverFixed::flush() {
  auto e = flush_raw();
  if (!e) return std::nullopt;
  return to_float(*e);
}

OverflowCounter ReceiverFixed::overflow_events() const {
  return input_counter_ + filter_.overflow_events() + bank_.overflow_events();
}

}  // namespace ranging
