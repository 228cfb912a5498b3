#pragma once
// The scene simulator: builds exactly the channel stages a scene names (model/sim/scene.hpp) and
// runs its measurements through the receiver of the scene's precision.
//
// Stages, in signal order (each exists only when the scene asks for it):
//   transducers  TX and RX resonators (transducers section)
//   directivity  piston directivity of both transducers at geometry.angle_deg
//   absorption   ISO 9613-1 air absorption over the path, zero-phase FIR (medium air conditions)
//   delay        propagation d/c, Kaiser-sinc fractional delay (always)
//   gain         sensitivity * amplitude * 0.1 m / d, spherical spreading (always)
//   noise        white Gaussian, snr_db or noise_v, seeded (noise.snr_db / noise.noise_v)
//   adc          quantization to bits over +-full_scale_v with clipping (noise.adc)
// The receiver (bandpass -> correlator bank -> peak detector, model/dsp/receiver.hpp) is the sink.
//
// Time of flight: the receiver's latency is calibrated once per code on a noise-free burst
// through the scene's deterministic stages at receiver.calibration_distance_m (the paper's
// system measures a known distance the same way). The paper's metrics are computed on the
// float bandpass output, whatever the receiver precision:
//   Pearson  the matched filter of section 3.3.2: each received template's rho (eq. 9) is
//            maximized over lags within +-L chips (L = code length) of the detected arrival
//            (model/sim/metrics.hpp PearsonBank); the argmax is the Pearson decoder's code;
//   u        eq. 10 for the code sent: rho(sent) - max rho(other codes), negative on a Pearson
//            misdecode (Measurement::u); Detection::pearson_margin is rho_max - rho_submax;
//   energy   sum of squares over the template span at the detected arrival;
//   T_d      section 2.2 from one chip before the arrival to the end of the stream or the next
//            detected burst, threshold max(b/10, 4.5 x the noise floor) (duration_td_stream),
//            flagged when the search range clips it or the noise floor set the threshold.
// Decode errors count the receiver's misses and misdecodes, the Pearson decoder's misdecodes and
// range-ambiguous (aliased) distances. Input clipping (ADC or the fixed receiver's clamp) is
// counted per measurement. With a compensation section every measurement's distance is
// c_est * tof, c_est = d_ref / tof_ref from its reference burst (SceneCompensation).
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "model/sim/scene.hpp"

namespace ranging {

// Seconds per simulation stage (SceneSimulator::stage_seconds).
struct StageSeconds {
  double channel = 0, receiver = 0, metrics = 0;
  StageSeconds& operator+=(const StageSeconds& o) {
    channel += o.channel;
    receiver += o.receiver;
    metrics += o.metrics;
    return *this;
  }
};

class CaptureSource;  // model/sim/capture_stream.hpp

struct SceneStage {
  std::string name;         // transducers, directivity, absorption, delay, gain, noise, adc
  std::string description;  // the parameters it uses
};

// The channel stages the scene builds (without running anything).
std::vector<SceneStage> scene_stages(const Scene& scene);

// One received burst as the receiver saw it.
struct Detection {
  int code = 0;            // 1-based j (receiver bank)
  double arrival_s = 0;    // calibrated arrival time from t = 0 (start of the first burst)
  double tof_s = 0;        // arrival - transmission time of the burst that carried code j: the latest
                           // send of code j at or before the arrival; with none, the arrival itself
  bool tof_from_send = true;  // false: no send of code j at or before the arrival (an echo of a burst
                              // sent before t = 0, or a misdecode), so tof_s is only the time from t = 0
  double score = 0;        // receiver rho^2 at the peak (hardware detector)
  double detector_margin = 0;  // receiver rho^2(best) - rho^2(second) at the peak
  // The paper's Pearson matched filter (eq. 9 over lags, +-L chips around the arrival).
  std::vector<double> rho;     // per code j-1: best rho over the lag window (empty: no window)
  int pearson_code = 0;        // argmax of rho (0 when rho is empty)
  double rho_max = 0, rho_submax = 0;
  double pearson_margin = 0;   // rho_max - rho_submax (eq. 12 as the decoder sees it, >= 0)
  double energy = 0;       // V^2, sum of squares of the filtered signal over the burst window
  double td_s = 0;         // T_d of the filtered signal around the burst (section 2.2)
  bool td_clipped = false;        // the search range may have cut T_d
  bool td_noise_limited = false;  // the noise floor, not b/10, set the T_d threshold
};

struct Measurement {
  std::string family;
  int repeat = 0;              // 1-based
  int burst = 0;               // 0-based index in the train (0 in single mode)
  double true_distance_m = 0;
  int code_sent = 0;           // 1-based j
  bool detected = false;
  Detection det;               // valid when detected
  double distance_m = 0;       // tof * c
  double error_m = 0;          // distance_m - true_distance_m
  double u = 0;                // eq. 10: rho(code_sent) - max rho(other), < 0 on a Pearson misdecode
  bool pearson_error = false;  // the Pearson decoder picked another code (or had no window)
  // Input clipping: samples of this burst's share of the stream (from its arrival to the next
  // burst's, the first burst also owning what precedes it) that the ADC clipped (noise.adc), or,
  // without an ADC stage, that the fixed receiver's input clamp to +-full_scale cut.
  std::size_t adc_clipped = 0;
  // Periodic schedule: detected with the right code, but |error| >= eta*c*T / 2: the burst
  // arrived after the next send of its own code (d at or beyond the unambiguous range) and its
  // distance aliased. A decode error, excluded from the RMSE.
  bool range_ambiguous = false;
  double speed_used = 0;       // c of the ToF -> distance conversion (c_est with compensation)
  bool reference_missed = false;  // compensation: the reference burst was not detected (receiver c used)
};

struct FamilySummary {
  std::string family;
  int eta = 0;
  // decode_errors: measurements that the receiver missed or misdecoded, or that the Pearson
  // decoder misdecoded, or whose distance aliased (range_ambiguous; the union of the parts below).
  std::size_t measurements = 0, decode_errors = 0, missed = 0, false_alarms = 0;
  std::size_t detector_errors = 0;       // receiver (hardware detector): missed or wrong code
  std::size_t pearson_errors = 0;        // Pearson matched filter: wrong code (u < 0 or no window)
  std::size_t td_clipped = 0, td_noise_limited = 0;  // T_d measurements flagged
  double error_rate = 0, rmse_m = 0;
  std::vector<double> u_per_code;        // mean eq. 10 u over all distances and repeats (Fig. 14)
  std::vector<double> energy_per_code;   // mean energy at the largest distance (Fig. 15)
  std::vector<double> td_per_code;       // max over distances of the mean T_d per distance
  std::vector<double> detector_margin_per_code;  // mean receiver rho^2 margin (detected bursts)
  double u_min = 0, energy_min = 0, td_max_s = 0, vmax_hz = 0;
  double u_max_over_min = 0;             // max/min of u_per_code (paper: 1.19-1.33 M, 1.85-5.85 Gold)
  double detector_margin_min = 0;        // min over codes of detector_margin_per_code
  std::uint64_t overflows = 0;           // fixed precision: saturations and wraps
  // Input clipping (Measurement::adc_clipped): measurements with any, total and largest count.
  std::size_t clipped_measurements = 0, clipped_samples = 0, clipped_max = 0;
  std::size_t range_ambiguous = 0;       // counted in decode_errors too
  double unambiguous_range_m = 0;        // eta*c*T (0: single mode)
  std::size_t reference_missed = 0;      // compensation: reference bursts not detected
  double distance_rmse_with_ambiguous_m = 0;  // the RMSE had the aliased distances been kept
};

// What a run writes as a capture: the whole received stream (volts) of one measurement.
struct CaptureStream {
  std::string family;
  double distance_m = 0;
  int repeat = 0;
  int code = 0;                // single mode: the code sent; periodic: 0
  double fs = 0;
  const std::vector<double>* volts = nullptr;
};

class SceneSimulator {
 public:
  explicit SceneSimulator(Scene scene);
  ~SceneSimulator();
  const Scene& scene() const { return scene_; }
  const std::vector<SceneStage>& stages() const { return stages_; }

  // Streams of run() processed in parallel (threads); 1 (the default) runs them in the calling
  // thread. The result does not depend on it (the noise of a stream is seeded by its values,
  // results are collected in stream order); a fixed-stream observer forces one thread.
  void set_jobs(int jobs) { jobs_ = jobs; }
  int jobs() const { return jobs_; }
  // decode_stream's bound on how far behind the receiver an event can start (derived from the
  // detector's holdoff; nullopt: that). Tests set a bound that events break, to check that the
  // decode then recomputes the metrics in a second pass and still gives decode()'s detections.
  void set_event_lookback(std::optional<long> samples) { lookback_ = samples; }
  // Receiver passes the last decode_stream made: 1, or 2 when an event broke the lookback bound.
  int decode_passes() const { return decode_passes_; }

  // Every measurement of one family (geometry x repeats x bursts). Deterministic for a seed.
  std::vector<Measurement> run(const std::string& family,
                               const std::function<void()>& tick = {},
                               const std::function<void(const CaptureStream&)>& capture = {},
                               std::size_t* false_alarms = nullptr, std::uint64_t* overflows = nullptr);
  // Received samples that run() has simulated so far (every stream, compensation references
  // included; calibration not): the denominator of a per-sample speed.
  std::uint64_t samples_simulated() const { return samples_; }
  // Seconds that run() has spent so far per stage, summed over its threads (each thread's
  // steady clock, so on an idle core about its CPU time): channel (the clean bursts through
  // transducers, medium and fractional delay, the streams' assembly, noise and ADC), receiver
  // (the receiver model, and at fixed precision the float filter of the metrics), metrics (the
  // paper's metrics, detections, matching). A speed figure, not a result: it changes run to run.
  const StageSeconds& stage_seconds() const { return stage_s_; }
  // Number of receiver runs (streams) of run(family), for progress bars.
  std::size_t streams(const std::string& family) const;

  // Builds now what decoding or simulating `family` needs: the receiver's design, its latency
  // calibration, the Pearson references and their transform plans (else made on first use), so
  // a caller can have it done beside other work (decode: beside the capture's open pass). The
  // results do not change. InputError as run().
  void prepare(const std::string& family);

  // Decode a recorded stream (volts or any scale; fs must be the scene's): every event the
  // receiver emits, with t0 the time of sample 0. period_s > 0: the bursts were sent every
  // period_s, codes 1..eta in order, so tof = arrival - (latest send of that code).
  std::vector<Detection> decode(const std::string& family, const std::vector<double>& x, double t0,
                                double period_s = 0);

  // decode() of a capture read in blocks of up to `block` samples (the first of
  // min(block, kDecodeFirstBlock), each next twice the last until `block`: the first block's
  // receiver runs alone, no burst being ready before it): the same detections, bit for bit,
  // in memory independent of the capture's length. Two passes: the capture's peak, then the
  // receiver with the bursts' metrics beside it over a sliding window of the filtered stream
  // (it spans the bursts whose metrics are pending, about one burst period); jobs() threads
  // share a block's receiver and metrics. peak: the capture's max |x| when the caller has it
  // (the first pass is skipped; it must be that maximum); on_block: called with every block of
  // the capture, in order, as the receiver's pass reads it (a caller's own scan without a read
  // of its own).
  static constexpr std::size_t kDecodeFirstBlock = 16384;
  std::vector<Detection> decode_stream(const std::string& family, CaptureSource& src, double period_s = 0,
                                       std::size_t block = std::size_t{1} << 16, std::optional<double> peak = {},
                                       const std::function<void(std::span<const double>)>& on_block = {});

  // The receiver of the scene's precision over a stream of volts at the scene's input scale
  // (noise.adc.full_scale_v, else receiver.full_scale_v; decode() instead normalizes to the
  // peak), t0 the time of sample 0 on the t = 0 grid; bursts went out every period_s from
  // t = 0 with codes 1..eta in turn (the scheduler's rule). Adds the fixed receiver's
  // saturations/wraps to *overflows.
  std::vector<Detection> receive_stream(const std::string& family, const std::vector<double>& volts, double t0,
                                        double period_s, std::uint64_t* overflows = nullptr);

  // The float-filtered noise-free received burst of a code at a distance (Figure 13), from
  // the start of transmission, volts.
  std::vector<double> filtered_burst(const std::string& family, int code, double distance_m);

  // Fixed precision only: called with every stream the fixed receiver runs (calibration and
  // measurements), its quantized ADC input and the events execute_raw emitted, in order (the
  // end-of-stream flush is not included). `ranging simulate --precision rtl` runs the same
  // streams through the Verilated receiver and compares the events.
  using FixedStreamObserver = std::function<void(const ReceiverDesign&, const std::vector<std::int64_t>&,
                                                 const std::vector<EventFixed>&)>;
  void set_fixed_observer(FixedStreamObserver f) { observer_ = std::move(f); }

  struct Link;  // per-family design, calibration and templates (scene_simulator.cpp)

 private:
  Link& link(const std::string& family);
  Scene scene_;
  std::vector<SceneStage> stages_;
  std::vector<std::unique_ptr<Link>> links_;
  FixedStreamObserver observer_;
  int jobs_ = 1;
  std::optional<long> lookback_;
  int decode_passes_ = 0;
  std::uint64_t samples_ = 0;
  StageSeconds stage_s_;
};

FamilySummary summarize(const Scene& scene, const std::string& family,
                        const std::vector<Measurement>& rows, std::size_t false_alarms = 0);

// Piston directivity |2 J1(x)/x|, x = ka sin(theta), with ka set by the full -3 dB beam angle.
double piston_directivity(double beam_angle_deg, double angle_deg);

}  // namespace ranging
