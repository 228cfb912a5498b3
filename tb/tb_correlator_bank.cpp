// rtl/correlator_bank.v against CorrelatorBankFixed, bit for bit, on every decimated output:
// Q_j of every code, E, the sample index, F_q (chip filter) and C_q of every code. The bank
// sends an output as a group of CODES beats (docs: notes/serial.md): the testbench gathers
// them and checks the framing (m_code = j, m_last on the last beat only, E / n / F equal on
// every beat of a group) and that a beat does not change while m_valid && !m_ready.
// Inputs: the default design's filtered received bursts of every Gold4 code at 100, 550 and
// 1000 mm with and without noise, full-scale worst-case inputs and random noise, with random
// s_valid gaps, random m_ready back-pressure and resets in the middle of a stream. Also the
// Verilator lint (-Wall) and an Icarus run of the same module on vectors from the model.
// RANGING_TRACE=1 writes $RANGING_TRACE_DIR/tb_correlator_bank.fst.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "model/config/receiver_config.hpp"
#include "model/dsp/bandpass_filter.hpp"
#include "model/dsp/correlator_headroom.hpp"
#include "model/sim/channel.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/receiver.hpp"
// Verilator's runtime headers are not warning-clean under -Wextra -Werror.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include "Vcorrelator_bank.h"
#include "tb/generated_params.hpp"
#include "tb/verilator_harness.hpp"
#pragma GCC diagnostic pop

namespace {

using namespace ranging;

const ReceiverDesign& design() { return tb::configured_design(); }

struct Output {
  std::vector<std::uint64_t> q;
  std::uint64_t energy = 0, index = 0;
  std::int64_t chip_re = 0, chip_im = 0;
  std::vector<std::int64_t> corr_re, corr_im;
};

// One beat of the m_* stream (code j of one output).
struct Beat {
  std::uint64_t q = 0, code = 0, energy = 0, index = 0;
  bool last = false;
  std::int64_t chip_re = 0, chip_im = 0, corr_re = 0, corr_im = 0;
  bool operator==(const Beat&) const = default;
};

// Gathers the beats of a group into an Output and checks the framing.
class GroupCollector {
 public:
  explicit GroupCollector(std::size_t codes) : codes_(codes) {}
  void clear() { out_ = Output{}; }
  // Adds a taken beat; returns a framing error ("" if none); *done when the group is complete.
  std::string add(const Beat& b, bool* done) {
    *done = false;
    const std::size_t j = out_.q.size();
    std::ostringstream os;
    if (b.code != j) os << "beat " << j << " of a group has m_code " << b.code;
    else if (b.last != (j + 1 == codes_)) os << "beat " << j << " of a group has m_last " << b.last;
    else if (j > 0 && (b.energy != out_.energy || b.index != out_.index || b.chip_re != out_.chip_re ||
                       b.chip_im != out_.chip_im))
      os << "beat " << j << ": energy/index/chip differ from beat 0 of the group";
    if (!os.str().empty()) {
      clear();  // resynchronise on the next group
      return os.str();
    }
    if (j == 0) {
      out_.energy = b.energy;
      out_.index = b.index;
      out_.chip_re = b.chip_re;
      out_.chip_im = b.chip_im;
    }
    out_.q.push_back(b.q);
    out_.corr_re.push_back(b.corr_re);
    out_.corr_im.push_back(b.corr_im);
    *done = b.last;
    return "";
  }
  Output take() {
    Output o = std::move(out_);
    clear();
    return o;
  }

 private:
  std::size_t codes_;
  Output out_;
};

// The model's decimated outputs for a stream from reset.
std::vector<Output> model_outputs(const std::vector<std::int64_t>& y) {
  const auto& d = design();
  CorrelatorBankFixed bank(d.reference, d.config.correlator);
  std::vector<Output> out;
  for (std::int64_t v : y) {
    if (!bank.execute(v)) continue;
    Output o;
    o.q = bank.weighted_power();
    o.energy = bank.energy();
    o.index = static_cast<std::uint64_t>(bank.sample_index());
    o.chip_re = bank.chip_re();
    o.chip_im = bank.chip_im();
    o.corr_re = bank.corr_re();
    o.corr_im = bank.corr_im();
    out.push_back(std::move(o));
  }
  return out;
}

// Filtered received burst of code j at distance_mm (bandpass model over the ADC codes).
std::vector<std::int64_t> filtered_burst(std::size_t code, double distance_mm, double noise,
                                         std::uint64_t seed, std::size_t* arrival) {
  const auto& d = design();
  const ExcitationParams ex = receiver_excitation(d.config);
  const auto exc = bpsk_excitation(d.family.codes.at(code), ex);
  ChannelParams ch;
  ch.distance_m = distance_mm / 1000.0;
  ch.gain = 0.5;
  ch.noise_rms = noise;
  ch.seed = seed;
  const double delay = ch.distance_m / ch.speed_of_sound * d.config.fs;
  *arrival = static_cast<std::size_t>(delay);
  const auto rx = propagate(exc, ch, d.config.fs, *arrival + 2600);
  BandpassFixed bp(d.filter, d.config.bandpass);
  OverflowCounter oc;
  std::vector<std::int64_t> y;
  y.reserve(rx.size());
  for (double v : rx) y.push_back(bp.execute_raw(quantize_input(v, d.config.bandpass.input_bits, &oc)));
  return y;
}

// The Verilated bank on the shared harness (tb/verilator_harness.hpp), plus a beat reader.
class BankSim : public tb::StreamHarness<Vcorrelator_bank> {
 public:
  BankSim() : StreamHarness("tb_correlator_bank") {}
  Beat read() const {
    const auto& c = design().config.correlator;
    const auto& t = top();
    Beat b;
    b.q = t.m_weighted;
    b.code = t.m_code;
    b.last = t.m_last != 0;
    b.energy = t.m_energy;
    b.index = t.m_index;
    b.chip_re = tb::sign_extend(t.m_chip_re, c.chip_bits);
    b.chip_im = tb::sign_extend(t.m_chip_im, c.chip_bits);
    b.corr_re = tb::sign_extend(t.m_corr_re, c.corr_bits);
    b.corr_im = tb::sign_extend(t.m_corr_im, c.corr_bits);
    return b;
  }
};

// First differing stage of one output, or "" when equal.
std::string compare(const Output& e, const Output& g) {
  std::ostringstream os;
  if (e.chip_re != g.chip_re || e.chip_im != g.chip_im) {
    os << "chip filter F: model (" << e.chip_re << "," << e.chip_im << ") rtl (" << g.chip_re << ","
       << g.chip_im << ")";
    return os.str();
  }
  for (std::size_t j = 0; j < e.q.size(); ++j) {
    if (e.corr_re[j] != g.corr_re[j] || e.corr_im[j] != g.corr_im[j]) {
      os << "combiner C code " << j + 1 << ": model (" << e.corr_re[j] << "," << e.corr_im[j]
         << ") rtl (" << g.corr_re[j] << "," << g.corr_im[j] << ")";
      return os.str();
    }
  }
  for (std::size_t j = 0; j < e.q.size(); ++j) {
    if (e.q[j] != g.q[j]) {
      os << "weighted power Q code " << j + 1 << ": model " << e.q[j] << " rtl " << g.q[j];
      return os.str();
    }
  }
  if (e.energy != g.energy) {
    os << "energy: model " << e.energy << " rtl " << g.energy;
    return os.str();
  }
  if (e.index != g.index) {
    os << "index: model " << e.index << " rtl " << g.index;
    return os.str();
  }
  return "";
}

struct Totals {
  std::uint64_t inputs = 0, outputs = 0, mismatches = 0, cycles = 0;
  std::string first;
};
Totals g_totals;

struct RunOpts {
  double gap = 0.0;    // probability of no s_valid in a cycle
  double stall = 0.0;  // probability of m_ready low
  std::int64_t reset_after_inputs = -1;  // assert rst mid-stream after this many inputs
};

// Feeds y from reset; compares every output with the model (for a mid-stream reset: the
// outputs before it with the first stream's model, then a fresh model on the rest).
void run(BankSim& sim, const std::vector<std::int64_t>& y, const RunOpts& o, std::mt19937_64& rng,
         const std::string& what) {
  std::uniform_real_distribution<double> u(0, 1);
  sim.reset();
  std::vector<std::int64_t> seg = y;
  std::size_t consumed_before_reset = 0;
  bool did_reset = o.reset_after_inputs < 0;
  std::vector<Output> exp = model_outputs(seg);
  std::size_t in = 0, k = 0;
  bool presenting = false;
  std::uint64_t guard = 0;
  Beat held;
  bool holding = false;
  GroupCollector groups(static_cast<std::size_t>(design().layout.codes));
  auto fail = [&](const std::string& msg) {
    ++g_totals.mismatches;
    if (g_totals.first.empty()) g_totals.first = what + ": " + msg;
  };
  const std::uint64_t max_cycles = 200 * y.size() + 10000;
  while (in < seg.size() || k < exp.size()) {
    auto& t = sim.top();
    if (!did_reset && static_cast<std::int64_t>(in) >= o.reset_after_inputs && u(rng) < 0.3) {
      // Reset at an arbitrary cycle (outputs in flight are dropped): the rest is a new stream.
      consumed_before_reset += in;
      seg.assign(y.begin() + static_cast<std::ptrdiff_t>(in), y.end());
      sim.reset();
      exp = model_outputs(seg);
      in = 0;
      k = 0;
      presenting = false;
      holding = false;
      groups.clear();
      did_reset = true;
      continue;
    }
    if (!presenting && in < seg.size()) presenting = u(rng) >= o.gap;
    t.s_valid = presenting ? 1 : 0;
    t.s_data = static_cast<std::uint16_t>(in < seg.size() ? seg[in] : 0) & 0xffffu;
    t.m_ready = u(rng) >= o.stall ? 1 : 0;
    t.eval();
    if (holding && !t.m_valid) fail("m_valid dropped before the beat was taken");
    if (t.m_valid) {
      const Beat b = sim.read();
      if (holding && !(held == b)) fail("beat changed while m_valid && !m_ready");
      held = b;
      holding = !t.m_ready;
      bool done = false;
      if (t.m_ready) {
        const std::string framing = groups.add(b, &done);
        if (!framing.empty()) fail("output " + std::to_string(k) + ": " + framing);
      }
      if (done) {
        const Output g = groups.take();
        if (k >= exp.size()) {
          fail("more outputs than the model");
        } else {
          const std::string diff = compare(exp[k], g);
          if (!diff.empty()) {
            fail("output " + std::to_string(k) + " (input sample " + std::to_string(exp[k].index) +
                 "): first stage differing: " + diff);
          }
        }
        ++k;
        ++g_totals.outputs;
      }
    }
    if (t.s_valid && t.s_ready) {
      ++in;
      presenting = false;
    }
    sim.tick();
    if (++guard > max_cycles) {
      ++g_totals.mismatches;
      if (g_totals.first.empty()) {
        g_totals.first = what + ": timeout after " + std::to_string(in) + " inputs, " +
                         std::to_string(k) + " of " + std::to_string(exp.size()) + " outputs";
      }
      break;
    }
  }
  g_totals.inputs += consumed_before_reset + in;
  g_totals.cycles += guard;
}

TEST(CorrelatorBankRtl, BitExactOnCodedBurstsAndWorstCase) {
  const auto& d = design();
  ASSERT_EQ(d.family.codes.size(), 9u) << "the generated parameters hold the Gold4 codes";
  BankSim sim;
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(0, 1);
  const std::array<double, 3> distances{100, 550, 1000};
  std::uint64_t seed = 7;
  int case_no = 0;
  for (std::size_t j = 0; j < d.family.codes.size(); ++j) {
    for (double dist : distances) {
      for (double noise : {0.0, 0.01}) {
        std::size_t arrival = 0;
        const auto y = filtered_burst(j, dist, noise, ++seed, &arrival);
        // From a little before the arrival to the end: the bank sees silence, burst and tail.
        const std::size_t start = arrival > 1100 ? arrival - 1100 : 0;
        std::vector<std::int64_t> seg(y.begin() + static_cast<std::ptrdiff_t>(start), y.end());
        RunOpts o;
        if (case_no % 3 == 1) {
          o.gap = 0.3;
          o.stall = 0.3;
        }
        if (case_no % 7 == 3) o.reset_after_inputs = 1500 + case_no;
        ++case_no;
        run(sim, seg, o, rng,
            "code " + std::to_string(j + 1) + " at " + std::to_string(static_cast<int>(dist)) +
                " mm noise " + std::to_string(noise));
      }
    }
  }
  // Full-scale worst case: +-full scale in phase with the LO, chip-modulated by code 1 (largest
  // mixer, decimator, chip filter and combiner magnitudes; saturating corr words).
  const int data_bits = d.config.correlator.data_bits;
  const std::int64_t top = (std::int64_t{1} << (data_bits - 1)) - 1, bottom = -top - 1;
  for (int variant = 0; variant < 3; ++variant) {
    std::vector<std::int64_t> y;
    const int p = d.layout.period, nc = d.layout.chip_samples;
    for (int rep = 0; rep < 4; ++rep) {
      for (std::size_t c = 0; c < d.family.codes[variant].size(); ++c) {
        for (int n = 0; n < nc; ++n) {
          const int ph = static_cast<int>(y.size()) % p;
          const bool pos = (ph < p / 2) == (d.family.codes[variant][c] != 0);
          y.push_back(variant == 2 ? bottom : (pos ? top : bottom));
        }
      }
    }
    RunOpts o;
    o.stall = variant == 1 ? 0.5 : 0.0;
    run(sim, y, o, rng, "full-scale worst case " + std::to_string(variant));
  }
  // Random full-range noise with gaps, back-pressure and a mid-stream reset.
  for (int r = 0; r < 2; ++r) {
    std::uniform_int_distribution<std::int64_t> full(bottom, top);
    std::vector<std::int64_t> y(12000);
    for (auto& v : y) v = full(rng);
    RunOpts o;
    o.gap = 0.2 * r;
    o.stall = 0.2 * r;
    o.reset_after_inputs = r == 1 ? 5000 : -1;
    run(sim, y, o, rng, "random noise " + std::to_string(r));
  }
  std::printf("correlator_bank: %llu input samples, %llu decimated outputs compared, %llu mismatches"
              " (%llu cycles, %.2f cycles per input sample)\n",
              static_cast<unsigned long long>(g_totals.inputs),
              static_cast<unsigned long long>(g_totals.outputs),
              static_cast<unsigned long long>(g_totals.mismatches),
              static_cast<unsigned long long>(g_totals.cycles),
              static_cast<double>(g_totals.cycles) / static_cast<double>(g_totals.inputs));
  EXPECT_EQ(g_totals.mismatches, 0u) << g_totals.first;
  // every run is compared to its end: about one output per DECIM inputs
  EXPECT_GT(g_totals.outputs, g_totals.inputs / static_cast<std::uint64_t>(2 * d.layout.decimation));
}

// Issue 12 section 4: every node's own worst-case input (model/dsp/correlator_headroom.hpp: the
// full-scale sign sequence of the node's sensitivity, re and im, both polarities, every code for
// the combiner) through the RTL, which must equal the model on every output, including the
// chip filter's saturations that the worst case provokes.
TEST(CorrelatorBankRtl, BitExactOnEveryNodesWorstCase) {
  const auto& d = design();
  const auto& cfg = d.config.correlator;
  BankSim sim;
  std::mt19937_64 rng(99);
  const Totals before = g_totals;
  std::uint64_t saturating_runs = 0;
  int case_no = 0;
  auto drive = [&](BankNode n, int code, bool im, bool neg) {
    const std::vector<std::int64_t> y = correlator_worst_case(d.reference, cfg, n, code, im, neg);
    CorrelatorBankFixed probe(d.reference, cfg);
    for (std::int64_t v : y) probe.execute(v);
    if (probe.overflow_events().total() > 0) ++saturating_runs;
    RunOpts o;
    if (case_no++ % 2 == 1) {
      o.gap = 0.3;
      o.stall = 0.3;
    }
    run(sim, y, o, rng, std::string(bank_node_name(n)) + " worst case, code " + std::to_string(code + 1) +
                            (im ? " im" : " re") + (neg ? " negated" : ""));
  };
  for (bool neg : {false, true}) {
    for (bool im : {false, true}) {
      for (BankNode n : {BankNode::Mixer, BankNode::Decimator, BankNode::ChipFir}) drive(n, 0, im, neg);
      for (int j = 0; j < static_cast<int>(d.family.codes.size()); ++j) drive(BankNode::CorrQ, j, im, neg);
    }
    drive(BankNode::Energy, 0, false, neg);
  }
  std::printf("correlator_bank worst cases: %llu input samples, %llu outputs compared, %llu runs saturating\n",
              static_cast<unsigned long long>(g_totals.inputs - before.inputs),
              static_cast<unsigned long long>(g_totals.outputs - before.outputs),
              static_cast<unsigned long long>(saturating_runs));
  EXPECT_EQ(g_totals.mismatches, before.mismatches) << g_totals.first;
  EXPECT_GT(g_totals.outputs - before.outputs, 0u);
  // The RTL saw the saturations the headroom analysis predicts (F_q at the default words).
  bool predicted = false;
  for (const auto& h : correlator_headroom(d.reference, cfg)) predicted |= !h.exact && h.headroom_bits < 0;
  EXPECT_EQ(saturating_runs > 0, predicted);
}

// Throughput at the default configuration: one input every 6 clocks (5 MS/s at 30 MHz). The
// bank must accept every sample on the clock it is presented (never stall the stream) and
// still match the model on every output, both with the output always taken and with a
// consumer like the peak detector: it takes the beats of a group one per clock, then is busy
// (m_ready low) for kBusy clocks after each group's last beat (~110 clocks per group; 101 is
// the detector's worst group, with an event, measured by tb_peak_detector).
TEST(CorrelatorBankRtl, SustainsOneSampleEverySixClocks) {
  const auto& d = design();
  ASSERT_EQ(d.layout.decimation, 20) << "the throughput target is for the default configuration";
  constexpr int kClocksPerSample = 6;
  constexpr int kBusy = 101;
  std::vector<std::int64_t> y;
  for (std::size_t j : {0u, 4u, 8u}) {  // three coded bursts back to back
    std::size_t arrival = 0;
    const auto b = filtered_burst(j, 550, 0.01, 100 + j, &arrival);
    y.insert(y.end(), b.begin() + static_cast<std::ptrdiff_t>(arrival > 300 ? arrival - 300 : 0), b.end());
  }
  const auto exp = model_outputs(y);
  ASSERT_GT(exp.size(), 300u);
  for (int busy : {0, kBusy}) {
    SCOPED_TRACE("consumer busy " + std::to_string(busy) + " clocks after each group");
    BankSim sim;
    sim.reset();
    auto& t = sim.top();
    GroupCollector groups(static_cast<std::size_t>(d.layout.codes));
    std::size_t in = 0, k = 0, refused = 0, mism = 0;
    std::string first;
    std::uint64_t clk = 0, last_out_clk = 0;
    int busy_left = 0;
    const std::uint64_t limit = static_cast<std::uint64_t>(kClocksPerSample) * y.size() + 2000;
    while ((in < y.size() || k < exp.size()) && clk < limit) {
      const bool present = in < y.size() && clk % kClocksPerSample == 0;
      t.s_valid = present ? 1 : 0;
      t.s_data = static_cast<std::uint16_t>(present ? y[in] : 0) & 0xffffu;
      t.m_ready = busy_left == 0 ? 1 : 0;
      t.eval();
      if (present) {
        if (t.s_ready) ++in; else ++refused;  // a refused sample is lost for a real-time ADC
      }
      if (busy_left > 0) --busy_left;
      if (t.m_valid && t.m_ready) {
        bool done = false;
        const std::string framing = groups.add(sim.read(), &done);
        if (!framing.empty() && ++mism == 1) first = "output " + std::to_string(k) + ": " + framing;
        if (done) {
          busy_left = busy;
          if (k < exp.size()) {
            const std::string diff = compare(exp[k], groups.take());
            if (!diff.empty() && ++mism == 1) first = "output " + std::to_string(k) + ": " + diff;
          } else if (++mism == 1) {
            first = "more outputs than the model";
          }
          ++k;
          last_out_clk = clk;
        }
      }
      sim.tick();
      ++clk;
    }
    std::printf("correlator_bank throughput (consumer busy %d clocks per group): %zu samples at 1 per"
                " %d clocks, %zu refused, %zu outputs, last output %llu clocks after the last sample"
                " was presented\n",
                busy, in, kClocksPerSample, refused, k,
                static_cast<unsigned long long>(last_out_clk - kClocksPerSample * (y.size() - 1)));
    EXPECT_EQ(refused, 0u) << "the bank stalled the 5 MS/s stream";
    EXPECT_EQ(in, y.size());
    EXPECT_EQ(k, exp.size());
    EXPECT_EQ(mism, 0u) << first;
  }
}

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

const std::string kVc = std::string(RANGING_GENERATED_DIR) + "/rtl/correlator_bank.vc";
// The module and the quantizer it instantiates.
const std::string kRtl =
    std::string(RANGING_SOURCE_DIR) + "/rtl/correlator_bank.v " + std::string(RANGING_SOURCE_DIR) + "/rtl/fx_quantize.v";

TEST(CorrelatorBankRtl, VerilatorLintIsClean) {
  const std::string log = std::string(RANGING_TRACE_DIR) + "/tb_correlator_bank_lint.log";
  const std::string cmd = "verilator --lint-only -Wall -f " + kVc + " " + kRtl + " > " + log + " 2>&1";
  const int rc = std::system(cmd.c_str());
  const std::string out = slurp(log);
  EXPECT_EQ(rc, 0) << out;
  EXPECT_EQ(out.find("%Warning"), std::string::npos) << out;
  EXPECT_EQ(out.find("%Error"), std::string::npos) << out;
}

// Bits of several fields packed LSB first, as hex (what $readmemh reads into one word).
struct Packer {
  std::vector<bool> bits;
  void add(std::uint64_t v, int width) {
    for (int b = 0; b < width; ++b) bits.push_back(b < 64 && ((v >> b) & 1u));
  }
  std::string hex() const {
    std::string s;
    const std::size_t digits = (bits.size() + 3) / 4;
    for (std::size_t dd = digits; dd-- > 0;) {
      int nib = 0;
      for (int b = 3; b >= 0; --b) {
        const std::size_t i = dd * 4 + static_cast<std::size_t>(b);
        nib = nib * 2 + (i < bits.size() && bits[i] ? 1 : 0);
      }
      s += "0123456789abcdef"[nib];
    }
    return s;
  }
};

// The bank's parameters as the generator writes them into the .vc (tb/generated_params.hpp).
HwModuleParams bank_params() { return tb::generated_module(design(), "correlator_bank"); }

// module iv_top instantiating the Icarus testbench with the generated parameters.
std::string iverilog_wrapper(const std::string& tb_module, const std::vector<std::string>& extra) {
  std::string params;
  for (const auto& e : extra) params += (params.empty() ? "" : ",\n    ") + e;
  for (const auto& [name, value] : tb::verilog_params(bank_params())) params += ",\n    ." + name + "(" + value + ")";
  return "module iv_top;\n  " + tb_module + " #(\n    " + params + "\n  ) tb();\nendmodule\n";
}

TEST(CorrelatorBankRtl, IcarusSimulationMatchesModel) {
  const auto& d = design();
  const auto& l = d.layout;
  const auto& c = d.config.correlator;
  std::size_t arrival = 0;
  auto y = filtered_burst(2, 100, 0.01, 99, &arrival);
  std::vector<std::int64_t> seg(y.begin() + static_cast<std::ptrdiff_t>(arrival - 300),
                                y.begin() + static_cast<std::ptrdiff_t>(arrival + 1700));
  const auto exp = model_outputs(seg);
  const int code_bits = static_cast<int>(bank_params().value("CODE_W"));
  std::size_t beats = 0;
  const std::string dir = std::string(RANGING_TRACE_DIR) + "/iverilog_rtlbank/correlator_bank";
  std::filesystem::create_directories(dir);
  {
    std::ofstream vin(dir + "/in.hex"), vout(dir + "/out.hex");
    for (std::int64_t v : seg) {
      Packer p;
      p.add(static_cast<std::uint64_t>(v), c.data_bits);
      vin << p.hex() << "\n";
    }
    // one word per beat: {corr_im, corr_re, chip_im, chip_re, index, energy, last, code, weighted}
    for (const auto& o : exp) {
      for (std::size_t j = 0; j < o.q.size(); ++j) {
        Packer p;
        p.add(o.q[j], l.weighted_bits);
        p.add(j, code_bits);
        p.add(j + 1 == o.q.size() ? 1u : 0u, 1);
        p.add(o.energy, l.energy_bits);
        p.add(o.index, 40);
        p.add(static_cast<std::uint64_t>(o.chip_re), c.chip_bits);
        p.add(static_cast<std::uint64_t>(o.chip_im), c.chip_bits);
        p.add(static_cast<std::uint64_t>(o.corr_re[j]), c.corr_bits);
        p.add(static_cast<std::uint64_t>(o.corr_im[j]), c.corr_bits);
        vout << p.hex() << "\n";
        ++beats;
      }
    }
    std::ofstream w(dir + "/wrapper.v");
    w << iverilog_wrapper("correlator_bank_iverilog_tb",
                         {".N_IN(" + std::to_string(seg.size()) + ")", ".N_OUT(" + std::to_string(beats) + ")"});
  }
  const std::string tb = std::string(RANGING_SOURCE_DIR) + "/tb/correlator_bank_iverilog_tb.v";
  const std::string log = dir + "/sim.log";
  const std::string cmd = "cd " + dir + " && iverilog -g2012 -s iv_top -o sim.vvp wrapper.v " + tb + " " +
                          kRtl + " > " + log + " 2>&1 && vvp -n sim.vvp +vin=in.hex +vout=out.hex >> " +
                          log + " 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(log);
  const std::string out = slurp(log);
  const auto pos = out.find("RESULT");
  ASSERT_NE(pos, std::string::npos) << out;
  unsigned long outputs = 0, mism = 0, xs = 0;
  ASSERT_EQ(std::sscanf(out.c_str() + pos, "RESULT outputs=%lu mismatches=%lu xs=%lu", &outputs, &mism, &xs), 3)
      << out;
  std::printf("correlator_bank (Icarus): %zu input samples, %lu beats (%zu outputs) compared, %lu mismatches\n",
              seg.size(), outputs, exp.size(), mism);
  EXPECT_EQ(outputs, beats) << out;
  EXPECT_EQ(mism, 0u) << out;
  EXPECT_EQ(xs, 0u) << out;
}

}  // namespace
