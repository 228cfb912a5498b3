// rtl/peak_detector.v against PeakDetectorFixed, bit for bit: the detector is driven with the
// model bank's outputs (Q_j, E, n) of streams of filtered Gold4 bursts at many distances, with
// random s_valid gaps, random m_ready back-pressure and a reset in the middle of a stream;
// every event (code, arrival, score, margin) must equal the model's, none lost or duplicated
// (the model's flush() at the end of a stream is not part of the hardware and not compared).
// Also the Verilator lint (-Wall). RANGING_TRACE=1 writes $RANGING_TRACE_DIR/tb_peak_detector.fst.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "model/bandpass_filter.hpp"
#include "model/channel.hpp"
#include "model/excitation.hpp"
#include "model/receiver.hpp"
// Verilator's runtime headers are not warning-clean under -Wextra -Werror.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include "Vpeak_detector.h"
#include "verilated.h"
#include "verilated_fst_c.h"
#pragma GCC diagnostic pop

namespace {

using namespace ranging;

const ReceiverDesign& design() {
  static const ReceiverDesign d = design_receiver(load_receiver_config(RANGING_CONFIG));
  return d;
}

template <std::size_t N>
void set_bits(VlWide<N>& w, int lo, int width, std::uint64_t v) {
  for (int b = 0; b < width; ++b) {
    const int i = lo + b;
    const std::uint32_t m = 1u << (i % 32);
    auto& word = w[static_cast<std::size_t>(i / 32)];
    word = ((v >> b) & 1u) ? (word | m) : (word & ~m);
  }
}
std::int64_t sext(std::uint64_t v, int width) {
  const std::uint64_t m = std::uint64_t{1} << (width - 1);
  return static_cast<std::int64_t>(((v & ((m << 1) - 1)) ^ m) - m);
}

struct Beat {
  std::vector<std::uint64_t> q;
  std::uint64_t energy = 0, index = 0;
};

// Filtered received bursts, one after the other (a new burst every `spacing` samples).
std::vector<std::int64_t> burst_stream(std::uint64_t seed, double noise, std::size_t bursts) {
  const auto& d = design();
  ExcitationParams ex;
  ex.carrier_hz = d.config.carrier_hz;
  ex.cycles_per_chip = d.config.cycles_per_chip;
  ex.fs = d.config.fs;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> dist_mm(100, 1000), gain(0.05, 0.8);
  BandpassFixed bp(d.filter, d.config.bandpass);
  OverflowCounter oc;
  std::vector<std::int64_t> y;
  for (std::size_t b = 0; b < bursts; ++b) {
    const auto exc = bpsk_excitation(d.family.codes.at(b % d.family.codes.size()), ex);
    ChannelParams ch;
    ch.distance_m = dist_mm(rng) / 1000.0;
    ch.gain = gain(rng);
    ch.noise_rms = noise;
    ch.seed = seed * 1000 + b;
    const std::size_t arrival = static_cast<std::size_t>(ch.distance_m / ch.speed_of_sound * d.config.fs);
    const auto rx = propagate(exc, ch, d.config.fs, arrival + 2600);
    const std::size_t start = arrival > 900 ? arrival - 900 : 0;
    for (std::size_t n = start; n < rx.size(); ++n) {
      y.push_back(bp.execute_raw(quantize_input(rx[n], d.config.bandpass.input_bits, &oc)));
    }
  }
  return y;
}

// The bank model's outputs for y, and the detector model's events on them (beats [0, split)
// with one detector, beats [split, end) with a freshly reset one).
void model(const std::vector<std::int64_t>& y, std::size_t split, std::vector<Beat>& beats,
           std::vector<EventFixed>& events, std::size_t& events_before_split) {
  const auto& d = design();
  CorrelatorBankFixed bank(d.reference, d.config.correlator);
  PeakDetectorFixed det(d.config.detector, bank.layout(), d.config.correlator);
  events_before_split = 0;
  for (std::int64_t v : y) {
    if (!bank.execute(v)) continue;
    if (beats.size() == split) {
      events_before_split = events.size();
      det.reset();
    }
    beats.push_back({bank.weighted_power(), bank.energy(), static_cast<std::uint64_t>(bank.sample_index())});
    if (auto e = det.execute(bank)) events.push_back(*e);
  }
  if (split >= beats.size()) events_before_split = events.size();
}

class DetSim {
 public:
  DetSim() : ctx_(std::make_unique<VerilatedContext>()), top_(std::make_unique<Vpeak_detector>(ctx_.get())) {
    const char* tr = std::getenv("RANGING_TRACE");
    if (tr && std::string(tr) == "1") {
      ctx_->traceEverOn(true);
      trace_ = std::make_unique<VerilatedFstC>();
      top_->trace(trace_.get(), 99);
      const char* dir = std::getenv("RANGING_TRACE_DIR");
      trace_->open((std::string(dir ? dir : RANGING_TRACE_DIR) + "/tb_peak_detector.fst").c_str());
    }
    top_->clk = 0;
    top_->rst = 1;
    top_->s_valid = 0;
    top_->m_ready = 0;
    top_->eval();
  }
  ~DetSim() {
    if (trace_) trace_->close();
    top_->final();
  }
  Vpeak_detector& top() { return *top_; }
  void tick() {
    top_->clk = 1;
    top_->eval();
    if (trace_) trace_->dump(time_++);
    top_->clk = 0;
    top_->eval();
    if (trace_) trace_->dump(time_++);
  }
  void reset() {
    top_->rst = 1;
    top_->s_valid = 0;
    tick();
    tick();
    top_->rst = 0;
    top_->eval();
  }

 private:
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<Vpeak_detector> top_;
  std::unique_ptr<VerilatedFstC> trace_;
  std::uint64_t time_ = 0;
};

struct Totals {
  std::uint64_t inputs = 0, beats = 0, events = 0, mismatches = 0;
  std::string first;
};

void run_stream(DetSim& sim, const std::vector<std::int64_t>& y, double gap, double stall,
                std::mt19937_64& rng, const std::string& what, Totals& tot) {
  const auto& d = design();
  const int ww = d.layout.weighted_bits, fb = d.config.detector.frac_bits;
  std::vector<Beat> beats;
  std::vector<EventFixed> events;
  std::size_t before = 0;
  std::uniform_real_distribution<double> u(0, 1);
  const std::size_t split = (y.size() / d.layout.decimation) / 2;
  model(y, split, beats, events, before);
  tot.inputs += y.size();
  sim.reset();
  std::size_t in = 0, got = 0;
  bool presenting = false, did_reset = false;
  std::uint64_t cycles = 0;
  auto fail = [&](const std::string& msg) {
    ++tot.mismatches;
    if (tot.first.empty()) tot.first = what + ": " + msg;
  };
  bool holding = false;
  EventFixed held;
  while (in < beats.size() || got < events.size() || holding) {
    auto& t = sim.top();
    if (!did_reset && in == split) {
      // Drain what the first half produced, then reset in the middle of the stream.
      if (got == before && t.s_ready && !t.m_valid) {
        sim.reset();
        did_reset = true;
        presenting = false;
        continue;
      }
    } else if (!presenting && in < beats.size()) {
      presenting = u(rng) >= gap;
    }
    t.s_valid = presenting ? 1 : 0;
    if (in < beats.size()) {
      for (std::size_t j = 0; j < beats[in].q.size(); ++j) {
        set_bits(t.s_weighted, static_cast<int>(j) * ww, ww, beats[in].q[j]);
      }
      t.s_energy = beats[in].energy;
      t.s_index = beats[in].index;
    }
    t.m_ready = u(rng) >= stall ? 1 : 0;
    t.eval();
    if (t.m_valid) {
      EventFixed g;
      g.code = t.m_code;
      g.arrival = sext(t.m_arrival, 40 + fb + 1);
      g.score = t.m_score;
      g.margin = t.m_margin;
      if (holding && !(g == held)) fail("event changed while m_valid && !m_ready");
      held = g;
      holding = !t.m_ready;
      if (t.m_ready) {
        if (got >= events.size()) {
          fail("extra event code " + std::to_string(g.code) + " arrival " + std::to_string(g.arrival));
        } else if (!(g == events[got])) {
          const auto& e = events[got];
          std::ostringstream os;
          os << "event " << got << ": model {code " << e.code << ", arrival " << e.arrival << ", score "
             << e.score << ", margin " << e.margin << "} rtl {code " << g.code << ", arrival " << g.arrival
             << ", score " << g.score << ", margin " << g.margin << "}";
          fail(os.str());
        }
        ++got;
        ++tot.events;
      }
    }
    if (t.s_valid && t.s_ready) {
      ++in;
      ++tot.beats;
      presenting = false;
    }
    sim.tick();
    if (++cycles > 400 * (beats.size() + 10)) {
      fail("timeout: " + std::to_string(got) + " of " + std::to_string(events.size()) + " events");
      break;
    }
  }
  // A few idle cycles: nothing else may come out.
  for (int i = 0; i < 400; ++i) {
    sim.top().m_ready = 1;
    sim.top().eval();
    if (sim.top().m_valid) fail("event after the model's last one");
    sim.tick();
  }
}

TEST(PeakDetectorRtl, EventsBitExactUnderGapsBackPressureAndReset) {
  DetSim sim;
  std::mt19937_64 rng(777);
  Totals tot;
  const double gaps[] = {0.0, 0.4, 0.1};
  const double stalls[] = {0.0, 0.5, 0.9};
  for (int s = 0; s < 3; ++s) {
    const auto y = burst_stream(100 + static_cast<std::uint64_t>(s), s == 1 ? 0.01 : 0.002, 27);
    run_stream(sim, y, gaps[s], stalls[s], rng, "stream " + std::to_string(s), tot);
  }
  std::printf("peak_detector: %llu input samples (model bank), %llu beats, %llu events compared, %llu mismatches\n",
              static_cast<unsigned long long>(tot.inputs), static_cast<unsigned long long>(tot.beats),
              static_cast<unsigned long long>(tot.events), static_cast<unsigned long long>(tot.mismatches));
  EXPECT_EQ(tot.mismatches, 0u) << tot.first;
  EXPECT_GT(tot.events, 50u);
}

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(PeakDetectorRtl, VerilatorLintIsClean) {
  const std::string vc = std::string(RANGING_GENERATED_DIR) + "/rtl/peak_detector.vc";
  const std::string rtl = std::string(RANGING_SOURCE_DIR) + "/rtl/peak_detector.v";
  const std::string log = std::string(RANGING_TRACE_DIR) + "/tb_peak_detector_lint.log";
  const int rc = std::system(("verilator --lint-only -Wall -f " + vc + " " + rtl + " > " + log + " 2>&1").c_str());
  const std::string out = slurp(log);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_EQ(out.find("%Warning"), std::string::npos) << out;
  EXPECT_EQ(out.find("%Error"), std::string::npos) << out;
}

}  // namespace
