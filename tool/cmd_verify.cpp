// `ranging verify`: the RTL of one configuration against the golden model (ReceiverFixed), bit
// for bit and stage by stage. The IP folder is generated into a work folder, the Verilated
// receiver_top is built there at run time (tool/rtl_runner.hpp) and streams are run through it:
// coded streams of every code of the family at several distances, the full-scale worst case,
// random input, random valid gaps with back-pressure, and a reset mid-stream. Exit status: 0
// every stage matched, 1 a mismatch (the first one is reported), 2 bad input.
#include <nlohmann/json.hpp>

#include <chrono>
#include <iostream>
#include <random>
#include <sstream>

#include "model/base/error.hpp"
#include "model/config/receiver_config.hpp"
#include "model/dsp/excitation.hpp"
#include "model/hw/hw_params.hpp"
#include "model/hw/realtime.hpp"
#include "model/sim/channel.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/json_meta.hpp"
#include "tool/options.hpp"
#include "tool/rtl_runner.hpp"

namespace ranging::tool {
namespace {

// Pipeline order: the first mismatching stage is the root cause of the later ones.
const char* const kStages[] = {"filter", "bank framing", "chip filter", "combiner", "weighted power",
                               "energy", "events"};
constexpr int kStageCount = 7;

struct Mismatch {
  std::string stage, run, where, expected, got;
};

struct StageCount {
  std::uint64_t compared = 0, mismatches = 0;
};

struct ModelTaps {
  std::vector<RtlFilterBeat> filter;
  std::vector<RtlBankBeat> bank;  // one per beat (code j), as the RTL streams them
  std::vector<EventFixed> events;
};

// The model's taps of samples [begin, end) from a fresh receiver.
ModelTaps model_taps(const ReceiverDesign& d, const std::vector<std::int64_t>& x, std::size_t begin, std::size_t end) {
  ReceiverFixed m(d);
  m.reset();
  ModelTaps t;
  for (std::size_t i = begin; i < end; ++i) {
    const auto ev = m.execute_raw(x[i]);
    t.filter.push_back({m.filtered(), m.filter().section_outputs()});
    const auto& b = m.bank();
    if ((b.sample_index() + 1) % b.layout().decimation == 0) {
      for (int j = 0; j < b.layout().codes; ++j) {
        RtlBankBeat beat;
        beat.code = j;
        beat.last = j == b.layout().codes - 1;
        beat.weighted = b.weighted_power()[j];
        beat.energy = b.energy();
        beat.index = b.sample_index();
        beat.chip_re = b.chip_re();
        beat.chip_im = b.chip_im();
        beat.corr_re = b.corr_re()[j];
        beat.corr_im = b.corr_im()[j];
        t.bank.push_back(beat);
      }
    }
    if (ev) t.events.push_back(*ev);
  }
  return t;
}

class Comparer {
 public:
  StageCount stage[kStageCount];
  std::vector<Mismatch> first;  // first mismatch per run and stage (reported: the earliest stage)

  void check(int s, const std::string& run, bool ok, const std::string& where, const std::string& expected,
             const std::string& got) {
    ++stage[s].compared;
    if (ok) return;
    ++stage[s].mismatches;
    if (first_of_run_[s] != run) {
      first.push_back({kStages[s], run, where, expected, got});
      first_of_run_[s] = run;
    }
  }
  void missing(int s, const std::string& run, const std::string& where, std::size_t rtl, std::size_t model) {
    check(s, run, false, where + ": output count", std::to_string(model), std::to_string(rtl));
  }

  // prefix: the segment was cut short by a reset (the RTL may have dropped what was in flight).
  void compare(const std::string& run, int seg, const RtlSegment& r, const ModelTaps& m, bool prefix) {
    const std::string sg = seg ? " after reset" : "";
    const std::size_t nf = std::min(r.filter.size(), m.filter.size());
    for (std::size_t i = 0; i < nf; ++i) {
      const auto& a = r.filter[i];
      const auto& e = m.filter[i];
      const bool ok = a.data == e.data && a.sections == e.sections;
      std::string ex, got;
      if (!ok) {
        std::size_t k = 0;
        while (k < e.sections.size() && k < a.sections.size() && a.sections[k] == e.sections[k]) ++k;
        if (k < e.sections.size()) {
          ex = "section " + std::to_string(k + 1) + " = " + std::to_string(e.sections[k]);
          got = "section " + std::to_string(k + 1) + " = " + std::to_string(a.sections[k]);
        } else {
          ex = std::to_string(e.data);
          got = std::to_string(a.data);
        }
      }
      check(0, run, ok, "filter sample " + std::to_string(i) + sg, ex, got);
    }
    if (r.filter.size() > m.filter.size() || (!prefix && r.filter.size() != m.filter.size())) {
      missing(0, run, "filter" + sg, r.filter.size(), m.filter.size());
    }
    const std::size_t nb = std::min(r.bank.size(), m.bank.size());
    for (std::size_t i = 0; i < nb; ++i) {
      const auto& a = r.bank[i];
      const auto& e = m.bank[i];
      std::ostringstream w;
      w << "sample " << e.index << ", code " << e.code + 1 << sg;
      const std::string at = w.str();
      check(1, run, a.code == e.code && a.last == e.last && a.index == e.index, at,
            "code " + std::to_string(e.code) + " last " + std::to_string(e.last) + " index " + std::to_string(e.index),
            "code " + std::to_string(a.code) + " last " + std::to_string(a.last) + " index " + std::to_string(a.index));
      check(2, run, a.chip_re == e.chip_re && a.chip_im == e.chip_im, at,
            std::to_string(e.chip_re) + " " + std::to_string(e.chip_im) + "j",
            std::to_string(a.chip_re) + " " + std::to_string(a.chip_im) + "j");
      check(3, run, a.corr_re == e.corr_re && a.corr_im == e.corr_im, at,
            std::to_string(e.corr_re) + " " + std::to_string(e.corr_im) + "j",
            std::to_string(a.corr_re) + " " + std::to_string(a.corr_im) + "j");
      check(4, run, a.weighted == e.weighted, at, std::to_string(e.weighted), std::to_string(a.weighted));
      check(5, run, a.energy == e.energy, at, std::to_string(e.energy), std::to_string(a.energy));
    }
    if (r.bank.size() > m.bank.size() || (!prefix && r.bank.size() != m.bank.size())) {
      missing(1, run, "bank beats" + sg, r.bank.size(), m.bank.size());
    }
    const std::size_t ne = std::min(r.events.size(), m.events.size());
    auto ev_text = [](const EventFixed& e) {
      return "{code " + std::to_string(e.code) + ", arrival " + std::to_string(e.arrival) + ", score " +
             std::to_string(e.score) + ", margin " + std::to_string(e.margin) + "}";
    };
    for (std::size_t i = 0; i < ne; ++i) {
      check(6, run, r.events[i] == m.events[i], "event " + std::to_string(i) + sg, ev_text(m.events[i]),
            ev_text(r.events[i]));
    }
    if (r.events.size() > m.events.size() || (!prefix && r.events.size() != m.events.size())) {
      missing(6, run, "events" + sg, r.events.size(), m.events.size());
    }
  }

 private:
  std::string first_of_run_[kStageCount];
};

// A transmit schedule as the paper runs it: code 1..eta, one every `period` samples, received at
// distance d (several bursts in flight at once), ADC-quantized (as tb/tb_receiver_top.cpp).
std::vector<std::int64_t> coded_stream(const ReceiverDesign& d, double distance, double noise, std::uint64_t seed,
                                       int period, double gain) {
  const ExcitationParams ex = receiver_excitation(d.config);
  const double fs = d.config.fs;
  const int eta = d.family.eta();
  ChannelParams ch;
  ch.distance_m = distance;
  ch.gain = gain;
  const std::size_t tof = static_cast<std::size_t>(distance / ch.speed_of_sound * fs);
  const std::size_t n = tof + static_cast<std::size_t>(eta * period) + 3000;
  std::vector<double> sum(n, 0.0);
  for (int j = 0; j < eta; ++j) {
    const auto rx = propagate(bpsk_excitation(d.family.codes[j], ex), ch, fs, n - j * period);
    for (std::size_t k = 0; k < rx.size(); ++k) sum[k + j * period] += rx[k];
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, noise > 0 ? noise : 1.0);
  std::vector<std::int64_t> x;
  for (double v : sum) x.push_back(quantize_input(v + (noise > 0 ? g(rng) : 0.0), d.config.bandpass.input_bits, nullptr));
  return x;
}

std::string fmt_distance(double m) {
  std::ostringstream os;
  os << static_cast<int>(m * 1000 + 0.5) << "mm";
  return os.str();
}

std::vector<RtlStimulus> stimuli(const ReceiverDesign& d, bool soak) {
  std::vector<RtlStimulus> v;
  // A burst spacing that keeps every code's response apart: the longest template plus margin.
  std::size_t tlen = 0;
  for (const auto& t : d.templates) tlen = std::max(tlen, t.size());
  const int period = static_cast<int>(std::max<std::size_t>(1400, tlen + 600));
  const std::vector<double> distances = soak ? std::vector<double>{0.1, 0.2, 0.3, 0.4, 0.55, 0.6, 0.7, 0.8, 0.9, 1.0}
                                             : std::vector<double>{0.15, 0.55, 1.0};
  const std::vector<double> noises = soak ? std::vector<double>{0.0, 0.003} : std::vector<double>{0.003};
  std::uint64_t seed = 11;
  for (double dist : distances) {
    for (double noise : noises) {
      RtlStimulus s;
      s.name = "coded-" + fmt_distance(dist) + (noise > 0 ? "-noise" : "");
      s.seed = seed;
      s.x = coded_stream(d, dist, noise, seed++, period, 0.5);
      v.push_back(std::move(s));
    }
  }
  const int in_w = d.config.bandpass.input_bits;
  const std::int64_t hi = (std::int64_t{1} << (in_w - 1)) - 1, lo = -hi - 1;
  const int n_noise = soak ? 40000 : 4000;
  {
    RtlStimulus s;  // full-scale worst case: +-full-scale noise, a carrier-rate square, clipped bursts
    s.name = "fullscale";
    s.seed = 5;
    std::mt19937_64 rng(3);
    for (int i = 0; i < n_noise; ++i) s.x.push_back((rng() & 1) ? hi : lo);
    const int half = std::max(1, d.config.period() / 2);
    for (int i = 0; i < n_noise; ++i) s.x.push_back(((i / half) % 2) ? hi : lo);
    const auto burst = coded_stream(d, 0.1, 0.0, 1, period, 4.0);
    s.x.insert(s.x.end(), burst.begin(), burst.end());
    v.push_back(std::move(s));
  }
  {
    RtlStimulus s;  // uniformly random samples over the ADC range
    s.name = "random";
    s.seed = 6;
    std::mt19937_64 rng(4);
    std::uniform_int_distribution<std::int64_t> u(lo, hi);
    for (int i = 0; i < n_noise; ++i) s.x.push_back(u(rng));
    v.push_back(std::move(s));
  }
  const auto x = coded_stream(d, 0.4, 0.002, 21, period, 0.5);
  {
    RtlStimulus s;  // random valid gaps and back-pressure
    s.name = "handshake";
    s.valid_prob = 0.6;
    s.ready_prob = 0.3;
    s.seed = 99;
    s.x = x;
    v.push_back(std::move(s));
  }
  {
    RtlStimulus s;  // a reset in the middle of a stream, under gaps and back-pressure
    s.name = "reset";
    s.valid_prob = 0.8;
    s.ready_prob = 0.5;
    s.seed = 17;
    s.reset_at = static_cast<long long>(x.size() / 3);
    s.x = x;
    v.push_back(std::move(s));
  }
  return v;
}

}  // namespace

int cmd_verify(const Args& args) {
  cli::Parser p = command_parser("verify");
  add_config_options(p, {.required = true, .overrides = false, .allow_out_of_spec = false});
  add_rtl_option(p);
  p.option("--out", "DIR", "work folder (IP folder, Verilator build, stimulus; default: under $TMPDIR)");
  p.flag("--soak", "the long run: ten distances, with and without noise, 10x longer noise streams");
  p.flag("--trace", "compile FST tracing in and write OUT/verify_<run>.fst (open with OUT/ip/receiver.gtkw)");
  add_output_options(p, {.json = true, .quiet = true});
  if (!p.parse(args)) return 0;
  const std::string config = p.required("--config");
  const bool quiet = p.has("--quiet");
  const ReceiverConfig cfg = load_config_options(p, "verify");
  check_generatable(cfg);
  const ReceiverDesign design = design_receiver(cfg);

  RtlBuildOptions bo;
  bo.rtl_dir = p.get_or("--rtl", "");
  if (p.has("--rtl") && !std::filesystem::is_directory(bo.rtl_dir)) {
    throw InputError("option --rtl: '" + bo.rtl_dir + "' is not a folder");
  }
  bo.work_dir = p.has("--out") ? std::filesystem::path(*p.get("--out")) : default_work_dir("verify", cfg.name);
  bo.origin = config;
  bo.trace = p.has("--trace");
  bo.quiet = quiet;
  const auto t0 = std::chrono::steady_clock::now();
  const RtlReceiver rtl(design, bo);

  const auto runs = stimuli(design, p.has("--soak"));
  std::size_t total = 0;
  for (const auto& s : runs) total += s.x.size();
  if (!quiet) std::cerr << "running " << runs.size() << " streams (" << total << " samples) through the RTL and the model\n";
  // One driver process per stream: progress with an ETA from the rate so far.
  Comparer cmp;
  std::size_t done = 0;
  const auto t_run = std::chrono::steady_clock::now();
  nlohmann::json run_json = nlohmann::json::array();
  bool stalled = false;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const auto& s = runs[k];
    const RtlResult r = rtl.run({s}).front();
    const std::size_t cut = s.reset_at >= 0 ? static_cast<std::size_t>(s.reset_at) : s.x.size();
    std::vector<ModelTaps> model{model_taps(design, s.x, 0, cut)};
    if (cut < s.x.size()) model.push_back(model_taps(design, s.x, cut, s.x.size()));
    if (r.stalled || r.segments.size() != model.size()) {
      stalled = true;
      cmp.first.push_back({"handshake", s.name, "sample " + std::to_string(r.samples_taken),
                           "all " + std::to_string(s.x.size()) + " samples taken",
                           r.stalled ? "s_axis_tready stuck low" : "reset segments differ"});
    }
    for (std::size_t g = 0; g < std::min(model.size(), r.segments.size()); ++g) {
      cmp.compare(s.name, static_cast<int>(g), r.segments[g], model[g], g + 1 < model.size());
    }
    std::size_t events = 0;
    for (const auto& seg : r.segments) events += seg.events.size();
    run_json.push_back({{"name", s.name}, {"samples", s.x.size()}, {"cycles", r.cycles}, {"events", events},
                        {"valid_prob", s.valid_prob}, {"ready_prob", s.ready_prob}, {"reset_at", s.reset_at}});
    done += s.x.size();
    if (!quiet) {
      const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_run).count();
      const double eta = done ? el * static_cast<double>(total - done) / static_cast<double>(done) : 0;
      std::cerr << "  [" << k + 1 << "/" << runs.size() << "] " << s.name << ": " << s.x.size() << " samples, "
                << events << " events; elapsed " << static_cast<int>(el) << " s, ETA " << static_cast<int>(eta + 0.5)
                << " s\n";
    }
  }

  // The real-time rule (model/hw/realtime.hpp) against the RTL: the first coded stream offered
  // as an ADC would, one sample every clock_hz / fs clocks; a sample the RTL takes after its due
  // cycle is late. A design the rule calls real time must have none.
  const RealTimeBudget budget = realtime_budget(design);
  RtlStimulus paced = runs.front();
  paced.name = "paced-" + paced.name;
  paced.cadence = budget.clocks_per_sample;
  paced.valid_prob = 1.0;
  paced.ready_prob = 1.0;
  paced.reset_at = -1;
  const RtlResult pr = rtl.run({paced}).front();
  const bool rule_rt = budget.real_time;
  const bool rtl_rt = pr.late == 0 && !pr.stalled && pr.samples_taken == paced.x.size();
  const bool rt_ok = !rule_rt || rtl_rt;  // a conservative rule (NOT REAL TIME, RTL keeps up) is no failure
  const std::string rt_text =
      std::string("real-time rule: ") + budget.summary() + "\n  RTL at one sample every " +
      std::to_string(budget.clocks_per_sample) + " clocks (" + paced.name + "): " + std::to_string(pr.late) + " of " +
      std::to_string(paced.x.size()) + " samples late" +
      (rule_rt == rtl_rt ? ": agrees with the rule"
                         : rule_rt ? ": the RTL falls behind a design the rule calls real time (FAIL)"
                                   : ": the RTL keeps up where the rule says it does not (the rule is conservative here)");

  std::uint64_t mismatches = 0;
  for (const auto& st : cmp.stage) mismatches += st.mismatches;
  const bool pass = mismatches == 0 && !stalled && rt_ok;
  // The first mismatch: the earliest stage of the earliest failing run.
  const Mismatch* first = nullptr;
  auto stage_rank = [](const std::string& s) {
    for (int i = 0; i < kStageCount; ++i) {
      if (s == kStages[i]) return i;
    }
    return kStageCount;
  };
  for (const auto& m : cmp.first) {
    if (!first) {
      first = &m;
    } else if (m.run == first->run && stage_rank(m.stage) < stage_rank(first->stage)) {
      first = &m;
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (p.has("--json")) {
    nlohmann::json j;
    stamp_build_info(j);
    j["config"] = cfg.name;
    j["config_file"] = config;
    j["rtl"] = rtl_dir_option(p);
    j["work_dir"] = rtl.work_dir().string();
    j["stages"] = nlohmann::json::array();
    for (int i = 0; i < kStageCount; ++i) {
      j["stages"].push_back({{"name", kStages[i]}, {"compared", cmp.stage[i].compared},
                             {"mismatches", cmp.stage[i].mismatches}});
    }
    j["runs"] = run_json;
    j["realtime"] = {{"rule_real_time", rule_rt},
                     {"rule", budget.summary()},
                     {"clocks_per_sample", budget.clocks_per_sample},
                     {"needed_clocks_per_sample", budget.needed_clocks_per_sample()},
                     {"run", paced.name},
                     {"samples", paced.x.size()},
                     {"late_samples", pr.late},
                     {"rtl_real_time", rtl_rt},
                     {"agree", rule_rt == rtl_rt},
                     {"pass", rt_ok}};
    j["first_mismatch"] = first ? nlohmann::json{{"stage", first->stage}, {"run", first->run}, {"sample", first->where},
                                                 {"expected", first->expected}, {"got", first->got}}
                                : nlohmann::json(nullptr);
    j["pass"] = pass;
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "verify " << cfg.name << " (" << config << "), RTL from "
              << rtl_dir_option(p) << "\n";
    for (int i = 0; i < kStageCount; ++i) {
      std::cout << "  " << kStages[i] << std::string(16 - std::string(kStages[i]).size(), ' ')
                << cmp.stage[i].compared << " compared, " << cmp.stage[i].mismatches << " mismatches\n";
    }
    std::cout << rt_text << "\n";
    if (first) {
      std::cout << "first mismatch: stage " << first->stage << ", run " << first->run << ", " << first->where
                << ": expected " << first->expected << ", got " << first->got << "\n";
    }
    std::cout << (pass ? "PASS" : "FAIL") << ": " << runs.size() << " streams, " << total << " samples in "
              << static_cast<int>(seconds) << " s (work folder " << rtl.work_dir().string() << ")\n";
  }
  return pass ? 0 : 1;
}

}  // namespace ranging::tool
