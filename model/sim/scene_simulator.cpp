#include "model/sim/scene_simulator.hpp"

#include <algorithm>
#include <chrono>
#include <atomic>
#include <exception>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <set>
#include <numbers>
#include <sstream>
#include <thread>

#include "model/sim/capture.hpp"
#include "model/sim/capture_stream.hpp"
#include "model/sim/channel.hpp"
#include "model/sim/fft.hpp"
#include "model/sim/front_end.hpp"
#include "model/base/error.hpp"
#include "model/base/parallel.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/latency.hpp"
#include "model/dsp/receiver_batch.hpp"
#include "model/sim/metrics.hpp"

namespace ranging {

double piston_directivity(double beam_angle_deg, double angle_deg) {
  // 2 J1(x)/x = 1/sqrt(2) at x = 1.616340 (the -3 dB point of a piston).
  constexpr double x3db = 1.6163399561827614;
  const double ka = x3db / std::sin(beam_angle_deg / 2.0 * std::numbers::pi / 180.0);
  const double x = ka * std::sin(angle_deg * std::numbers::pi / 180.0);
  if (std::abs(x) < 1e-9) return 1.0;
  return std::abs(2.0 * std::cyl_bessel_j(1.0, x) / x);
}

namespace {

std::string fmt(double v, int prec = 4) {
  std::ostringstream os;
  os.precision(prec);
  os << v;
  return os.str();
}

// Near-field length N = a^2 / lambda of a piston with the scene's beam angle.
double near_field_m(const Scene& s) {
  constexpr double x3db = 1.6163399561827614;
  const double lambda = s.speed() / s.transducers.centre_hz;
  const double a = x3db / std::sin(s.transducers.beam_angle_deg / 2.0 * std::numbers::pi / 180.0) *
                   lambda / (2.0 * std::numbers::pi);
  return a * a / lambda;
}

// A lap timer on the steady clock: lap() returns the seconds since the last lap (or creation).
class StageClock {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double s = std::chrono::duration<double>(now - t_).count();
    t_ = now;
    return s;
  }

 private:
  std::chrono::steady_clock::time_point t_ = std::chrono::steady_clock::now();
};

std::uint64_t splitmix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// FNV-1a, 64 bit, over the bytes of a value: a stable hash for the noise seeds.
struct StableHash {
  std::uint64_t h = 0xcbf29ce484222325ull;
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 0x100000001b3ull;
  }
  void u64(std::uint64_t v) {
    for (int i = 0; i < 8; ++i) {
      const unsigned char b = static_cast<unsigned char>(v >> (8 * i));  // little-endian on every host
      bytes(&b, 1);
    }
  }
  void f64(double v) {
    std::uint64_t u = 0;
    std::memcpy(&u, &v, sizeof u);
    u64(v == 0.0 ? 0 : u);  // -0 and +0 alike
  }
  void str(const std::string& s) {
    u64(s.size());
    bytes(s.data(), s.size());
  }
};

struct Sparse {
  long start = 0;              // sample index of y[0] (may be negative: clipped when added)
  std::vector<double> y;
};

struct Burst {
  int code = 0;        // 1-based
  double tx_s = 0;     // transmission time
};

// What a decoded stream is matched against: with period_s > 0 the codes in order every period_s
// up to `span` (seconds), else every code once at t = 0.
std::vector<Burst> decode_schedule(int eta, double span, double period_s) {
  std::vector<Burst> schedule;
  if (period_s > 0) {
    for (long k = 0; k * period_s <= span; ++k) schedule.push_back({static_cast<int>(k % eta) + 1, k * period_s});
  } else {
    for (int j = 1; j <= eta; ++j) schedule.push_back({j, 0.0});
  }
  return schedule;
}

}  // namespace

std::vector<SceneStage> scene_stages(const Scene& s) {
  std::vector<SceneStage> st;
  if (s.transducers.named) {
    st.push_back({"transducers", "TX and RX resonators, centre " + fmt(s.transducers.centre_hz / 1e3) +
                                     " kHz, Q " + fmt(s.transducers.q) + ", beam " +
                                     fmt(s.transducers.beam_angle_deg) + " deg, near field " +
                                     fmt(near_field_m(s) * 1e3) + " mm"});
  }
  if (s.geometry.angle_deg) {
    st.push_back({"directivity", "piston, beam " + fmt(s.transducers.beam_angle_deg) + " deg at " +
                                     fmt(*s.geometry.angle_deg) + " deg off axis: gain " +
                                     fmt(std::pow(piston_directivity(s.transducers.beam_angle_deg,
                                                                     *s.geometry.angle_deg), 2))});
  }
  if (s.medium.air) {
    const auto& a = *s.medium.air;
    st.push_back({"absorption", "ISO 9613-1 at " + fmt(a.temperature_c) + " C, " + fmt(a.relative_humidity) +
                                    " % RH, " + fmt(a.pressure_kpa) + " kPa: " +
                                    fmt(absorption_db_per_m(s.excitation.carrier_hz, a)) + " dB/m at the carrier"});
  }
  if (s.geometry.type == "rotor") {  // model/sim/moving_channel.hpp replaces delay and gain
    st.push_back({"moving", "emission time per sample (c = " + fmt(s.speed(), 6) +
                                " m/s), Doppler, spreading 0.1 m/d, piston directivity of both moving transducers, "
                                "sensitivity " + fmt(s.sensitivity) + " V/V, drive " + fmt(s.excitation.amplitude()) +
                                " V peak"});
  } else {
    st.push_back({"delay", "d/c with c = " + fmt(s.speed(), 6) + " m/s, 64-tap fractional delay"});
    st.push_back({"gain", "spherical spreading 0.1 m/d, sensitivity " + fmt(s.sensitivity) + " V/V, drive " +
                              fmt(s.excitation.amplitude()) + " V peak"});
  }
  if (s.noise.named && (s.noise.snr_db || s.noise.noise_v)) {
    st.push_back({"noise", (s.noise.snr_db ? "white Gaussian at SNR " + fmt(*s.noise.snr_db) + " dB"
                                           : "white Gaussian " + fmt(*s.noise.noise_v) + " V rms") +
                               ", seed " + std::to_string(s.noise.seed)});
  }
  if (s.noise.adc) {
    st.push_back({"adc", std::to_string(s.noise.adc->bits) + " bits over +-" + fmt(s.noise.adc->full_scale_v) +
                             " V, clipping, " + fmt(s.fs / 1e6) + " MS/s"});
  }
  return st;
}

// ---------------------------------------------------------------------------------------

namespace {

// The stages of a clean burst (SceneSimulator::Link::clean), in the order they apply.

// The TX and RX resonators, with 30 amplitude time constants Q/(pi f0) of ring-down appended.
void through_transducers(const Scene& s, std::vector<double>& z) {
  const double tau = s.transducers.q / (std::numbers::pi * s.transducers.centre_hz) * s.fs;
  z.resize(z.size() + static_cast<std::size_t>(std::ceil(30.0 * tau)) + 16, 0.0);
  const TransducerParams tp{s.transducers.centre_hz, s.transducers.q, false};
  Transducer tx(tp, s.fs), rx(tp, s.fs);
  for (double& v : z) v = rx.execute(tx.execute(v));
}

// Spherical spreading 0.1 m / d, the sensitivity and (off axis) both pistons' directivity.
double path_gain(const Scene& s, double d) {
  double g = s.sensitivity * kReferenceDistance / d;
  if (s.geometry.angle_deg) g *= std::pow(piston_directivity(s.transducers.beam_angle_deg, *s.geometry.angle_deg), 2);
  return g;
}

// The stages after the transducers as one FIR, per distance: the zero-phase absorption FIR
// (when the medium is named) convolved with propagate()'s fractional-delay interpolator for
// the whole delay d/c, scaled by the path gain; kernel[0] applies at sample `start` of a burst
// whose z[0] is sample 0.
struct PathKernel {
  long start = 0;
  std::vector<double> kernel;
};
PathKernel path_kernel(const Scene& s, double d, double c) {
  std::vector<double> h{1.0};
  long half = 0;
  if (s.medium.air) {
    h = absorption_fir(*s.medium.air, d, s.fs);
    half = static_cast<long>(h.size() / 2);  // h is centred: its tap `half` is time 0
  }
  const double shift = d / c * s.fs - static_cast<double>(half);
  const double whole = std::floor(shift);
  const auto taps = fractional_delay_taps(shift - whole);
  constexpr long m_lo = -(kDelayTaps / 2 - 1);
  PathKernel k;
  k.start = static_cast<long>(whole) + m_lo;
  k.kernel = convolve(h, taps);
  const double g = path_gain(s, d);
  for (double& v : k.kernel) v *= g;
  return k;
}

}  // namespace

struct SceneSimulator::Link {
  const Scene* scene = nullptr;
  const FixedStreamObserver* observer = nullptr;
  std::string family_name;
  ReceiverDesign design;
  int L = 0, spc = 0;
  std::size_t template_len = 0;
  std::vector<double> offset;                   // receiver latency per code, samples
  std::vector<std::vector<double>> templates;   // Pearson references per code
  std::unique_ptr<PearsonBank> bank;            // their matched filter over lags
  std::map<std::pair<int, long long>, Sparse> cache;  // (code, distance in nm) -> clean burst
  std::map<long long, PathKernel> kernel_cache;  // distance in nm -> the path's FIR
  std::uint64_t overflows = 0;

  double c() const { return scene->speed(); }
  double fs() const { return scene->fs; }
  bool fixed() const { return scene->receiver.precision == "fixed"; }
  double input_scale() const {
    return scene->noise.adc ? scene->noise.adc->full_scale_v : scene->receiver.full_scale_v;
  }

  // Noise-free received burst of code j sent at t = 0 over distance d (volts): the scene's
  // deterministic stages in order (scene_stages()).
  const Sparse& clean(int code, double d) {
    const auto key = std::make_pair(code, std::llround(d * 1e9));
    if (auto it = cache.find(key); it != cache.end()) return it->second;
    const Scene& s = *scene;
    ExcitationParams ex{s.excitation.carrier_hz, design.config.cycles_per_chip, s.fs, s.excitation.amplitude()};
    std::vector<double> z = bpsk_excitation(design.family.codes[static_cast<std::size_t>(code - 1)], ex);
    if (s.transducers.named) through_transducers(s, z);
    auto it = kernel_cache.find(key.second);
    if (it == kernel_cache.end()) it = kernel_cache.emplace(key.second, path_kernel(s, d, c())).first;
    Sparse out;
    out.start = it->second.start;
    out.y = convolve(z, it->second.kernel);  // FFTW when both are longer than 64 samples
    return cache.emplace(key, std::move(out)).first->second;
  }

  static void add_into(std::vector<double>& x, const Sparse& b, long shift) {
    for (std::size_t n = 0; n < b.y.size(); ++n) {
      const long k = b.start + shift + static_cast<long>(n);
      if (k >= 0 && k < static_cast<long>(x.size())) x[static_cast<std::size_t>(k)] += b.y[n];
    }
  }

  // Runs the receiver of the scene's precision over x (volts); returns its events and the
  // float bandpass output in volts. The fixed receiver's saturations/wraps (input included) are
  // added to *ovf (default: this link's counter). The fixed receiver runs through its block API
  // (ReceiverFixed::execute_block, bit-exact with execute_raw per sample: tests/test_block_api).
  // clamped (fixed precision): appends the indices of the samples the input clamp to +-scale cut.
  std::vector<Event> receive(const std::vector<double>& volts, double scale, std::vector<double>& filtered,
                             std::uint64_t* ovf = nullptr, std::vector<std::size_t>* clamped = nullptr) {
    filtered.resize(volts.size());
    if (!fixed()) return receive_float(volts, scale, filtered);
    return receive_fixed(volts, scale, filtered, *(ovf ? ovf : &overflows), clamped);
  }

  std::vector<Event> receive_float(const std::vector<double>& volts, double scale, std::vector<double>& filtered) const {
    std::vector<Event> ev;
    const double inv = 1.0 / scale;
    ReceiverFloat rf(design);
    const bool keep = scene->receiver.metrics.any();  // the filtered stream feeds the metrics only
    // ReceiverFloat::execute_block (bit for bit execute() per sample), a chunk at a time
    constexpr std::size_t kChunk = 4096;
    std::vector<double> xs(std::min(kChunk, volts.size()));
    for (std::size_t n0 = 0; n0 < volts.size(); n0 += kChunk) {
      const std::size_t len = std::min(kChunk, volts.size() - n0);
      for (std::size_t i = 0; i < len; ++i) xs[i] = volts[n0 + i] * inv;
      std::span<double> f = keep ? std::span<double>(filtered.data() + n0, len) : std::span<double>();
      rf.execute_block(std::span<const double>(xs.data(), len), ev, f);
      for (double& v : f) v *= scale;
    }
    if (auto e = rf.flush()) ev.push_back(*e);
    return ev;
  }

  // The fixed receiver's saturations and wraps, the ADC's input saturations among them, are added to ovf.
  std::vector<Event> receive_fixed(const std::vector<double>& volts, double scale, std::vector<double>& filtered,
                                   std::uint64_t& ovf, std::vector<std::size_t>* clamped) const {
    std::vector<Event> ev;
    const double inv = 1.0 / scale;
    ReceiverFixed rx(design);
    BandpassFloat bp(design.filter);
    const bool observed = observer && *observer;
    OverflowCounter adc;
    // The same quantization as ReceiverFixed::execute(double), a chunk at a time (the whole
    // stream's codes are kept only for the observer).
    constexpr std::size_t kChunk = 4096;
    std::vector<std::int64_t> raw(observed ? volts.size() : std::min(kChunk, volts.size()));
    std::vector<EventFixed> raw_events;
    for (std::size_t n0 = 0; n0 < volts.size(); n0 += kChunk) {
      const std::size_t n1 = std::min(volts.size(), n0 + kChunk);
      std::int64_t* q = raw.data() + (observed ? n0 : 0);
      quantize_input_block(std::span<const double>(volts).subspan(n0, n1 - n0), inv, design.config.bandpass.input_bits,
                           q, adc, clamped, n0);
      rx.execute_block(std::span<const std::int64_t>(q, n1 - n0), raw_events);
      if (scene->receiver.metrics.any()) {  // the float filter runs for the metrics only
        bp.execute_block(std::span<const double>(volts.data() + n0, n1 - n0),
                         std::span<double>(filtered.data() + n0, n1 - n0));
      }
    }
    for (const auto& e : raw_events) ev.push_back(rx.to_float(e));
    if (auto e = rx.flush()) ev.push_back(*e);
    if (observed) (*observer)(design, raw, raw_events);
    ovf += rx.overflow_events().total() + adc.total();
    return ev;
  }

  // One stream of receive_batch: its input, and what receive() gives for it.
  struct BatchStream {
    const std::vector<double>* volts = nullptr;
    std::vector<std::size_t>* clamped = nullptr;  // receive()'s clamped
    std::vector<Event> events;
    std::vector<double> filtered;  // empty when the scene names no metric
    std::uint64_t overflows = 0;  // added to receive()'s *ovf
  };
  // Both batch receivers of a worker (the one of the scene's precision is used).
  struct Batches {
    explicit Batches(const ReceiverDesign& d) : fixed(d), flt(d) {}
    ReceiverFixedBatch fixed;
    ReceiverFloatBatch flt;
  };
  // receive() on several streams (not observed): the streams run together through
  // ReceiverFixedBatch or ReceiverFloatBatch (one per SIMD lane, bit for bit ReceiverFixed /
  // ReceiverFloat per stream: tests/test_receiver_batch.cpp), so every result is receive()'s.
  void receive_batch(std::vector<BatchStream>& streams, double scale, Batches& b) const {
    const double inv = 1.0 / scale;
    if (!fixed()) {  // receive_float's: x = volts / scale, the filtered stream back in volts
      std::vector<std::span<const double>> spans;
      for (const auto& st : streams) spans.emplace_back(*st.volts);
      std::vector<std::vector<Event>> ev;
      std::vector<std::vector<double>> f;
      const bool keep = scene->receiver.metrics.any();  // the filtered stream feeds the metrics only
      b.flt.run(spans, inv, ev, keep ? &f : nullptr);
      for (std::size_t i = 0; i < streams.size(); ++i) {
        streams[i].events = std::move(ev[i]);
        if (keep) {
          streams[i].filtered = std::move(f[i]);
          for (double& v : streams[i].filtered) v *= scale;
        }  // else empty: no metric reads it
        streams[i].overflows = 0;
      }
      return;
    }
    ReceiverFixedBatch& batch = b.fixed;
    std::vector<std::vector<std::int64_t>> codes(streams.size());
    std::vector<std::span<const std::int64_t>> spans;
    std::vector<OverflowCounter> adc(streams.size());
    for (std::size_t i = 0; i < streams.size(); ++i) {
      const auto& v = *streams[i].volts;
      codes[i].resize(v.size());
      quantize_input_block(v, inv, design.config.bandpass.input_bits, codes[i].data(), adc[i],
                           streams[i].clamped);
      spans.emplace_back(codes[i]);
    }
    std::vector<std::vector<EventFixed>> raw;
    std::vector<OverflowCounter> ovf;
    batch.run(spans, raw, ovf);
    // the float filter runs for the metrics only (else empty), on the streams' SIMD lanes
    std::vector<std::vector<double>> f;
    if (scene->receiver.metrics.any()) {
      std::vector<std::span<const double>> vs;
      for (const auto& st : streams) vs.emplace_back(*st.volts);
      bandpass_float_streams(design.filter, vs, f);
    }
    for (std::size_t i = 0; i < streams.size(); ++i) {
      auto& st = streams[i];
      if (!f.empty()) st.filtered = std::move(f[i]);
      st.events.clear();
      for (const auto& e : raw[i]) st.events.push_back(batch.to_float(e));
      st.overflows = ovf[i].total() + adc[i].total();
    }
  }

  // receive() over a capture read in blocks, events only (the filtered stream is not kept).
  // The receiver of the scene's precision over a stream handed over a block at a time
  // (decode_stream): block() is receive()'s loop on the next samples, bit for bit, finish()
  // after the last (the detector's pending candidate).
  class StreamReceiver {
   public:
    StreamReceiver(const Link& lk, double scale)
        : scale_(scale), inv_(1.0 / scale), rx_bits_(lk.design.config.bandpass.input_bits) {
      if (lk.fixed()) {
        rx_.emplace(lk.design);
      } else {
        rf_.emplace(lk.design);
      }
    }
    // x: the next samples in capture units (the float receiver scales them in place); events
    // are appended to ev; filtered (float receiver only; empty, or x's size) receives the
    // bandpass output in capture units, as receive() gives it.
    void block(std::span<double> x, std::vector<Event>& ev, std::span<double> filtered) {
      if (rf_) {
        for (double& v : x) v *= inv_;
        rf_->execute_block(x, ev, filtered);
        for (double& v : filtered) v *= scale_;
        return;
      }
      raw_.resize(x.size());
      quantize_input_block(x, inv_, rx_bits_, raw_.data(), adc_, nullptr);
      raw_events_.clear();
      rx_->execute_block(std::span<const std::int64_t>(raw_.data(), x.size()), raw_events_);
      for (const auto& e : raw_events_) ev.push_back(rx_->to_float(e));
    }
    void finish(std::vector<Event>& ev) {
      if (auto e = rf_ ? rf_->flush() : rx_->flush()) ev.push_back(*e);
    }

   private:
    double scale_, inv_;
    int rx_bits_;  // the fixed receiver's input word
    std::optional<ReceiverFloat> rf_;
    std::optional<ReceiverFixed> rx_;
    OverflowCounter adc_;
    std::vector<std::int64_t> raw_;
    std::vector<EventFixed> raw_events_;
  };

  // Once the receiver has read P samples of a stream, every event it emits later has its
  // template start (prepare()) at or after P - event_lookback(): a candidate is released at the
  // first output holdoff samples after it unless a later one replaces it, so a pending one
  // sits within holdoff + D samples of P, a later one at P or after; the parabola moves the
  // arrival by D/2 at most; the start is the arrival less the code's calibrated latency.
  long event_lookback() const {
    const DetectorConfig& dc = design.config.detector;
    const long hold = dc.holdoff != -1 ? dc.holdoff : std::max(design.reference.window, design.layout.window);
    const long dec = std::max(design.reference.decimation, design.layout.decimation);
    double off = 0;
    for (double o : offset) off = std::max(off, o);
    return hold + 2 * dec + static_cast<long>(std::ceil(off)) + 4;
  }

  std::size_t stream_tail() const { return static_cast<std::size_t>((3 * L + 6) * spc) + 2000; }

  void calibrate() {
    const Scene& s = *scene;
    const double d = s.receiver.calibration_distance_m;
    const std::size_t eta = design.family.codes.size();
    const double delay = calibration_flight(d, c(), s.fs);
    std::vector<std::vector<double>> filtered(eta);
    offset = calibrate_receiver_latency<Event>(
        eta, delay,
        [&](int code) {
          const Sparse& b = clean(code, d);
          std::vector<double> x(static_cast<std::size_t>(std::max<long>(b.start, 0)) + b.y.size() + stream_tail(),
                                0.0);
          add_into(x, b, 0);
          double peak = 0;
          for (double v : x) peak = std::max(peak, std::abs(v));
          // Calibrate at half full scale so the fixed receiver sees a healthy level.
          return receive(x, peak / 0.5, filtered[static_cast<std::size_t>(code - 1)]);
        },
        [&](int code) {
          return s.origin + ": calibration: code " + std::to_string(code) + " of " + family_name +
                 " was not decoded on a noise-free burst at " + fmt(d) + " m (" + fmt(s.fs / 1e6) + " MS/s, " +
                 fmt(s.fs / s.excitation.carrier_hz) + " samples per carrier cycle); lower receiver.threshold, " +
                 "raise the sample rate (few samples per cycle blur the chips) or check the scene's stages";
        });
    templates.assign(eta, {});
    for (std::size_t j = 0; j < eta; ++j) {
      const std::size_t start = static_cast<std::size_t>(std::lround(delay));
      const std::vector<double>& f = filtered[j];
      if (s.receiver.reference == "received") {
        templates[j].assign(f.begin() + static_cast<long>(start), f.begin() + static_cast<long>(start + template_len));
      } else if (s.receiver.reference == "ideal") {
        ExcitationParams ex{s.excitation.carrier_hz, design.config.cycles_per_chip, s.fs, 1.0};
        templates[j] = bpsk_excitation(design.family.codes[j], ex);
        templates[j].resize(template_len, 0.0);
      }
    }
    // Recorded references are aligned by the receiver's calibrated arrival, so every offset first.
    if (s.receiver.reference == "files") {
      check_references_dir();
      for (std::size_t j = 0; j < eta; ++j) templates[j] = load_reference(static_cast<int>(j) + 1);
    }
    bank = std::make_unique<PearsonBank>(templates, max_lags());
  }
  // The Pearson search's lags per burst: +-L chips (metrics_window's reach), so every burst's
  // search, edge windows too, runs on one transform size (PearsonBank's max_lags).
  std::size_t max_lags() const { return static_cast<std::size_t>(2 * L * spc + 1); }

  // The references folder itself, once: a file or a missing path is named as such.
  void check_references_dir() const {
    const Scene& s = *scene;
    namespace fs = std::filesystem;
    std::error_code ec;
    if (!fs::is_directory(s.receiver.references_dir, ec)) {
      throw InputError(s.receiver.references_dir + (fs::exists(s.receiver.references_dir, ec)
                                                         ? ": not a folder; expected the references folder"
                                                         : ": no such folder; expected the references folder") +
                       " (" + family_name + "-<j>.csv or .wav inside)");
    }
  }

  std::vector<double> load_reference(int j) {
    const Scene& s = *scene;
    namespace fs = std::filesystem;
    const std::string stem = s.receiver.references_dir + "/" + family_name + "-" + std::to_string(j);
    std::string path;
    for (const char* ext : {".csv", ".wav"}) {
      if (fs::exists(stem + ext)) path = stem + ext;
    }
    if (path.empty()) {
      throw InputError(s.receiver.references_dir + ": no reference for code " + std::to_string(j) + " (expected " +
                       stem + ".csv or .wav)");
    }
    Capture c = read_capture(path);
    if (std::abs(c.sample_rate - s.fs) > 1e-4 * s.fs) {
      throw InputError(path + ": reference sampled at " + fmt(c.sample_rate, 9) + " Hz, the signal at " +
                       fmt(s.fs, 9) + " Hz");
    }
    const std::size_t burst = static_cast<std::size_t>(L * spc);
    if (c.samples.size() < burst) {
      throw InputError(path + ": too short: " + std::to_string(c.samples.size()) + " samples, a " + family_name +
                       " burst is " + std::to_string(burst));
    }
    // A recording has its own time origin: the receiver finds the burst in it, and the template
    // (filtered like the received signal: the paper's references are filtered signals) starts at
    // its calibrated arrival, as the segments it is compared with do (metrics()).
    std::vector<double> x = c.samples;
    double peak = 0;
    for (double v : x) peak = std::max(peak, std::abs(v));
    if (peak == 0.0) throw InputError(path + ": reference is all zero");
    x.resize(x.size() + stream_tail(), 0.0);
    std::vector<double> y;
    const auto ev = receive(x, peak / 0.5, y);
    const Event* best = strongest_event(ev);
    if (!best) throw InputError(path + ": the receiver detects no " + family_name + " burst in this reference");
    const long k0 = std::lround(best->arrival - offset[static_cast<std::size_t>(best->code - 1)]);
    std::vector<double> t(template_len, 0.0);
    for (std::size_t i = 0; i < template_len; ++i) {
      const long k = k0 + static_cast<long>(i);
      if (k >= 0 && k < static_cast<long>(c.samples.size())) t[i] = y[static_cast<std::size_t>(k)];
    }
    return t;
  }

  // Events -> detections: calibrated arrival, ToF against the schedule, the paper's metrics.
  std::vector<Detection> detections(const std::vector<Event>& ev, const std::vector<double>& filtered, double t0,
                                    const std::vector<Burst>& schedule) {
    return detections(ev, filtered, t0, schedule, *bank);
  }
  // pb: the matched filter to use (PearsonBank is not thread-safe: one per worker thread).
  std::vector<Detection> detections(const std::vector<Event>& ev, const std::vector<double>& filtered, double t0,
                                    const std::vector<Burst>& schedule, PearsonBank& pb) {
    return detections(ev, filtered, static_cast<long>(filtered.size()), t0, schedule, pb);
  }
  // n: the stream's length; filtered may be empty when the scene names no metric (none reads it).
  std::vector<Detection> detections(const std::vector<Event>& ev, const std::vector<double>& filtered, long n,
                                    double t0, const std::vector<Burst>& schedule, PearsonBank& pb) {
    std::vector<Detection> out;
    for (auto& p : prepare(ev, n, t0, schedule)) {
      (void)metrics_window(p.d, filtered, 0, n, p.start, p.end, pb);
      out.push_back(p.d);
    }
    return out;
  }

  // An event as a detection before its metrics: the template start and the end of its T_d search.
  struct Pending {
    Detection d;
    long start = 0, end = 0;
  };
  // n: the stream's length. T_d of a burst is searched up to the next detected burst's start (or
  // the stream's end); ToF against the latest send of the event's code at or before its arrival.
  std::vector<Pending> prepare(const std::vector<Event>& ev, long n, double t0, const std::vector<Burst>& schedule) {
    std::vector<long> sorted;
    for (const auto& e : ev) sorted.push_back(start_of(e));
    std::sort(sorted.begin(), sorted.end());
    const auto sends = send_times(schedule);
    std::vector<Pending> out;
    for (const Event& e : ev) {
      long end = n;
      if (auto it = std::upper_bound(sorted.begin(), sorted.end(), start_of(e)); it != sorted.end() && *it < n) {
        end = *it;
      }
      out.push_back(pending(e, end, t0, sends));
    }
    return out;
  }
  // An event's template start (its arrival less the code's calibrated latency), samples.
  long start_of(const Event& e) const { return std::lround(e.arrival - offset[static_cast<std::size_t>(e.code - 1)]); }
  // The schedule's send times per code, sorted.
  static std::map<int, std::vector<double>> send_times(const std::vector<Burst>& schedule) {
    std::map<int, std::vector<double>> sends;
    for (const auto& b : schedule) sends[b.code].push_back(b.tx_s);
    for (auto& [code, v] : sends) std::sort(v.begin(), v.end());
    return sends;
  }
  // One event as a detection before its metrics, its T_d searched up to `end`.
  Pending pending(const Event& e, long end, double t0, const std::map<int, std::vector<double>>& sends) const {
    Pending p;
    p.end = end;
    Detection& d = p.d;
    d.code = e.code;
    d.score = e.score;
    d.detector_margin = e.margin;
    const double a = e.arrival - offset[static_cast<std::size_t>(e.code - 1)];
    d.arrival_s = t0 + a / fs();
    double tx = 0;
    d.tof_from_send = false;
    if (auto sit = sends.find(e.code); sit != sends.end()) {
      const auto& v = sit->second;
      if (auto it = std::upper_bound(v.begin(), v.end(), d.arrival_s); it != v.begin()) {
        tx = *(it - 1);
        d.tof_from_send = true;
      }
    }
    d.tof_s = d.arrival_s - tx;
    p.start = std::lround(a);
    return p;
  }

  // The paper's metrics of the burst whose template starts at `start`, T_d searched to `end`.
  void metrics(Detection& d, const std::vector<double>& f, long start, long end, PearsonBank& pb) const {
    (void)metrics_window(d, f, 0, static_cast<long>(f.size()), start, end, pb);
  }

  // The samples of the filtered stream that metrics_window needs for a burst: [lo, hi_min) at
  // least (hi_min: beyond it only T_d's search may need more, up to the burst's `end`).
  struct Need {
    long lo = 0, hi_min = 0;
  };
  Need need(long n, long start) const {
    const long W = static_cast<long>(template_len);
    const long reach = static_cast<long>(L) * spc;
    const long lo = std::clamp<long>(start - 3 * spc, 0, n - 1);
    const long p0 = std::clamp<long>(start, 0, n - 1);
    const long p1 = std::clamp<long>(start + W, p0 + 1, n);
    Need r{lo > 2000 ? lo - 2000 : 0, p1};
    if (start - reach <= n - W && start + reach >= 0 && n >= W) {
      r.lo = std::min(r.lo, std::max(start - reach, 0L));
      r.hi_min = std::max(r.hi_min, std::min(start + reach, n - W) + W);
    }
    if (start >= 0 && start + W <= n) r.hi_min = std::max(r.hi_min, start + W);
    return r;
  }

  // metrics() on a window w = f[base, base + w.size()) of a stream of n samples that holds
  // need(n, start) (the caller's duty). Returns false, leaving d unset, when T_d's search reached
  // the window's end before `end` without finding its end: the caller retries with more samples.
  // Every index is the same as metrics() on the whole stream, so the results are bit for bit.
  bool metrics_window(Detection& d, std::span<const double> w, long base, long n, long start, long end,
                      PearsonBank& pb) const {
    const long W = static_cast<long>(template_len);
    const long reach = static_cast<long>(L) * spc;  // the lag window: +-L chips
    const long avail = base + static_cast<long>(w.size());
    const long lo = std::clamp<long>(start - 3 * spc, 0, n - 1);
    const long hi = std::clamp<long>(end, lo + 1, n);
    const long p0 = std::clamp<long>(start, 0, n - 1);
    const long p1 = std::clamp<long>(start + W, p0 + 1, n);
    const long hi_w = std::min(hi, avail);
    const SceneMetrics& mt = scene->receiver.metrics;  // only the metrics the scene names
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (!mt.td) {
      d.td_s = nan;
    } else {
      try {
        const StreamDuration td =
            duration_td_stream(w, static_cast<std::size_t>(lo - base), static_cast<std::size_t>(hi_w - base),
                               static_cast<std::size_t>(p0 - base), static_cast<std::size_t>(p1 - base),
                               static_cast<std::size_t>(2 * spc), fs());
        if (hi_w < hi && !td.ended_forward) return false;
        d.td_s = td.seconds;
        d.td_clipped = td.clipped;
        d.td_noise_limited = td.noise_limited;
      } catch (const InputError&) {
        d.td_s = 0;
        d.td_clipped = true;
      }
    }
    if (!mt.pearson) {
      d.rho.clear();
      d.pearson_code = 0;
      d.rho_max = d.rho_submax = d.pearson_margin = nan;
    } else if (start - reach <= n - W && start + reach >= 0 && n >= W) {
      const auto best = pb.search(w, start - reach - base, start + reach - base);
      d.rho.clear();
      for (const auto& b : best) d.rho.push_back(b.rho);
      const Distinguishability dist = distinguishability(d.rho);
      d.pearson_code = dist.best_code;
      d.rho_max = dist.rho_max;
      d.rho_submax = dist.rho_submax;
      d.pearson_margin = dist.u;
    }
    if (!mt.energy) {
      d.energy = nan;
    } else if (start >= 0 && start + W <= n) {
      d.energy = energy(w.subspan(static_cast<std::size_t>(start - base), template_len));
    }
    return true;
  }
};

SceneSimulator::SceneSimulator(Scene scene) : scene_(std::move(scene)), stages_(scene_stages(scene_)) {
  if (scene_.transducers.named) {
    const double nf = near_field_m(scene_);
    for (double d : scene_.geometry.distances_m) {
      if (d < nf) {
        throw InputError(scene_.origin + ": geometry.distances_m: " + fmt(d) + " m is inside the near field (" +
                         fmt(nf * 1e3) + " mm) of the transducers; the model is far-field");
      }
    }
  }
}
SceneSimulator::~SceneSimulator() = default;

void SceneSimulator::prepare(const std::string& family) {
  Link& lk = link(family);
  if (lk.bank) lk.bank->prepare();
}

SceneSimulator::Link& SceneSimulator::link(const std::string& family) {
  for (auto& l : links_) {
    if (l->family_name == family) return *l;
  }
  auto l = std::make_unique<Link>();
  l->scene = &scene_;
  l->observer = &observer_;
  l->family_name = family;
  ReceiverConfig cfg = scene_.receiver.config;
  cfg.family = family;
  cfg.cycles_per_chip = scene_.excitation.q_of(family);
  fit_decimation_to_chip(cfg);
  try {
    l->design = design_receiver(cfg);
  } catch (const InputError& e) {
    throw InputError(scene_.origin + ": receiver: " + e.what());
  }
  l->L = l->design.family.length;
  l->spc = cfg.chip_samples();
  l->template_len = static_cast<std::size_t>((l->L + 3) * l->spc);
  l->calibrate();
  links_.push_back(std::move(l));
  return *links_.back();
}

namespace {
std::vector<int> codes_sent(const Scene& s, int eta) {
  std::vector<int> codes = s.excitation.codes;
  if (codes.empty()) {
    for (int j = 1; j <= eta; ++j) codes.push_back(j);
  }
  return codes;
}
}  // namespace

std::size_t SceneSimulator::streams(const std::string& family) const {
  const int eta = code_family(family).eta();
  const std::size_t per = scene_.excitation.schedule.mode == "periodic" ? 1 : codes_sent(scene_, eta).size();
  return per * scene_.geometry.distances_m.size() * static_cast<std::size_t>(scene_.geometry.repeats);
}

std::vector<Measurement> SceneSimulator::run(const std::string& family, const std::function<void()>& tick,
                                             const std::function<void(const CaptureStream&)>& capture,
                                             std::size_t* false_alarms, std::uint64_t* overflows) {
  Link& lk = link(family);
  const Scene& s = scene_;
  const int eta = lk.design.family.eta();
  const std::vector<int> codes = codes_sent(s, eta);
  const bool periodic = s.excitation.schedule.mode == "periodic";
  // The trains: single mode sends each code alone; periodic sends codes in order every T.
  std::vector<std::vector<Burst>> trains;
  if (periodic) {
    const int n = s.excitation.schedule.bursts > 0 ? s.excitation.schedule.bursts : static_cast<int>(codes.size());
    std::vector<Burst> t;
    for (int k = 0; k < n; ++k) t.push_back({codes[static_cast<std::size_t>(k) % codes.size()], k * s.excitation.schedule.period_s});
    trains.push_back(t);
  } else {
    for (int j : codes) trains.push_back({{j, 0.0}});
  }
  const double window_samples = lk.L * lk.spc;
  const double match = periodic ? std::min(window_samples, s.excitation.schedule.period_s * s.fs / 2.0) : window_samples;

  // The streams (distance x repeat x train), in output order. The clean bursts are computed
  // first, in that order, so the workers only read the link's caches.
  struct Item {
    std::size_t di = 0, ti = 0;
    int rep = 0;
  };
  std::vector<Item> items;
  StageClock clean_clk;
  for (std::size_t di = 0; di < s.geometry.distances_m.size(); ++di) {
    for (const auto& train : trains) {
      for (const auto& b : train) (void)lk.clean(b.code, s.geometry.distances_m[di]);
      if (s.compensation) (void)lk.clean(train.front().code, s.compensation->reference_distance_m);
    }
    for (int rep = 1; rep <= s.geometry.repeats; ++rep) {
      for (std::size_t ti = 0; ti < trains.size(); ++ti) items.push_back({di, ti, rep});
    }
  }
  stage_s_.channel += clean_clk.lap();  // the clean bursts: transducers, medium, fractional delay
  // The noise stage's sigma for a measurement at d: snr_db is against the mean square of the
  // noise-free burst (the train's first code at d) over its T_d; the compensation reference
  // shares the measurement's sigma (the same electronics).
  auto noise_sigma = [&](const std::vector<Burst>& train, double d) {
    double sigma = s.noise.noise_v.value_or(0.0);
    if (s.noise.snr_db) {
      const Sparse& cb = lk.clean(train.front().code, d);
      const Duration td = duration_td(cb.y, s.fs);
      double ms = 0;
      for (std::size_t n = td.first; n <= td.last; ++n) ms += cb.y[n] * cb.y[n];
      ms /= static_cast<double>(td.last - td.first + 1);
      sigma = std::sqrt(ms / std::pow(10.0, *s.noise.snr_db / 10.0));
    }
    return sigma;
  };
  // Noise then ADC over a stream assembled for (d, rep, train); salt 0: the measurement's own
  // stream, 1: its compensation reference. Appends the indices of the samples the ADC clipped.
  auto add_noise_and_adc = [&](std::vector<double>& x, double sigma, double d, int rep,
                               const std::vector<Burst>& train, std::uint64_t salt,
                               std::vector<std::size_t>& clipped) {
    if (s.noise.named && (s.noise.snr_db || s.noise.noise_v)) {
      // The draws depend on the values of the measurement (seed, family, distance, repeat,
      // the codes and times of its train), never on its place in a list: a measurement gives
      // the same noise in any scene, sweep, shard or order.
      StableHash hv;
      hv.u64(s.noise.seed);
      hv.str(family);
      hv.f64(d);
      hv.u64(static_cast<std::uint64_t>(rep));
      hv.u64(train.size());
      for (const auto& b : train) {
        hv.u64(static_cast<std::uint64_t>(b.code));
        hv.f64(b.tx_s);
      }
      if (salt != 0) hv.u64(salt);
      add_white_noise(x, sigma, splitmix(hv.h));
    }
    if (s.noise.adc) (void)adc_quantize(x, *s.noise.adc, &clipped);
  };
  // One stream: its measurements, false alarms, overflows and (for the capture callback) its samples.
  struct StreamOut {
    std::vector<Measurement> rows;
    std::size_t fa = 0;
    std::uint64_t ovf = 0;
    std::uint64_t samples = 0;  // received samples simulated (the measurement's and its reference's)
    StageSeconds t;             // this stream's time per stage
    std::vector<double> x;
  };
  const bool keep_x = static_cast<bool>(capture);
  // A stream in three steps: prepare (assemble it and its compensation reference, noise, ADC),
  // receive (the receiver over both), finish (detections, compensation, matching). one() runs
  // them on a stream; group() receives up to 8 streams together (ReceiverFixedBatch or
  // ReceiverFloatBatch: one per SIMD lane), with the same results.
  struct Prepared {
    std::vector<double> x, xr;          // the stream and its compensation reference (if any)
    std::vector<std::size_t> clipped;   // sample indices the input stage clipped
    std::vector<Event> ev, rev;         // the receiver's events over x and xr
    std::vector<double> f, fr;          // the float bandpass over x and xr (for the metrics)
    StreamOut out;
  };
  // Where a stream's bursts start (shifts, in samples) and its length; the clean bursts are in
  // the link's cache already, so this only reads it.
  auto stream_layout = [&](const Item& it, std::vector<long>* shifts) {
    const double d = s.geometry.distances_m[it.di];
    long end = 0;
    for (const auto& b : trains[it.ti]) {
      const Sparse& cb = lk.clean(b.code, d);
      // Transmission times on the sample grid; the fractional part would need its own
      // interpolation, so periods are rounded to samples (documented).
      const long sh = std::lround(b.tx_s * s.fs);
      if (shifts) shifts->push_back(sh);
      end = std::max(end, cb.start + sh + static_cast<long>(cb.y.size()));
    }
    return static_cast<std::size_t>(std::max<long>(end, 0)) + lk.stream_tail();
  };
  auto prepare = [&](const Item& it, Prepared& p) {
    StageClock clk;
    const double d = s.geometry.distances_m[it.di];
    const int rep = it.rep;
    const auto& train = trains[it.ti];
    // Assemble the stream.
    std::vector<long> shifts;
    p.x.assign(stream_layout(it, &shifts), 0.0);
    for (std::size_t k = 0; k < train.size(); ++k) Link::add_into(p.x, lk.clean(train[k].code, d), shifts[k]);
    const double sigma = noise_sigma(train, d);
    add_noise_and_adc(p.x, sigma, d, rep, train, 0, p.clipped);
    p.out.samples += p.x.size();
    if (s.compensation) {  // the reference path measures c (SceneCompensation)
      const Sparse& cb = lk.clean(train.front().code, s.compensation->reference_distance_m);
      p.xr.assign(static_cast<std::size_t>(std::max<long>(cb.start + static_cast<long>(cb.y.size()), 0)) +
                      lk.stream_tail(),
                  0.0);
      Link::add_into(p.xr, cb, 0);
      std::vector<std::size_t> rclip;
      add_noise_and_adc(p.xr, sigma, d, rep, train, 1, rclip);
      p.out.samples += p.xr.size();
    }
    p.out.t.channel += clk.lap();
  };
  auto receive_one = [&](Prepared& p) {
    StageClock clk;
    p.ev = lk.receive(p.x, lk.input_scale(), p.f, &p.out.ovf, s.noise.adc ? nullptr : &p.clipped);
    if (s.compensation) p.rev = lk.receive(p.xr, lk.input_scale(), p.fr, &p.out.ovf);
    p.out.t.receiver += clk.lap();
  };
  auto finish = [&](const Item& it, Prepared& p, PearsonBank& pb) {
    StreamOut& out = p.out;
    StageClock clk;
    const double d = s.geometry.distances_m[it.di];
    const int rep = it.rep;
    const auto& train = trains[it.ti];
    const std::vector<double>& x = p.x;
    const std::vector<double>& f = p.f;
    std::vector<std::size_t>& clipped = p.clipped;
    const long n = static_cast<long>(x.size());  // f is empty when no metric is named
    const auto dets = lk.detections(p.ev, f, n, 0.0, train, pb);
    // Compensation: the reference path measures c (SceneCompensation).
    double c_est = s.receiver_speed();
    bool ref_missed = false;
    if (s.compensation) {
      const double dref = s.compensation->reference_distance_m;
      const Burst rb{train.front().code, 0.0};
      const auto rdets = lk.detections(p.rev, p.fr, static_cast<long>(p.xr.size()), 0.0, {rb}, pb);
      const double rtruth = dref / lk.c() * s.fs;
      int rbest = -1;
      for (std::size_t i = 0; i < rdets.size(); ++i) {
        if (rdets[i].code != rb.code || std::abs(rdets[i].arrival_s * s.fs - rtruth) > window_samples) continue;
        if (rbest < 0 || rdets[i].score > rdets[static_cast<std::size_t>(rbest)].score) rbest = static_cast<int>(i);
      }
      if (rbest >= 0 && rdets[static_cast<std::size_t>(rbest)].tof_s > 0) {
        c_est = dref / rdets[static_cast<std::size_t>(rbest)].tof_s;
      } else {
        ref_missed = true;
      }
    }
    std::sort(clipped.begin(), clipped.end());
    auto clipped_in = [&](long a, long b) {  // [a, b)
      const auto lo = std::lower_bound(clipped.begin(), clipped.end(), static_cast<std::size_t>(std::max<long>(a, 0)));
      const auto hi = std::lower_bound(clipped.begin(), clipped.end(), static_cast<std::size_t>(std::max<long>(b, 0)));
      return static_cast<std::size_t>(hi - lo);
    };
    const double ru = s.unambiguous_range_m(eta);
    std::vector<bool> used(dets.size(), false);
    for (std::size_t k = 0; k < train.size(); ++k) {
      Measurement m;
      m.family = family;
      m.repeat = rep;
      m.burst = static_cast<int>(k);
      m.true_distance_m = d;
      m.code_sent = train[k].code;
      const double truth = (train[k].tx_s + d / lk.c()) * s.fs;
      const long own_lo = k == 0 ? 0 : std::lround(truth);
      const long own_hi = k + 1 < train.size() ? std::lround((train[k + 1].tx_s + d / lk.c()) * s.fs)
                                               : static_cast<long>(x.size());
      m.adc_clipped = clipped_in(own_lo, own_hi);
      m.speed_used = c_est;
      m.reference_missed = ref_missed;
      int best = -1;
      for (std::size_t i = 0; i < dets.size(); ++i) {
        if (std::abs(dets[i].arrival_s * s.fs - truth) > match) continue;
        if (best < 0 || dets[i].score > dets[static_cast<std::size_t>(best)].score) best = static_cast<int>(i);
      }
      if (best >= 0) {
        used[static_cast<std::size_t>(best)] = true;
        m.detected = true;
        m.det = dets[static_cast<std::size_t>(best)];
        m.distance_m = m.det.tof_s * c_est;
        m.error_m = m.distance_m - d;
        m.range_ambiguous = ru > 0 && m.det.code == m.code_sent && std::abs(m.error_m) >= ru / 2.0;
      } else {
        // The paper's metrics at the true alignment, T_d searched to the next burst.
        long end = n;
        if (k + 1 < train.size()) end = std::lround((train[k + 1].tx_s + d / lk.c()) * s.fs);
        (void)lk.metrics_window(m.det, f, 0, n, std::lround(truth), end, pb);
      }
      // Without the pearson metric there is no Pearson decoder to err.
      m.pearson_error = s.receiver.metrics.pearson && (m.det.rho.empty() || m.det.pearson_code != m.code_sent);
      m.u = m.det.rho.empty() ? std::nan("") : u_for_sent(m.det.rho, m.code_sent);
      out.rows.push_back(m);
    }
    for (bool u : used) out.fa += !u;
    out.t.metrics += clk.lap();  // the detections' metrics, the matching and the missed bursts' metrics
    if (keep_x) out.x = std::move(p.x);
    return std::move(out);
  };
  auto one = [&](const Item& it, PearsonBank& pb) {
    Prepared p;
    prepare(it, p);
    receive_one(p);
    return finish(it, p, pb);
  };
  // Streams [b, e) of items (at most 8), received together (a fixed-stream observer sees one
  // stream at a time).
  const bool batched = !observer_;
  auto group = [&](std::size_t b, std::size_t e, PearsonBank& pb, Link::Batches& rb, StreamOut* outs) {
    std::vector<Prepared> ps(e - b);
    for (std::size_t i = b; i < e; ++i) prepare(items[i], ps[i - b]);
    StageClock clk;
    for (int ref = 0; ref < (s.compensation ? 2 : 1); ++ref) {
      std::vector<Link::BatchStream> bs(ps.size());
      for (std::size_t i = 0; i < ps.size(); ++i) {
        bs[i].volts = ref ? &ps[i].xr : &ps[i].x;
        bs[i].clamped = !ref && !s.noise.adc ? &ps[i].clipped : nullptr;
      }
      lk.receive_batch(bs, lk.input_scale(), rb);
      for (std::size_t i = 0; i < ps.size(); ++i) {
        (ref ? ps[i].rev : ps[i].ev) = std::move(bs[i].events);
        (ref ? ps[i].fr : ps[i].f) = std::move(bs[i].filtered);
        ps[i].out.ovf += bs[i].overflows;
      }
    }
    const double t = clk.lap() / static_cast<double>(ps.size());  // the group's receiver time, shared
    for (std::size_t i = b; i < e; ++i) {
      ps[i - b].out.t.receiver += t;
      outs[i - b] = finish(items[i], ps[i - b], pb);
    }
  };

  std::vector<Measurement> rows;
  std::size_t fa = 0;
  lk.overflows = 0;
  auto emit = [&](StreamOut& o, const Item& it) {
    if (capture) {
      capture({family, s.geometry.distances_m[it.di], it.rep, periodic ? 0 : trains[it.ti].front().code, s.fs, &o.x});
    }
    rows.insert(rows.end(), o.rows.begin(), o.rows.end());
    fa += o.fa;
    lk.overflows += o.ovf;
    samples_ += o.samples;
    stage_s_ += o.t;
    if (tick) tick();
  };
  // The fixed-stream observer sees the streams in order: one thread then.
  const std::size_t jobs = (observer_ ? 1 : std::min<std::size_t>(static_cast<std::size_t>(std::max(jobs_, 1)), items.size()));
  // Units of work: consecutive streams received together, up to 8 of them and at most
  // kGroupSamples samples between them, so a group holds no more memory than a few long streams
  // (a stream longer than that, or any stream when observed, is a unit alone and runs one()).
  constexpr std::size_t kGroupSamples = std::size_t{1} << 22;  // 4 M samples: ~100 MB of a group's arrays
  std::vector<std::pair<std::size_t, std::size_t>> units;  // [b, e) of items
  for (std::size_t i = 0; i < items.size();) {
    std::size_t e = i + 1, total = stream_layout(items[i], nullptr);
    while (batched && e < items.size() && e - i < ReceiverFixedBatch::kLanes) {
      const std::size_t next = stream_layout(items[e], nullptr);
      if (total + next > kGroupSamples) break;
      total += next;
      ++e;
    }
    units.emplace_back(i, e);
    i = e;
  }
  auto run_unit = [&](std::size_t b, std::size_t e, PearsonBank& pb, Link::Batches* rb, StreamOut* outs,
                      std::exception_ptr* errors) {
    if (rb && e - b > 1) {
      try {
        group(b, e, pb, *rb, outs);
        return;
      } catch (...) {
        // a stream of the group failed: run them one at a time, so each has its own outcome
      }
    }
    for (std::size_t i = b; i < e; ++i) {
      try {
        outs[i - b] = one(items[i], pb);
      } catch (...) {
        errors[i - b] = std::current_exception();
      }
    }
  };
  // Each worker has its own matched filter (PearsonBank owns FFTW buffers) and batch receivers.
  // Results are emitted in item order, so the output depends neither on jobs nor on grouping.
  std::vector<std::unique_ptr<PearsonBank>> banks;
  std::vector<std::unique_ptr<Link::Batches>> rbs;
  for (std::size_t k = 0; k < jobs; ++k) {
    banks.push_back(k == 0 ? nullptr : std::make_unique<PearsonBank>(lk.templates, lk.max_lags()));
    if (batched) rbs.push_back(std::make_unique<Link::Batches>(lk.design));
  }
  // The units run on the threads, handed out in order; each stream's result is held until every
  // stream before it is done, then emitted in stream order by one thread at a time (the one that
  // finds the next unit done; the others go on with their next units meanwhile). No thread waits
  // for a round's slowest unit. What is held is the units done after the first one not done
  // (about one per thread when the units take alike). As with one thread, the streams before a
  // failing one (its own error, or its emit's: a capture callback that throws) are emitted, then
  // that error is thrown and no later stream is emitted (units already started run on; their
  // results are dropped).
  std::vector<StreamOut> outs(items.size());
  std::vector<std::exception_ptr> errors(items.size());
  std::vector<char> unit_done(units.size(), 0);
  std::mutex emit_m;          // guards the four below; emit()'s state is the draining thread's
  std::size_t next_unit = 0;  // the first unit not yet emitted
  bool draining = false;      // a thread is emitting
  std::exception_ptr failed;  // the error that stopped the emission
  std::atomic<bool> stop{false};
  auto unit = [&](std::size_t u, std::size_t t) {
    if (stop) return;
    const auto [b, e] = units[u];
    run_unit(b, e, t == 0 ? *lk.bank : *banks[t], batched ? rbs[t].get() : nullptr, outs.data() + b,
             errors.data() + b);
    std::unique_lock<std::mutex> lock(emit_m);
    unit_done[u] = 1;
    if (draining) return;  // that thread will find this unit done
    draining = true;
    while (!failed && next_unit < units.size() && unit_done[next_unit]) {
      const auto [vb, ve] = units[next_unit];
      lock.unlock();
      std::exception_ptr err;
      for (std::size_t i = vb; i < ve && !err; ++i) {
        try {
          if (errors[i]) std::rethrow_exception(errors[i]);
          emit(outs[i], items[i]);
          outs[i] = StreamOut{};  // emitted: its memory goes
        } catch (...) {
          err = std::current_exception();
        }
      }
      lock.lock();
      if (err) {
        failed = err;
        stop = true;
      }
      ++next_unit;
    }
    draining = false;
  };
  parallel_items(units.size(), jobs, unit);
  if (failed) std::rethrow_exception(failed);
  if (false_alarms) *false_alarms = fa;
  if (overflows) *overflows = lk.overflows;
  return rows;
}

std::vector<Detection> SceneSimulator::decode(const std::string& family, const std::vector<double>& x, double t0,
                                              double period_s) {
  Link& lk = link(family);
  double peak = 0;
  for (double v : x) peak = std::max(peak, std::abs(v));
  if (peak == 0) return {};
  const std::vector<Burst> schedule =
      decode_schedule(lk.design.family.eta(), t0 + static_cast<double>(x.size()) / scene_.fs, period_s);
  std::vector<double> f;
  // The receiver sees the capture at half full scale at its peak; f comes back in capture units.
  const auto ev = lk.receive(x, peak / 0.5, f);
  const long s0 = std::lround(t0 * scene_.fs);  // sample index of x[0] on the t = 0 grid
  auto dets = lk.detections(ev, f, static_cast<double>(s0) / scene_.fs, schedule);
  return dets;
}

std::vector<Detection> SceneSimulator::decode_stream(const std::string& family, CaptureSource& src, double period_s,
                                                     std::size_t block, std::optional<double> known_peak,
                                                     const std::function<void(std::span<const double>)>& on_block) {
  Link& lk = link(family);
  // no buffer longer than the capture (its pages would be faulted in for nothing); the two block
  // buffers x (this block) and xn (the next, read ahead) are halves of one BufferVector: not
  // zeroed (read() writes them first), and from 1 MiB on backed by huge pages where the kernel
  // has them (model/base/aligned.hpp): at 65536-sample blocks and up, both share whole 2 MiB pages
  block = std::clamp<std::size_t>(src.size(), 1, std::max<std::size_t>(block, 1));
  const std::size_t stride = (block + 7) / 8 * 8;  // xn starts on a 64-byte boundary too
  BufferVector<double> xbuf(stride + block);
  std::span<double> x(xbuf.data(), block), xn(xbuf.data() + stride, block);
  // Pass 1: the peak (the receiver sees the capture at half full scale at its peak).
  double peak = 0;
  if (known_peak) {
    peak = *known_peak;
  } else {
    src.rewind();
    for (std::size_t k; (k = src.read(x)) > 0;) {
      for (std::size_t i = 0; i < k; ++i) peak = std::max(peak, std::abs(x[i]));
    }
  }
  if (peak == 0) {  // nothing to receive; the caller's scan still sees every block
    if (on_block) {
      src.rewind();
      for (std::size_t k; (k = src.read(x)) > 0;) on_block(std::span<const double>(x.data(), k));
    }
    return {};
  }
  const double t0 = src.t0();
  const long n = static_cast<long>(src.size());
  const std::vector<Burst> schedule =
      decode_schedule(lk.design.family.eta(), t0 + static_cast<double>(src.size()) / scene_.fs, period_s);
  const double scale = peak / 0.5;
  const long s0 = std::lround(t0 * scene_.fs);
  const double t0s = static_cast<double>(s0) / scene_.fs;
  const auto sends = Link::send_times(schedule);
  const bool metrics = scene_.receiver.metrics.any();
  const bool fixed = lk.fixed();
  // The receiver's pass, with the bursts' metrics beside it: each block runs the receiver (and
  // at fixed precision the metrics' float filter) on one thread while the bursts whose window of
  // the filtered stream (receive()'s, in capture units) is in run on the others, each with its
  // own PearsonBank. The window holds what the bursts still pending need (Link::need), oldest
  // first. A burst's T_d search ends at the next burst's start, so a burst waits until no later
  // event can start before that (Link::event_lookback). An event that breaks that bound (the
  // bound is derived, and checked) makes a second pass recompute the metrics with every event
  // known (`known`: the first pass's events; the receiver's own are dropped then).
  std::vector<Event> ev;
  std::vector<Link::Pending> result;
  auto pass = [&](const std::vector<Event>* known) -> bool {
    std::vector<Event> got;  // the receiver's events (the second pass drops them)
    std::vector<long> starts;
    std::multiset<long> sorted;  // every start so far
    std::vector<Link::Pending> pend;
    std::vector<Link::Need> needs;
    std::vector<std::size_t> open, active;  // end unknown yet / metrics pending
    long floor_used = std::numeric_limits<long>::min();  // the largest bound a burst relied on
    bool exact = true;
    // The window: f[base, base + wn) in w[0, wn); w grows (never zero-filled: every sample is the
    // receiver's before it is read) but is not resized per block. Once the samples no longer
    // needed are at least half of it, the rest moves to the front (a copy of at most what is
    // dropped: amortized, under one copy per sample).
    BufferVector<double> w;
    std::size_t wn = 0;
    long base = 0, read = 0;
    auto add_events = [&](const std::vector<Event>& from, std::size_t i0) {
      for (std::size_t i = i0; i < from.size(); ++i) {
        const long st = lk.start_of(from[i]);
        if (st < floor_used) exact = false;
        starts.push_back(st);
        sorted.insert(st);
        pend.emplace_back();
        needs.emplace_back();
        open.push_back(starts.size() - 1);
      }
    };
    // the events whose T_d end is known: every later start is >= floor (all: none comes later)
    auto settle = [&](const std::vector<Event>& from, long floor, bool all) {
      std::erase_if(open, [&](std::size_t i) {
        long end = n;
        if (auto it = sorted.upper_bound(starts[i]); it != sorted.end() && *it < n) end = *it;
        if (!all && end > floor) return false;
        if (!all) floor_used = std::max(floor_used, floor);
        pend[i] = lk.pending(from[i], end, t0s, sends);
        needs[i] = lk.need(n, starts[i]);
        if (needs[i].lo < base) {
          exact = false;  // its samples have left the window: the bound was broken
        } else {
          active.push_back(i);
        }
        return true;
      });
    };
    const std::vector<Event>& events = known ? *known : got;
    if (known) {
      add_events(*known, 0);
      settle(*known, 0, true);
    }
    Link::StreamReceiver rcv(lk, scale);
    BandpassFloat bp(lk.design.filter);  // fixed precision: the metrics' float filter
    const long reach = static_cast<long>(lk.L) * lk.spc + 3L * lk.spc + 2000;  // need(n, s).lo >= s - reach
    const long lookback = lookback_ ? *lookback_ : lk.event_lookback();
    // jobs_ - 1 more matched-filter banks for the worker threads (this thread uses lk.bank)
    std::vector<std::unique_ptr<PearsonBank>> banks;
    if (scene_.receiver.metrics.pearson) {
      for (int t = 1; t < jobs_; ++t) banks.push_back(std::make_unique<PearsonBank>(lk.templates, lk.max_lags()));
    }
    // Burst i's metrics on window wr, on worker thread t (thread 0 uses lk.bank; without Pearson
    // outputs no bank is used and banks is empty); false: its T_d search needs more samples.
    auto metrics_of = [&](std::size_t i, std::span<const double> wr, std::size_t t) -> char {
      PearsonBank& pb = (t == 0 || banks.empty()) ? *lk.bank : *banks[t - 1];
      return lk.metrics_window(pend[i].d, wr, base, n, pend[i].start, pend[i].end, pb);
    };
    // Blocks are read one ahead (item 1 of a round reads the next while item 0 receives this one).
    // The first block is short and each next one twice the last, up to `block`: the first
    // round's receiver runs alone (no burst is ready before it), so it is kept short.
    src.rewind();
    std::size_t want = std::min(block, kDecodeFirstBlock);
    std::size_t k = src.read(std::span<double>(x.data(), want));
    for (bool last = false; !last;) {
      last = k == 0;
      const std::size_t w0 = wn;
      const long avail = base + static_cast<long>(w0);
      std::vector<std::size_t> ready;
      for (std::size_t i : active) {
        if (avail >= needs[i].hi_min) ready.push_back(i);
      }
      std::vector<char> done(ready.size(), 0);
      const std::size_t got0 = got.size();
      // the block's filtered samples go to the window's end; the metrics read what was there
      if (metrics && w.size() < w0 + k) w.resize(std::max(w0 + k, 2 * w.size()));
      const std::span<const double> wr(w.data(), w0);
      const std::span<double> fk = metrics ? std::span<double>(w.data() + w0, k) : std::span<double>();
      const std::span<double> xk(x.data(), k);
      std::size_t k_next = 0;
      const std::size_t want_next = std::min(block, 2 * want);
      // item 0: the receiver on this block (the pending candidate after the last); item 1: the
      // next block's read; item 2 at fixed precision: the metrics' float filter; then the ready
      // bursts' metrics
      const std::size_t first = last ? 1 : (metrics && fixed) ? 3 : 2;
      parallel_items(first + ready.size(), std::min<std::size_t>(std::max(jobs_, 1), first + ready.size()),
                     [&](std::size_t item, std::size_t t) {
                       if (item == 0) {
                         if (last) return rcv.finish(got);
                         if (known && fixed) return;  // the events are known; the filter is item 2
                         if (on_block && !known) on_block(xk);
                         return rcv.block(xk, got, fixed ? std::span<double>() : fk);
                       }
                       if (item == 1 && !last) {
                         k_next = src.read(std::span<double>(xn.data(), want_next));
                         return;
                       }
                       if (item == 2 && first == 3) return bp.execute_block(xk, fk);
                       done[item - first] = metrics_of(ready[item - first], wr, t);
                     });
      std::swap(x, xn);
      want = want_next;
      // ready is a subsequence of active, in order: one pass drops the finished ones
      std::size_t r = 0;
      std::erase_if(active, [&](std::size_t i) { return r < ready.size() && ready[r] == i && done[r++]; });
      read += static_cast<long>(k);
      if (metrics) wn += k;
      k = k_next;
      if (!known) add_events(got, got0);
      settle(events, read - lookback, last);
      if (!metrics) continue;
      // the samples still needed: the pending bursts', and those of events to come
      long keep = std::min(base + static_cast<long>(wn), std::min(read - lookback, n - 1) - reach);
      for (std::size_t i : active) keep = std::min(keep, needs[i].lo);
      for (std::size_t i : open) keep = std::min(keep, lk.need(n, starts[i]).lo);
      if (keep > base && static_cast<std::size_t>(keep - base) * 2 >= wn) {
        const auto cut = static_cast<std::size_t>(keep - base);
        std::copy(w.begin() + static_cast<std::ptrdiff_t>(cut), w.begin() + static_cast<std::ptrdiff_t>(wn), w.begin());
        wn -= cut;
        base = keep;
      }
    }
    if (!known) ev = std::move(got);
    if (!metrics) {  // no metric named: the fields set to NaN
      for (auto& p : pend) (void)lk.metrics_window(p.d, {}, 0, n, p.start, p.end, *lk.bank);
      result = std::move(pend);
      return true;
    }
    if (!exact) return false;
    // the last bursts: the whole stream is in the window now
    std::vector<char> done(active.size(), 0);
    parallel_items(active.size(), std::min<std::size_t>(std::max(jobs_, 1), active.size()),
                   [&](std::size_t r, std::size_t t) {
                     done[r] = metrics_of(active[r], std::span<const double>(w.data(), wn), t);
                   });
    if (read != n || base + static_cast<long>(wn) != n || !open.empty() ||
        std::find(done.begin(), done.end(), 0) != done.end()) {
      throw InputError(src.path() + ": changed while it was read");
    }
    result = std::move(pend);
    return true;
  };
  decode_passes_ = 1;
  if (!pass(nullptr)) {
    decode_passes_ = 2;
    if (!pass(&ev)) throw std::logic_error("decode_stream: the second pass broke its own bound");
  }
  std::vector<Detection> out;
  for (auto& p : result) out.push_back(std::move(p.d));
  return out;
}

std::vector<Detection> SceneSimulator::receive_stream(const std::string& family, const std::vector<double>& x,
                                                      double t0, double period_s, std::uint64_t* overflows) {
  Link& lk = link(family);
  const std::vector<Burst> schedule =
      decode_schedule(lk.design.family.eta(), t0 + static_cast<double>(x.size()) / scene_.fs, period_s);
  std::vector<double> f;
  lk.overflows = 0;
  const auto ev = lk.receive(x, lk.input_scale(), f);
  if (overflows) *overflows += lk.overflows;
  const long s0 = std::lround(t0 * scene_.fs);
  return lk.detections(ev, f, static_cast<double>(s0) / scene_.fs, schedule);
}

std::vector<double> SceneSimulator::filtered_burst(const std::string& family, int code, double d) {
  Link& lk = link(family);
  const Sparse& b = lk.clean(code, d);
  std::vector<double> x(static_cast<std::size_t>(std::max<long>(b.start, 0)) + b.y.size() + 200, 0.0);
  Link::add_into(x, b, 0);
  BandpassFloat bp(lk.design.filter);
  for (double& v : x) v = bp.execute(v);
  return x;
}

FamilySummary summarize(const Scene& scene, const std::string& family, const std::vector<Measurement>& rows,
                        std::size_t false_alarms) {
  FamilySummary s;
  s.family = family;
  s.eta = code_family(family).eta();
  s.false_alarms = false_alarms;
  const auto eta = static_cast<std::size_t>(s.eta);
  double dmax = 0;
  for (const auto& r : rows) dmax = std::max(dmax, r.true_distance_m);
  std::vector<double> usum(eta, 0), un(eta, 0), esum(eta, 0), en(eta, 0), msum(eta, 0), mn(eta, 0);
  std::map<std::pair<int, long long>, std::pair<double, int>> td;  // (code, d) -> sum, n
  double se = 0, se_all = 0;
  std::size_t nse = 0, nse_all = 0;
  s.unambiguous_range_m = scene.unambiguous_range_m(s.eta);
  for (const auto& r : rows) {
    if (r.family != family) continue;
    ++s.measurements;
    const auto j = static_cast<std::size_t>(r.code_sent - 1);
    if (!r.detected) ++s.missed;
    const bool det_err = !r.detected || r.det.code != r.code_sent;
    s.detector_errors += det_err;
    s.pearson_errors += r.pearson_error;
    s.range_ambiguous += r.range_ambiguous;
    s.decode_errors += det_err || r.pearson_error || r.range_ambiguous;
    s.td_clipped += r.det.td_clipped;
    s.td_noise_limited += r.det.td_noise_limited;
    s.clipped_measurements += r.adc_clipped > 0;
    s.clipped_samples += r.adc_clipped;
    s.clipped_max = std::max(s.clipped_max, r.adc_clipped);
    s.reference_missed += r.reference_missed;
    if (!det_err) {
      se_all += r.error_m * r.error_m;
      ++nse_all;
    }
    if (!det_err && !r.range_ambiguous) {
      se += r.error_m * r.error_m;
      ++nse;
    }
    if (r.detected) {
      msum[j] += r.det.detector_margin;
      mn[j] += 1;
    }
    if (std::isfinite(r.u)) {
      usum[j] += r.u;
      un[j] += 1;
    }
    if (r.true_distance_m == dmax && scene.receiver.metrics.energy) {
      esum[j] += r.det.energy;
      en[j] += 1;
    }
    if (scene.receiver.metrics.td) {
      auto& t = td[{r.code_sent, std::llround(r.true_distance_m * 1e9)}];
      t.first += r.det.td_s;
      t.second += 1;
    }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  s.u_per_code.assign(eta, nan);
  s.energy_per_code.assign(eta, nan);
  s.td_per_code.assign(eta, nan);
  s.detector_margin_per_code.assign(eta, nan);
  s.u_min = s.energy_min = s.detector_margin_min = inf;
  double u_max = -inf;
  s.td_max_s = 0;
  for (std::size_t j = 0; j < eta; ++j) {
    if (un[j] > 0) {
      s.u_per_code[j] = usum[j] / un[j];
      s.u_min = std::min(s.u_min, s.u_per_code[j]);
      u_max = std::max(u_max, s.u_per_code[j]);
    }
    if (en[j] > 0) {
      s.energy_per_code[j] = esum[j] / en[j];
      s.energy_min = std::min(s.energy_min, s.energy_per_code[j]);
    }
    if (mn[j] > 0) {
      s.detector_margin_per_code[j] = msum[j] / mn[j];
      s.detector_margin_min = std::min(s.detector_margin_min, s.detector_margin_per_code[j]);
    }
  }
  for (const auto& [key, v] : td) {
    const auto j = static_cast<std::size_t>(key.first - 1);
    const double mean = v.first / v.second;
    if (std::isnan(s.td_per_code[j]) || mean > s.td_per_code[j]) s.td_per_code[j] = mean;
    s.td_max_s = std::max(s.td_max_s, mean);
  }
  if (!std::isfinite(s.u_min)) s.u_min = nan;
  if (!std::isfinite(s.energy_min)) s.energy_min = nan;
  if (!std::isfinite(s.detector_margin_min)) s.detector_margin_min = nan;
  // max/min is a ratio of positive u only; a group with u_min <= 0 (misdecodes) has none.
  s.u_max_over_min = std::isfinite(s.u_min) && s.u_min > 0 ? u_max / s.u_min : nan;
  s.error_rate = s.measurements ? static_cast<double>(s.decode_errors) / static_cast<double>(s.measurements) : 0;
  s.rmse_m = nse ? std::sqrt(se / static_cast<double>(nse)) : nan;
  s.distance_rmse_with_ambiguous_m = nse_all ? std::sqrt(se_all / static_cast<double>(nse_all)) : nan;
  if (!scene.receiver.metrics.td) s.td_max_s = nan;  // not computed, not 0
  const double L = scene.range_l();
  s.vmax_hz = s.td_max_s > 0 ? vmax(s.td_max_s, s.eta, scene.speed(), L) : nan;
  return s;
}

}  // namespace ranging
