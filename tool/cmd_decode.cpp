// `ranging decode CAPTURE --family NAME`: decode a recorded received signal (an oscilloscope
// CSV export or a WAV file, model/sim/capture.hpp) with the receiver and the paper's Pearson
// decoder; print every received burst: code j, ToF, distance, rho_max, the Pearson margin
// rho_max - rho_submax (eq. 12 as the decoder sees it: the code sent is unknown).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cstdio>
#include <iostream>
#include <exception>
#include <functional>
#include <optional>
#include <thread>
#include <sstream>

#include "model/sim/capture.hpp"
#include "model/sim/capture_stream.hpp"
#include "model/sim/capture_calibration.hpp"
#include "model/base/parallel.hpp"
#include "model/sim/metrics.hpp"
#include "model/dsp/codes.hpp"
#include "model/base/error.hpp"
#include "model/sim/medium.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"
#include "tool/cli.hpp"
#include "tool/guard.hpp"
#include "tool/commands.hpp"
#include "tool/json_meta.hpp"
#include "tool/json_text.hpp"
#include "tool/options.hpp"
#include "tool/plot.hpp"

namespace ranging::tool {

namespace {

// Where a setting came from, for the output.
struct Setting {
  double value = 0;
  std::string source;  // "option --x", "capture metadata (FILE)", "default"
};

// decode --plot: the capture, the float receiver's bandpass output (capture units) and the
// bank's rho^2 per code against time, with the detections; drawn by scripts/plot_decode.py.
void plot_decode(const std::string& png, const Scene& scene, const std::string& family, const Capture& cap,
                 double fs, const std::vector<Detection>& dets, const std::vector<Detection>& below) {
  ReceiverConfig cfg = scene.receiver.config;
  cfg.family = family;
  cfg.cycles_per_chip = scene.excitation.q_of(family);
  fit_decimation_to_chip(cfg);
  const ReceiverDesign design = design_receiver(cfg);
  ReceiverFloat rx(design);
  double peak = 0;
  for (double v : cap.samples) peak = std::max(peak, std::abs(v));
  const double scale = peak > 0 ? 0.5 / peak : 1.0;  // as SceneSimulator::decode: half full scale at the peak
  std::vector<double> filtered;
  filtered.reserve(cap.samples.size());
  std::vector<double> t_bank;
  std::vector<std::vector<double>> rho2(static_cast<std::size_t>(design.family.eta()));
  for (double v : cap.samples) {
    (void)rx.execute(v * scale);
    filtered.push_back(rx.filtered() / scale);
    if (rx.bank().sample_index() >= 0 && filtered.size() % static_cast<std::size_t>(cfg.decimation) == 0) {
      t_bank.push_back(cap.t0 + static_cast<double>(rx.bank().sample_index()) / fs);
      for (std::size_t j = 0; j < rho2.size(); ++j) rho2[j].push_back(rx.bank().rho2(static_cast<int>(j)));
    }
  }
  constexpr std::size_t kBuckets = 4000;
  const Trace raw = min_max_trace(cap.samples, cap.t0, 1 / fs, kBuckets);
  const Trace flt = min_max_trace(filtered, cap.t0, 1 / fs, kBuckets);
  nlohmann::json j;
  j["title"] = "ranging decode: " + family + ", " + std::to_string(cap.samples.size()) + " samples at " +
               std::to_string(fs / 1e6).substr(0, 5) + " MS/s";
  j["capture"] = {{"t", raw.x}, {"v", raw.y}};
  j["filtered"] = {{"t", flt.x}, {"v", flt.y}};
  nlohmann::json codes = nlohmann::json::array();
  for (std::size_t k = 0; k < rho2.size(); ++k) {
    // the bank's rate is fs / D: thin only long captures (max per bucket keeps the peaks)
    Trace tr;
    const std::size_t n = rho2[k].size(), b = std::min<std::size_t>(n, kBuckets);
    for (std::size_t i = 0; i < b; ++i) {
      const std::size_t lo = i * n / b, hi = (i + 1) * n / b;
      std::size_t best = lo;
      for (std::size_t m = lo; m < hi; ++m) if (rho2[k][m] > rho2[k][best]) best = m;
      tr.x.push_back(t_bank[best]);
      tr.y.push_back(rho2[k][best]);
    }
    codes.push_back({{"code", k + 1}, {"t", tr.x}, {"rho2", tr.y}});
  }
  j["bank"] = codes;
  j["threshold"] = cfg.detector.threshold;
  nlohmann::json ds = nlohmann::json::array();
  for (const auto* list : {&dets, &below}) {
    for (const auto& d : *list) {
      ds.push_back({{"code", d.code}, {"arrival_s", d.arrival_s}, {"rho", d.rho_max}, {"passed", list == &dets}});
    }
  }
  j["detections"] = ds;
  plot_with_script("option --plot", "scripts/plot_decode.py", j, png);
}

int decode_opened(cli::Parser& p, const std::string& path, const CaptureRead& how, int channel,
                  std::optional<std::size_t> block_option, int jobs, CaptureSource& cap, FlatTopScan& scan,
                  const std::function<void()>& wait_for_pass);

}  // namespace

int cmd_decode(const Args& args) {
  cli::Parser p = command_parser("decode");
  p.positional("CAPTURE", "capture file (.csv or .wav)");
  add_family_option(p, "the one the transmitter used; default: the capture's metadata");
  p.option("--channel", "N", "the channel to decode, 1..65535: a WAV's Nth channel, a CSV's column N + 1 (the first is the time); the --calibrate capture is read on the same channel", "1");
  p.option("--sample-rate", "HZ", "the capture's sample rate, 1e4..1e9 Hz, for a CSV of one column of samples and no time (numpy.savetxt of an array; read from t = 0), or to replace a WAV header's rate; a CSV with a time column refuses it (the rate comes from the time)");
  p.option("--references", "DIR", "recorded reference bursts DIR/<family>-<j>.csv|.wav for the Pearson decoder");
  add_speed_of_sound_option(p, "the capture's metadata, else 340");
  p.option("--temperature", "C", "air temperature -40..60 C: speed of sound at 50 % RH, 101.325 kPa");
  p.option("--period", "S", "bursts were sent every S seconds, codes 1..eta in turn (default: the capture's metadata, else one burst per code, all at t = 0)");
  p.option("--min-rho", "R", "report bursts whose Pearson rho_max (eq. 9) is at least R, 0..1 (noise triggers score lower)", "0.7");
  add_scene_overrides(p, "the decoding scene built from the options");
  p.option("--calibrate", "FILE", "a capture of the same transducers at the known --distance (one burst per code at t = 0, or a train with its period in its metadata): corrects the receiver latency per code, the mean for codes it lacks");
  p.option("--distance", "M", "the distance of the --calibrate capture, 0.001..1000 m");
  p.option("--plot", "FILE.png", "draw the capture, the bandpass output and the bank's rho^2 per code with the detections");
  add_output_options(p, {.json = true});
  p.option("--block-samples", "N", "the capture is streamed in blocks of up to N samples, 64..67108864 (the first of 16384 at most, each next twice the last; memory and speed, not results, depend on it); auto: the capture's length / 64 rounded down to a power of two, within 65536..1048576", "auto");
  add_jobs_option(p, "the capture's validation pass (a WAV's samples, a CSV's rows) and the bursts' metrics (Pearson rho, T_d, energy) computed");
  if (!p.parse(args)) return 0;
  const std::string path = p.positionals().at(0);
  if (p.has("--plot")) check_png_option("--plot", *p.get("--plot"));
  std::optional<std::size_t> block_option;
  if (p.has("--block-samples")) block_option = static_cast<std::size_t>(p.integer("--block-samples", 1 << 16, 64, 1 << 26));
  const int channel = static_cast<int>(p.integer("--channel", 1, 1, 65535));
  const CaptureRead how{channel, p.has("--sample-rate") ? p.number("--sample-rate", 0, 1e4, 1e9) : 0.0};
  // Streamed (model/sim/capture_stream.hpp): validated whole at open, then read in blocks.
  // Input clipping: the capture's flat tops at its extreme values (model/sim/metrics.hpp), in
  // two streamed passes: the extremes (whose larger magnitude is the decode's peak, so the
  // decode skips its own peak pass), seen as the capture is opened, then the runs at them,
  // during the receiver's pass.
  // The open pass runs on the --jobs threads (a WAV's or a CSV's parts, each with its own levels).
  const int jobs = jobs_option(p);
  std::vector<FlatTopScan> part_levels(static_cast<std::size_t>(jobs));
  // The header now; the pass over the samples (a WAV's validation and the extremes) on a thread
  // of its own while this one sets the receiver up (scene, design, latency calibration, FFT
  // plans): neither needs the other until the decode starts. When the capture's pass fails, its
  // error is the one reported, as when the pass came first.
  CaptureSource cap(
      path, how, [&](std::size_t part, std::span<const double> x) { part_levels[part].levels(x); },
      part_levels.size(), CaptureSource::Deferred{});
  std::exception_ptr pass_error;
  std::thread pass([&] {
    try {
      cap.finish();
    } catch (...) {
      pass_error = std::current_exception();
    }
  });
  const auto join_pass = [&] {
    pass.join();
    if (pass_error) std::rethrow_exception(pass_error);
  };
  FlatTopScan scan;
  const std::function<void()> wait_for_pass = [&] {
    join_pass();
    for (const auto& s : part_levels) scan.merge_levels(s);
  };
  try {
    return decode_opened(p, path, how, channel, block_option, jobs, cap, scan, wait_for_pass);
  } catch (...) {
    if (pass.joinable()) join_pass();  // the capture's error first
    throw;
  }
}

namespace {

// cmd_decode once the capture's header is read: wait_for_pass() returns when its pass over the
// samples has (scan then holds the capture's extremes), or rethrows that pass's error.
int decode_opened(cli::Parser& p, const std::string& path, const CaptureRead& how, int channel,
                  std::optional<std::size_t> block_option, int jobs, CaptureSource& cap, FlatTopScan& scan,
                  const std::function<void()>& wait_for_pass) {
  std::string rate_note;  // where the sample rate came from, when an option set it
  if (how.sample_rate > 0) {
    std::ostringstream os;
    os.precision(9);
    os << "sample rate " << how.sample_rate << " Hz from option --sample-rate";
    if (cap.file_rate() > 0 && std::abs(cap.file_rate() - how.sample_rate) > 1e-9 * how.sample_rate) {
      os << " (the file's header says " << cap.file_rate() << " Hz)";
    }
    rate_note = os.str();
  }
  const CaptureMeta& meta = cap.meta();
  const std::string meta_src = "capture metadata (" + (meta.source.empty() ? path : meta.source) + ")";

  std::string family, family_source;
  if (p.has("--family")) {
    family = *p.get("--family");
    family_source = "option --family";
  } else if (meta.family) {
    family = *meta.family;
    family_source = meta_src;
  } else {
    throw InputError("option --family: required (the capture has no family metadata; ranging codes --list)");
  }
  try {
    (void)code_family(family);
  } catch (const InputError& e) {
    throw InputError((p.has("--family") ? std::string("option --family: ") : meta_src + ": family: ") + e.what());
  }
  if (p.has("--speed-of-sound") && p.has("--temperature")) {
    throw InputError("options --speed-of-sound and --temperature: give one, not both");
  }
  Setting c{340.0, "default (340 m/s, the paper's)"};
  if (p.has("--speed-of-sound")) {
    c = {speed_of_sound_option(p), "option --speed-of-sound"};
  } else if (p.has("--temperature")) {
    AirConditions a;
    a.temperature_c = p.number("--temperature", 20, -40, 60);
    c = {speed_of_sound(a), "option --temperature"};
  } else if (meta.speed_of_sound) {
    c = {*meta.speed_of_sound, meta_src};
  }
  Setting period{0.0, "default (one burst per code at t = 0)"};
  if (p.has("--period")) {
    period = {p.number("--period", 0, 0, 10), "option --period"};
  } else if (meta.period_s) {
    period = {*meta.period_s, meta_src};
  }
  const double min_rho = p.number("--min-rho", 0.7, 0, 1);
  if (p.has("--calibrate") != p.has("--distance")) {
    throw InputError("options --calibrate and --distance: give both (a capture and the distance it was taken at)");
  }
  const double cal_distance = p.number("--distance", 1.0, 0.001, 1000);

  // The receiver needs an integer number of samples per carrier cycle.
  constexpr double carrier = 200e3;
  auto check_rate = [&](double rate, const std::string& file) {
    if (rate > kMaxClockHz) {  // as a scene's sample_rate: one sample per clock at most
      std::ostringstream os;
      os.precision(9);
      os << file << ": sample rate " << rate / 1e6 << " MS/s is above what the receiver takes ("
         << kMaxClockHz / 1e6 << " MS/s); "
         << "decimate the capture first (the paper's 5 MS/s is 25 samples per carrier cycle)";
      throw InputError(os.str());
    }
    const double ratio = rate / carrier;
    if (std::abs(ratio - std::round(ratio)) > 1e-3 * ratio || std::round(ratio) < 4) {
      std::ostringstream os;
      os << file << ": sample rate " << rate << " Hz is " << ratio
         << " samples per 200 kHz carrier cycle; the receiver needs an integer >= 4 (e.g. 1, 2, 4, 5 or 10 MS/s)";
      // the nearest rates it takes, to resample the capture to
      const double lo = std::max(std::floor(ratio), 4.0), hi = std::max(std::ceil(ratio), 4.0);
      if (lo == hi) {
        os << "; the nearest is " << lo * carrier / 1e6 << " MS/s";
      } else {
        os << "; the nearest are " << lo * carrier / 1e6 << " and " << hi * carrier / 1e6 << " MS/s";
      }
      if (rate < 1e5 && file.size() >= 4 && file.compare(file.size() - 4, 4, ".csv") == 0) {
        os << " (a CSV's first column is the time in seconds)";
      }
      throw InputError(os.str());
    }
    return std::round(ratio) * carrier;
  };
  const double fs = check_rate(cap.sample_rate(), path);

  std::ostringstream yaml;
  yaml.precision(17);
  yaml << "name: decode\nsample_rate: " << fs << "\nmedium:\n  speed_of_sound: " << c.value
       << "\ntransducers: {}\ngeometry:\n  distances_m: [1.0]\nexcitation:\n  family: " << family << "\n";
  if (p.has("--references")) yaml << "receiver:\n  reference: files\n  references_dir: \"" << *p.get("--references") << "\"\n";
  Scene scene = parse_scene(yaml.str(), path, ".", parse_overrides(p.values("--set")), p.has("--allow-out-of-spec"));
  for (const auto& w : scene.warnings) std::fprintf(stderr, "ranging decode: warning: %s\n", w.c_str());
  if (!scene.receiver.metrics.pearson) {  // --min-rho selects the bursts by the Pearson rho
    throw InputError("option --set: receiver.metrics: decode reports bursts by their Pearson rho (--min-rho); "
                     "the metrics must include pearson");
  }
  warn_if_out_of_spec("decode", scene.receiver.config);
  const CodeFamily fam = code_family(family);
  const std::size_t burst = static_cast<std::size_t>(fam.length + 3) * static_cast<std::size_t>(scene.receiver.config.chip_samples());
  auto check_len = [&](std::size_t samples, const std::string& file) {
    if (samples < burst) {
      std::ostringstream os;
      os << file << ": too short: " << samples << " samples (" << samples / fs * 1e6
         << " us) hold less than one burst of " << family << " (" << burst << " samples, " << burst / fs * 1e6 << " us)";
      throw InputError(os.str());
    }
  };
  check_len(cap.size(), path);
  // Long blocks run the bandpass on its SIMD lanes (time split: float from kBandpassFloatSplitMin
  // samples on, fixed from kBandpassSplitMin), but each sample of a block's buffers is fresh
  // memory once (a page fault per 4 KiB, or per 2 MiB where the kernel gives the buffers of
  // 131072 samples and more huge pages: model/base/aligned.hpp): long blocks pay on long
  // captures only.
  std::size_t block = block_option.value_or(std::size_t{1} << 16);
  while (!block_option && block < (std::size_t{1} << 20) && 2 * block <= cap.size() / 64) block *= 2;
  SceneSimulator sim(scene);
  sim.set_jobs(jobs);
  sim.prepare(family);  // the receiver's design, calibration and plans, beside the capture's pass

  std::optional<LatencyCalibration> cal;
  if (p.has("--calibrate")) {
    const std::string cal_path = *p.get("--calibrate");
    Capture k = read_capture(cal_path, how);
    if (std::abs(check_rate(k.sample_rate, cal_path) - fs) > 1e-6 * fs) {
      throw InputError("option --calibrate: " + cal_path + " is sampled at " + std::to_string(k.sample_rate) +
                       " Hz, the capture at " + std::to_string(cap.sample_rate()) + " Hz");
    }
    check_len(k.samples.size(), cal_path);
    std::vector<Detection> kd;
    // The calibration capture's own burst period (its metadata) if it has one, else the capture's.
    const double kperiod = k.meta.period_s ? *k.meta.period_s : period.value;
    for (const auto& d : sim.decode(family, k.samples, k.t0, kperiod)) {
      if (d.rho_max >= min_rho) kd.push_back(d);
    }
    cal = calibrate_latency(kd, cal_distance, c.value, "option --calibrate (" + cal_path + ")");
  }

  wait_for_pass();
  const FlatTops levels = scan.result();
  const double peak = std::max(std::abs(levels.high), std::abs(levels.low));
  std::vector<Detection> dets, below;
  const auto decoded =
      sim.decode_stream(family, cap, period.value, block, peak, [&](std::span<const double> x) { scan.runs(x); });
  const FlatTops clip = scan.result();
  for (auto d : decoded) {
    if (cal) d.tof_s = cal->correct(d.code, d.tof_s);
    (d.rho_max >= min_rho ? dets : below).push_back(d);
  }
  if (p.has("--plot")) {  // the picture needs the whole capture in memory (decoding does not)
    plot_decode(*p.get("--plot"), scene, family, read_capture(path, how), fs, dets, below);
  }
  const bool known = meta.code_sent && *meta.code_sent > 0;
  // A burst that arrives before its code was first sent (an echo of a burst sent before the
  // capture's t = 0, or a misdecode) has no time of flight: null, never a distance from t = 0.
  std::size_t unsent = 0;
  for (const auto* v : {&dets, &below}) {
    for (const auto& d : *v) unsent += d.tof_from_send ? 0 : 1;
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto tof_of = [&](const Detection& d) { return d.tof_from_send ? d.tof_s : nan; };
  // One detection's members, in key order (tool/json_text.hpp: dump()'s text without a json
  // object per detection).
  auto det_text = [&](JsonObjectText& o, const Detection& d) {
    const double tof = tof_of(d);
    if (!d.tof_from_send) o.number("arrival_s", d.arrival_s);
    o.integer("code", d.code);
    o.number("distance_m", tof * c.value);
    if (meta.true_distance_m) o.number("error_m", tof * c.value - *meta.true_distance_m);
    o.integer("pearson_code", d.pearson_code);
    o.number("pearson_margin", d.pearson_margin);
    o.number("receiver_rho2", d.score);
    o.number("rho", d.rho_max);
    o.number("tof_s", tof);
    if (known && d.rho.size() >= 2 && *meta.code_sent <= static_cast<int>(d.rho.size())) {
      o.number("u", u_for_sent(d.rho, *meta.code_sent));  // eq. 10, with the code the metadata says was sent
    }
  };

  if (p.has("--json")) {
    nlohmann::json j;
    j["sample_rate"] = cap.sample_rate();
    j["channel"] = channel;
    j["channels"] = cap.channels();
    j["sample_rate_source"] = rate_note.empty() ? std::string("capture file") : std::string("option --sample-rate");
    j["family"] = family;
    j["family_source"] = family_source;
    j["speed_of_sound"] = c.value;
    j["speed_of_sound_source"] = c.source;
    j["period_s"] = period.value;
    j["period_source"] = period.source;
    j["min_rho"] = min_rho;
    if (cal) {
      nlohmann::json per = nlohmann::json::object();
      for (const auto& [code, v] : cal->per_code_s) per[std::to_string(code)] = v;
      j["calibration"] = {{"file", *p.get("--calibrate")}, {"distance_m", cal_distance},
                          {"latency_correction_s", per}, {"mean_correction_s", cal->mean_s}};
    }
    if (meta.scene) j["scene"] = *meta.scene;
    if (meta.code_sent) j["code_sent"] = *meta.code_sent;
    if (meta.true_distance_m) j["true_distance_m"] = *meta.true_distance_m;
    // The detections (50 000 in a 100 M-sample capture) are written on sim.jobs() threads as
    // dump(2) places them in the document, which holds a marker string in their place.
    const std::pair<const char*, const std::vector<Detection>*> lists[] = {{"detections", &dets},
                                                                           {"below_gate", &below}};
    for (const auto& [key, list] : lists) j[key] = std::string("\x01") + key + "\x01";
    j["found"] = !dets.empty();
    j["arrivals_before_first_send"] = unsent;  // their tof_s and distance_m are null
    j["input_clipping"] = {{"samples", clip.samples}, {"runs", clip.runs}, {"max", clip.high}, {"min", clip.low},
                           {"rule", "runs of >= 3 consecutive samples at the capture's maximum or minimum"}};
    const std::string text = stamp_build_info(j).dump(2);
    JsonArrayText arrays[std::size(lists)];
    std::vector<std::pair<std::string, const JsonArrayText*>> splice;
    for (std::size_t i = 0; i < std::size(lists); ++i) {
      arrays[i] = json_array_text(*lists[i].second, det_text, 1, sim.jobs());
      splice.emplace_back(std::string("\"\\u0001") + lists[i].first + "\\u0001\"", &arrays[i]);  // as dump() escapes it
    }
    json_splice(std::cout, text, splice);
    std::cout << "\n";
  } else {
    std::fprintf(stderr, "ranging decode: family %s from %s; speed of sound %.6g m/s from %s; period %.6g s from %s%s%s\n",
                 family.c_str(), family_source.c_str(), c.value, c.source.c_str(), period.value,
                 period.source.c_str(), rate_note.empty() ? "" : "; ", rate_note.c_str());
    const std::string chan = cap.channels() > 1 ? ", channel " + std::to_string(channel) + " of " +
                                                      std::to_string(cap.channels())
                                                : std::string();
    std::printf("%s: %zu samples at %.6g MS/s%s, family %s, c = %.2f m/s%s\n", path.c_str(), cap.size(),
                cap.sample_rate() / 1e6, chan.c_str(), family.c_str(), c.value, cal ? ", latency calibrated" : "");
    std::printf("%5s %12s %12s %8s %8s\n", "code", "tof_us", "distance_mm", "rho_max", "margin");
    auto row = [&](const Detection& d) {
      if (d.tof_from_send) {
        std::printf("%5d %12.3f %12.3f %8.4f %8.4f", d.code, d.tof_s * 1e6, d.tof_s * c.value * 1e3, d.rho_max,
                    d.pearson_margin);
      } else {
        std::printf("%5d %12s %12s %8.4f %8.4f  arrived at %.3f us, before code %d was first sent: no ToF", d.code,
                    "-", "-", d.rho_max, d.pearson_margin, d.arrival_s * 1e6, d.code);
      }
    };
    for (const auto& d : dets) {
      row(d);
      std::printf("\n");
    }
    for (const auto& d : below) {
      row(d);
      std::printf("  below the gate (rho %.4f < --min-rho %.4g)\n", d.rho_max, min_rho);
    }
    if (unsent > 0) {
      std::printf("%zu burst(s) arrived before their code was first sent: echoes of bursts sent before the capture's "
                  "t = 0 (t = 0 must be the first burst's start), or misdecodes; no distance is given for them\n",
                  unsent);
    }
    if (dets.empty()) {
      std::printf(below.empty() ? "no burst detected\n" : "no burst passed the gate\n");
    }
    if (clip.samples > 0) {
      std::printf("input clipped: %zu samples in %zu flat tops at the capture's extremes (%.6g / %.6g): distances and rho "
                  "may be biased\n",
                  clip.samples, clip.runs, clip.high, clip.low);
    } else {
      std::printf("input clipping: none (no run of >= 3 samples at the capture's extremes)\n");
    }
  }
  return dets.empty() ? 1 : 0;
}

}  // namespace

}  // namespace ranging::tool
