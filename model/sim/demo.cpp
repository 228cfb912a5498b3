#include "model/sim/demo.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>

#include "model/base/error.hpp"
#include "model/base/parallel.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/latency.hpp"
#include "model/sim/metrics.hpp"

namespace ranging {
namespace {

constexpr double kCalibrationDistance = kReferenceDistance;  // m

ChannelParams channel_for(const DemoParams& p, double distance, double noise, std::uint64_t seed) {
  ChannelParams c;
  c.speed_of_sound = p.speed_of_sound;
  c.distance_m = distance;
  c.gain = p.gain;
  c.tx = p.transducer;
  c.rx = p.transducer;
  c.noise_rms = noise;
  c.seed = seed;
  return c;
}

// Runs both receivers over x; keeps the strongest event of each; optionally records the
// float filter output.
struct Pass {
  std::optional<Event> flt, fix;
  std::uint64_t overflows = 0;
  std::vector<double> filtered;
};

Pass run_receivers(const ReceiverDesign& design, const std::vector<double>& x) {
  ReceiverFloat rf(design);
  ReceiverFixed rx(design);
  Pass out;
  out.filtered.reserve(x.size());
  auto keep = [](std::optional<Event>& best, const std::optional<Event>& e) {
    if (e && (!best || e->score > best->score)) best = e;
  };
  for (double v : x) {
    keep(out.flt, rf.execute(v));
    out.filtered.push_back(rf.filtered());
    keep(out.fix, rx.execute(v));
  }
  keep(out.flt, rf.flush());
  keep(out.fix, rx.flush());
  out.overflows = rx.overflow_events().total();
  return out;
}

}  // namespace

std::vector<DemoRow> run_demo(const DemoParams& p,
                              const std::function<void(std::size_t, std::size_t)>& progress) {
  require_in_range("--speed-of-sound", p.speed_of_sound, 100, 10000);
  require_in_range("--gain", p.gain, 1e-6, 10);
  require_in_range("--noise-rms", p.noise_rms, 0, 10);
  if (p.distances_m.empty()) throw InputError("--distances: give at least one distance");
  require_in_range("--jobs", p.jobs, 1, 256);
  for (double d : p.distances_m) require_in_range("--distances", d, 0.01, 20.0);

  const ReceiverDesign design = design_receiver(p.receiver);
  const ReceiverConfig& rc = design.config;
  const ExcitationParams ex = receiver_excitation(rc);
  const int window = design.family.length * rc.chip_samples();
  const std::size_t template_len = static_cast<std::size_t>(window + 2 * rc.chip_samples());
  const std::size_t tail = static_cast<std::size_t>(window) * 3 + 2000;

  const std::size_t eta = design.family.codes.size();
  const std::size_t total = eta * (p.distances_m.size() + 1);
  std::size_t done = 0;

  // Calibration: noise-free burst of every code at the reference distance, through both
  // receivers at once (the passes are kept for the float receiver's offsets and the templates).
  // Any decoded code is taken: a misdecoding receiver shows in the rows.
  const double cal_delay = calibration_flight(kCalibrationDistance, p.speed_of_sound, rc.fs);
  std::vector<Pass> cal(eta);
  auto events = [](const std::optional<Event>& e) { return e ? std::vector<Event>{*e} : std::vector<Event>{}; };
  auto failure = [](int code) {
    return "calibration: code " + std::to_string(code) +
           " was not detected at the reference distance; lower detector.threshold or raise --gain";
  };
  const std::vector<double> offset_fix = calibrate_receiver_latency<Event>(
      eta, cal_delay,
      [&](int code) {
        const auto exc = bpsk_excitation(design.family.codes[static_cast<std::size_t>(code - 1)], ex);
        const auto rx = propagate(exc, channel_for(p, kCalibrationDistance, 0.0, p.seed), rc.fs,
                                  static_cast<std::size_t>(cal_delay) + tail);
        Pass& pass = cal[static_cast<std::size_t>(code - 1)];
        pass = run_receivers(design, rx);
        if (!pass.flt || !pass.fix) throw InputError(failure(code));  // both receivers, code by code
        if (progress) progress(++done, total);
        return events(pass.fix);
      },
      failure, CalibrationCode::Any);
  const std::vector<double> offset_flt = calibrate_receiver_latency<Event>(
      eta, cal_delay, [&](int code) { return events(cal[static_cast<std::size_t>(code - 1)].flt); }, failure,
      CalibrationCode::Any);
  std::vector<std::vector<double>> templates(eta);
  for (std::size_t j = 0; j < eta; ++j) {
    const std::size_t start = static_cast<std::size_t>(std::lround(cal_delay));
    templates[j].assign(cal[j].filtered.begin() + start, cal[j].filtered.begin() + start + template_len);
  }
  cal.clear();

  // The rows (distance x code) are independent: each is drawn from its own seed (p.seed + 1 +
  // its index) and written to its own slot, on p.jobs threads with a matched filter each.
  const std::size_t threads = std::min<std::size_t>(static_cast<std::size_t>(p.jobs), p.distances_m.size() * eta);
  std::vector<std::unique_ptr<PearsonBank>> banks;
  for (std::size_t t = 0; t < threads; ++t) banks.push_back(std::make_unique<PearsonBank>(templates));
  std::vector<DemoRow> rows(p.distances_m.size() * eta);
  std::mutex progress_lock;
  parallel_items(rows.size(), threads, [&](std::size_t item, std::size_t t) {
    PearsonBank& bank = *banks[t];
    const double d = p.distances_m[item / eta];
    const std::size_t j = item % eta;
    const auto exc = bpsk_excitation(design.family.codes[j], ex);
    const double delay = d / p.speed_of_sound * rc.fs;
    const auto rx = propagate(exc, channel_for(p, d, p.noise_rms, p.seed + 1 + item), rc.fs,
                              static_cast<std::size_t>(delay) + tail);
    Pass pass = run_receivers(design, rx);
    DemoRow row;
    row.code = static_cast<int>(j) + 1;
    row.distance_m = d;
    row.overflows = pass.overflows;
    auto fill = [&](DemoDecode& out, const std::optional<Event>& e,
                    const std::vector<double>& offsets) {
      if (!e) return;
      out.detected = true;
      out.decoded = e->code;
      out.tof_s = (e->arrival - offsets[e->code - 1]) / rc.fs;
      out.distance_m = out.tof_s * p.speed_of_sound;
      out.error_m = out.distance_m - d;
      out.score = e->score;
      out.margin = e->margin;
    };
    fill(row.flt, pass.flt, offset_flt);
    fill(row.fix, pass.fix, offset_fix);
    // The paper's decoder: the Pearson matched filter (eq. 9 over lags, +-L chips around the
    // float receiver's time of flight, or the true one if nothing was found); u by eq. 10.
    const double tof_samples = row.flt.detected ? row.flt.tof_s * rc.fs : delay;
    const long start = std::lround(tof_samples);
    const long reach = static_cast<long>(window);
    const long n = static_cast<long>(pass.filtered.size());
    if (start - reach <= n - static_cast<long>(template_len) && start + reach >= 0) {
      const auto best = bank.search(pass.filtered, start - reach, start + reach);
      std::vector<double> rhos;
      for (const auto& b : best) rhos.push_back(b.rho);
      const Distinguishability dist = distinguishability(rhos);
      row.pearson_decoded = dist.best_code;
      row.rho_max = dist.rho_max;
      row.rho_submax = dist.rho_submax;
      row.u = u_for_sent(rhos, row.code);
    }
    if (start >= 0 && static_cast<std::size_t>(start) + template_len <= pass.filtered.size()) {
      row.energy = energy(std::span<const double>(pass.filtered.data() + start, template_len));
    }
    rows[item] = row;
    if (progress) {
      const std::lock_guard<std::mutex> lock(progress_lock);
      progress(++done, total);
    }
  });
  return rows;
}

}  // namespace ranging
