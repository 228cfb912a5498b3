// rtl/bandpass_sos.v against the golden model BandpassFixed, bit for bit: every output
// sample and every section output (m_sections), for coded echoes, the worst-case input,
// full-scale noise, steps and impulses, with random gaps on s_valid, random back-pressure on
// m_ready and resets in the middle of a stream. The Verilated module takes the parameters
// the generator wrote for configs/default.yaml (.vc). Also: Verilator -Wall lint, and an
// Icarus Verilog run of model vectors for the default and for other rounding / overflow /
// width / b1 != 0 configurations (self-checking Verilog testbench written into the build tree).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "Vbandpass_sos.h"
#include "model/config/receiver_config.hpp"
#include "model/dsp/bandpass_filter.hpp"
#include "model/sim/channel.hpp"
#include "model/dsp/codes.hpp"
#include "model/dsp/excitation.hpp"
#include "model/hw/hw_params.hpp"
#include "model/dsp/receiver.hpp"
#include "tb/generated_params.hpp"
#include "tb/verilator_harness.hpp"

namespace {

using namespace ranging;
using Dut = Vbandpass_sos;

const ReceiverDesign& default_design() { return tb::configured_design(); }

std::uint64_t g_total_compared = 0;

class TotalReport : public ::testing::Environment {
 public:
  void TearDown() override {
    std::cout << "bandpass_sos: " << g_total_compared << " samples compared in total (this process)\n";
  }
};
[[maybe_unused]] ::testing::Environment* const g_env = ::testing::AddGlobalTestEnvironment(new TotalReport);

// ---- stimuli ------------------------------------------------------------------------------

std::vector<std::int64_t> coded_echo(const Code& code, double distance_m, double noise_rms, std::uint64_t seed,
                                     int in_bits) {
  const ReceiverConfig& c = default_design().config;
  const ExcitationParams ex{c.carrier_hz, c.cycles_per_chip, c.fs, 1.0};
  const std::vector<double> tx = bpsk_excitation(code, ex);
  ChannelParams ch;
  ch.distance_m = distance_m;
  ch.gain = 0.9;  // near full scale at 0.1 m: the 100 mm echoes touch the ADC limits
  ch.noise_rms = noise_rms;
  ch.seed = seed;
  const auto delay = static_cast<std::size_t>(distance_m / ch.speed_of_sound * c.fs);
  const std::vector<double> rx = propagate(tx, ch, c.fs, delay + tx.size() + 400);
  std::vector<std::int64_t> out;
  out.reserve(rx.size());
  for (double v : rx) out.push_back(quantize_input(v, in_bits, nullptr));
  return out;
}

std::int64_t max_code(int bits) { return (std::int64_t{1} << (bits - 1)) - 1; }
std::int64_t min_code(int bits) { return -(std::int64_t{1} << (bits - 1)); }

// The sign pattern of the cascade's impulse response, time reversed, at full scale: drives
// the output at the last sample to (nearly) its L1 bound.
std::vector<std::int64_t> worst_case(const BandpassFixed& model, int in_bits, bool negate, std::size_t length) {
  BandpassFloat f(model.quantized_filter());
  std::vector<double> h(length);
  for (std::size_t n = 0; n < length; ++n) h[n] = f.execute(n == 0 ? 1.0 : 0.0);
  std::vector<std::int64_t> x(length);
  for (std::size_t n = 0; n < length; ++n) {
    const bool pos = (h[length - 1 - n] >= 0) != negate;
    x[n] = pos ? max_code(in_bits) : min_code(in_bits);
  }
  return x;
}

std::vector<std::int64_t> uniform_noise(std::size_t n, int in_bits, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<std::int64_t> d(min_code(in_bits), max_code(in_bits));
  std::vector<std::int64_t> x(n);
  for (auto& v : x) v = d(rng);
  return x;
}

std::vector<std::int64_t> steps_and_impulses(int in_bits, std::size_t hold) {
  std::vector<std::int64_t> x;
  const std::int64_t levels[] = {max_code(in_bits), min_code(in_bits), 0, max_code(in_bits) / 3};
  for (std::int64_t l : levels) x.insert(x.end(), hold, l);
  for (std::int64_t l : {max_code(in_bits), min_code(in_bits), std::int64_t{1}, std::int64_t{-1}}) {
    x.push_back(l);
    x.insert(x.end(), hold, 0);
  }
  return x;
}

// ---- the Verilated bench ------------------------------------------------------------------

class SosBench {
 public:
  SosBench(const std::string& trace_name, std::uint64_t seed)
      : h_(trace_name),
        model_(default_design().filter, default_design().config.bandpass),
        sections_(static_cast<int>(model_.coefficients().size())),
        data_w_(model_.config().data_bits),
        in_w_(model_.config().input_bits),
        rng_(seed) {
    Dut& t = h_.top();
    t.s_valid = 0;
    t.m_ready = 0;
    t.s_data = 0;
    h_.reset(2);
  }

  BandpassFixed& model() { return model_; }
  tb::Harness<Dut>& harness() { return h_; }
  int in_bits() const { return in_w_; }
  std::uint64_t compared() const { return compared_; }
  std::uint64_t mismatches() const { return mismatches_; }
  std::uint64_t protocol_errors() const { return protocol_errors_; }

  std::int64_t section_word(int k) const {
    return tb::sign_extend(tb::port_bits(h_top().m_sections, k * data_w_, data_w_), data_w_);
  }

  // Streams `in` through the DUT (the model continues from its current state, like the DUT)
  // with s_valid offered with probability p_valid and m_ready with p_ready per cycle; compares
  // every output beat with the model and ends with the pipeline drained.
  void stream(const std::vector<std::int64_t>& in, double p_valid, double p_ready) {
    std::vector<std::int64_t> exp_y;
    std::vector<std::vector<std::int64_t>> exp_s;
    exp_y.reserve(in.size());
    exp_s.reserve(in.size());
    for (std::int64_t x : in) {
      exp_y.push_back(model_.execute_raw(x));
      exp_s.push_back(model_.section_outputs());
    }
    Dut& t = h_.top();
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::size_t ii = 0, oi = 0;
    bool s_hold = false;  // s_valid was refused: keep it (AXI: valid never drops unaccepted)
    bool prev_stall = false;
    std::vector<std::int64_t> prev_words(static_cast<std::size_t>(sections_));
    const std::uint64_t limit = h_.cycles() + 64 * in.size() + 10000;
    while (oi < in.size()) {
      if (h_.cycles() > limit) {
        ADD_FAILURE() << "bandpass_sos: no progress (deadlock?) after " << oi << " of " << in.size() << " outputs";
        ++mismatches_;
        return;
      }
      if (!s_hold) {
        const bool v = ii < in.size() && u(rng_) < p_valid;
        t.s_valid = v;
        // Garbage when not valid: the DUT must ignore s_data then.
        tb::set_port(t.s_data, v ? in[ii] : static_cast<std::int64_t>(rng_()), in_w_);
      }
      const bool ready = u(rng_) < p_ready;
      t.m_ready = ready;
      h_.settle();
      if (prev_stall) {  // AXI: valid held, data stable while valid && !ready
        bool same = t.m_valid != 0;
        for (int k = 0; k < sections_ && same; ++k) same = section_word(k) == prev_words[static_cast<std::size_t>(k)];
        if (!same) {
          if (protocol_errors_++ < 3) ADD_FAILURE() << "bandpass_sos: m_valid/m_sections changed while stalled before output " << oi;
        }
      }
      if (t.m_valid) {
        for (int k = 0; k < sections_; ++k) prev_words[static_cast<std::size_t>(k)] = section_word(k);
      }
      prev_stall = t.m_valid && !ready;
      if (t.m_valid && ready) {
        check(oi, exp_y[oi], exp_s[oi]);
        ++oi;
      }
      const bool fire_in = t.s_valid && t.s_ready;
      if (fire_in) ++ii;
      s_hold = t.s_valid && !t.s_ready;
      h_.tick();
    }
    // Drained: nothing may come out any more (no duplicated sample).
    t.s_valid = 0;
    t.m_ready = 1;
    for (int c = 0; c < 16 * sections_ + 16; ++c) {
      h_.settle();
      if (t.m_valid) {
        if (protocol_errors_++ < 3) ADD_FAILURE() << "bandpass_sos: extra output beat after " << in.size() << " samples";
        break;
      }
      h_.tick();
    }
  }

  // Offers in[i] for exactly one clock every `every` clocks with m_ready held high; returns
  // how many offers were refused (s_ready low) -- those are retried at the next slot.
  std::uint64_t stream_every(const std::vector<std::int64_t>& in, int every) {
    std::vector<std::int64_t> exp_y;
    std::vector<std::vector<std::int64_t>> exp_s;
    for (std::int64_t x : in) {
      exp_y.push_back(model_.execute_raw(x));
      exp_s.push_back(model_.section_outputs());
    }
    Dut& t = h_.top();
    t.m_ready = 1;
    std::size_t ii = 0, oi = 0;
    std::uint64_t refused = 0;
    const std::uint64_t limit = h_.cycles() + static_cast<std::uint64_t>(every) * in.size() + 10000;
    for (std::uint64_t c = 0; oi < in.size(); ++c) {
      if (h_.cycles() > limit) {
        ADD_FAILURE() << "bandpass_sos: no progress after " << oi << " of " << in.size() << " outputs";
        ++mismatches_;
        return refused;
      }
      const bool offer = ii < in.size() && c % static_cast<std::uint64_t>(every) == 0;
      t.s_valid = offer;
      tb::set_port(t.s_data, offer ? in[ii] : static_cast<std::int64_t>(rng_()), in_w_);
      h_.settle();
      if (t.m_valid) {
        check(oi, exp_y[oi], exp_s[oi]);
        ++oi;
      }
      if (offer) {
        if (t.s_ready) ++ii;
        else ++refused;
      }
      h_.tick();
    }
    t.s_valid = 0;
    return refused;
  }

  // Offers `n` samples at full rate with random m_ready and stops in mid-flight, without
  // checking (a reset follows); the model does not see them.
  void push_unchecked(const std::vector<std::int64_t>& in, std::size_t cycles) {
    Dut& t = h_.top();
    std::size_t ii = 0;
    for (std::size_t c = 0; c < cycles; ++c) {
      t.s_valid = ii < in.size();
      tb::set_port(t.s_data, ii < in.size() ? in[ii] : 0, in_w_);
      t.m_ready = (rng_() & 1) != 0;
      h_.settle();
      if (t.s_valid && t.s_ready) ++ii;
      h_.tick();
    }
  }

 private:
  const Dut& h_top() const { return h_.top(); }

  void check(std::size_t i, std::int64_t y, const std::vector<std::int64_t>& s) {
    ++compared_;
    ++g_total_compared;
    const std::int64_t m = tb::sign_extend(static_cast<std::uint64_t>(h_.top().m_data), data_w_);
    int first = -1;
    for (int k = 0; k < sections_; ++k) {
      if (section_word(k) != s[static_cast<std::size_t>(k)]) {
        first = k;
        break;
      }
    }
    if (first < 0 && m == y) return;
    if (mismatches_++ < 3) {
      std::ostringstream os;
      os << "bandpass_sos mismatch at sample " << i << " of this stream: ";
      if (first >= 0) {
        os << "first differing stage is section " << first + 1 << " (rtl " << section_word(first) << ", model "
           << s[static_cast<std::size_t>(first)] << ")";
      } else {
        os << "m_data " << m << " differs from the model output " << y << " (sections agree)";
      }
      ADD_FAILURE() << os.str();
    }
  }

  tb::Harness<Dut> h_;
  BandpassFixed model_;
  int sections_, data_w_, in_w_;
  std::mt19937_64 rng_;
  std::uint64_t compared_ = 0, mismatches_ = 0, protocol_errors_ = 0;
};

void report(const char* what, const SosBench& b) {
  std::cout << "bandpass_sos: " << what << ": " << b.compared() << " samples compared, " << b.mismatches()
            << " mismatches\n";
}

// Prints the bench's counts and checks them: every offered sample compared, no mismatch, no
// handshake violation.
void expect_clean(const char* what, const SosBench& b, std::uint64_t offered) {
  report(what, b);
  EXPECT_EQ(b.compared(), offered) << what;
  EXPECT_EQ(b.mismatches(), 0u) << what;
  EXPECT_EQ(b.protocol_errors(), 0u) << what;
}

// ---- helpers for the external tools ---------------------------------------------------------

struct CmdResult {
  int rc = -1;
  std::string output;
};

CmdResult run(const std::string& cmd) {
  CmdResult r;
  FILE* p = popen((cmd + " 2>&1").c_str(), "r");
  if (p == nullptr) return r;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
  const int st = pclose(p);
  r.rc = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
  return r;
}

using tb::ParamList;

// What the generator writes into generated/<config>/rtl/bandpass_sos.vc (tb/generated_params.hpp).
ParamList generated_params() { return tb::verilog_params(tb::generated_module(default_design(), "bandpass_sos")); }

int rounding_code(Rounding r) { return r == Rounding::Truncate ? 0 : r == Rounding::RoundHalfUp ? 1 : 2; }

// The module parameters for a model configuration (what the generator does for bandpass_sos).
ParamList params_for(const BandpassFixed& m, int sample_cycles) {
  const BandpassFixedConfig& c = m.config();
  std::vector<std::int64_t> coefs;
  for (const auto& s : m.coefficients()) coefs.insert(coefs.end(), s.begin(), s.end());
  return {{"SECTIONS", std::to_string(m.coefficients().size())},
          {"IN_W", std::to_string(c.input_bits)},
          {"DATA_W", std::to_string(c.data_bits)},
          {"DATA_FRAC", std::to_string(c.data_frac)},
          {"COEF_W", std::to_string(c.coef_bits)},
          {"COEF_FRAC", std::to_string(c.coef_frac)},
          {"ACC_W", std::to_string(c.acc_bits)},
          {"ROUNDING", std::to_string(rounding_code(c.rounding))},
          {"SATURATE", c.overflow == Overflow::Saturate ? "1" : "0"},
          {"COEFS", verilog_packed(coefs, c.coef_bits)},
          {"SAMPLE_CYCLES", std::to_string(sample_cycles)}};
}

// The module and the quantizer it instantiates.
std::string rtl_path() {
  const std::string rtl = std::string(RANGING_SOURCE_DIR) + "/rtl/";
  return rtl + "bandpass_sos.v " + rtl + "fx_quantize.v";
}

CmdResult lint(const ParamList& params) {
  std::string cmd = std::string(RANGING_VERILATOR_BIN) + " --lint-only -Wall --top-module bandpass_sos";
  // Double quotes: the sized literals contain a single quote (400'h...).
  for (const auto& [n, v] : params) cmd += " \"-G" + n + "=" + v + "\"";
  return run(cmd + " " + rtl_path());
}

std::string hex_of(std::int64_t v, int bits) {
  const std::string p = verilog_packed({v}, bits);
  return p.substr(p.find('h') + 1);
}

struct IcarusOutcome {
  long compared = -1, mismatches = -1, xs = -1, timeout = -1;
  std::string log;
};

// Writes the vectors of `in` through `model` (fresh state) and a self-checking Verilog
// testbench with `params` into `dir`, runs it with Icarus and parses its RESULT line.
IcarusOutcome run_icarus(const std::string& dir, const ParamList& params, BandpassFixed& model,
                         const std::vector<std::int64_t>& in, int seed) {
  std::filesystem::create_directories(dir);
  const int in_w = model.config().input_bits, data_w = model.config().data_bits;
  const int sections = static_cast<int>(model.coefficients().size());
  const int tw = sections * data_w;
  {
    std::ofstream fi(dir + "/in.hex"), fe(dir + "/exp.hex");
    model.reset();
    for (std::int64_t x : in) {
      model.execute_raw(x);
      fi << hex_of(x, in_w) << "\n";
      const std::string p = verilog_packed(model.section_outputs(), data_w);
      fe << p.substr(p.find('h') + 1) << "\n";
    }
  }
  std::ostringstream v;
  const std::size_t n = in.size();
  v << "`timescale 1ns/1ps\n`default_nettype none\n"
    << "module bandpass_sos_iverilog_tb;\n"
    << "  localparam integer N = " << n << ", IN_W = " << in_w << ", DATA_W = " << data_w << ", TW = " << tw << ";\n"
    << "  reg clk = 1'b0, rst = 1'b1, s_valid = 1'b0, m_ready = 1'b0;\n"
    << "  reg [IN_W-1:0] s_data = {IN_W{1'b0}};\n"
    << "  wire s_ready, m_valid;\n  wire [DATA_W-1:0] m_data;\n  wire [TW-1:0] m_sections;\n"
    << "  reg [IN_W-1:0] in_mem [0:N-1];\n  reg [TW-1:0] exp_mem [0:N-1];\n"
    << "  integer ii = 0, oi = 0, mism = 0, xcount = 0, cyc = 0, rcyc = 0, tail = 0, seed = " << seed << ";\n"
    << "  bandpass_sos #(";
  for (std::size_t i = 0; i < params.size(); ++i) v << (i ? ", " : "") << "." << params[i].first << "(" << params[i].second << ")";
  v << ") dut (.clk(clk), .rst(rst), .s_data(s_data), .s_valid(s_valid), .s_ready(s_ready),\n"
    << "    .m_data(m_data), .m_valid(m_valid), .m_ready(m_ready), .m_sections(m_sections));\n"
    << "  always #5 clk = ~clk;\n"
    << "  initial begin\n    $readmemh(\"" << dir << "/in.hex\", in_mem);\n    $readmemh(\"" << dir
    << "/exp.hex\", exp_mem);\n  end\n"
    << "  always @(posedge clk) begin\n"
    << "    rcyc = rcyc + 1;\n"
    << "    if (rcyc == 3) rst <= 1'b0;\n"
    << "    if (!rst) begin\n"
    << "      cyc = cyc + 1;\n"
    << "      if ((^{s_ready, m_valid, m_data, m_sections}) === 1'bx) xcount = xcount + 1;\n"
    << "      if (m_valid && m_ready) begin\n"
    << "        if (oi >= N) begin mism = mism + 1; $display(\"EXTRA output beat\"); end\n"
    << "        else if (m_sections !== exp_mem[oi] || m_data !== exp_mem[oi][TW-1 -: DATA_W]) begin\n"
    << "          mism = mism + 1;\n"
    << "          if (mism <= 5) $display(\"MISMATCH sample %0d: rtl %h model %h\", oi, m_sections, exp_mem[oi]);\n"
    << "        end\n"
    << "        oi = oi + 1;\n"
    << "      end\n"
    << "      if (s_valid && s_ready) ii = ii + 1;\n"
    << "      if (!(s_valid && !s_ready)) begin\n"
    << "        s_valid <= (ii < N) && (($random(seed) & 3) != 0);\n"
    << "        s_data <= (ii < N) ? in_mem[ii] : {IN_W{1'b0}};\n"
    << "      end\n"
    << "      m_ready <= (($random(seed) & 7) != 0);\n"
    << "      if (oi >= N) tail = tail + 1;\n"
    << "      if (tail > 200 || cyc > 64 * N + 10000) begin\n"
    << "        $display(\"RESULT compared=%0d mismatches=%0d x=%0d timeout=%0d\", oi, mism, xcount, tail <= 200);\n"
    << "        $finish;\n"
    << "      end\n"
    << "    end\n"
    << "  end\n"
    << "endmodule\n";
  std::ofstream(dir + "/bandpass_sos_iverilog_tb.v") << v.str();

  IcarusOutcome o;
  const CmdResult c = run(std::string(RANGING_IVERILOG_BIN) + " -g2012 -Wall -o " + dir + "/sim.vvp " + dir +
                          "/bandpass_sos_iverilog_tb.v " + rtl_path());
  o.log = c.output;
  if (c.rc != 0) return o;
  const CmdResult s = run(std::string(RANGING_VVP_BIN) + " -n " + dir + "/sim.vvp");
  o.log += s.output;
  const auto pos = s.output.find("RESULT ");
  if (pos == std::string::npos) return o;
  std::sscanf(s.output.c_str() + pos, "RESULT compared=%ld mismatches=%ld x=%ld timeout=%ld", &o.compared,
              &o.mismatches, &o.xs, &o.timeout);
  return o;
}

// ---- tests --------------------------------------------------------------------------------

TEST(BandpassSosRtl, GeneratedParametersAreTheModels) {
  // The Verilated module gets the generator's .vc; the benches below build the model from the
  // same configuration. Both must describe the same filter for the comparison to mean anything.
  const BandpassFixed m(default_design().filter, default_design().config.bandpass);
  const ParamList vc = generated_params();
  const ParamList mine = params_for(m, default_design().config.sample_cycles());
  ASSERT_EQ(vc.size(), mine.size());
  for (std::size_t i = 0; i < vc.size(); ++i) {
    EXPECT_EQ(vc[i].first, mine[i].first);
    EXPECT_EQ(vc[i].second, mine[i].second) << vc[i].first;
  }
  // The committed manifest.json (next to the .vc the Verilated module was built with) holds
  // the same values.
  const auto manifest = tb::manifest_module(std::string(RANGING_GENERATED_DIR) + "/manifest.json", "bandpass_sos");
  const HwModuleParams gen = tb::generated_module(default_design(), "bandpass_sos");
  ASSERT_EQ(manifest.size(), gen.params.size());
  for (const auto& p : gen.params) {
    ASSERT_EQ(manifest.count(p.name), 1u) << p.name;
    EXPECT_EQ(manifest.at(p.name), p.elements) << p.name;
  }
}

TEST(BandpassSosRtl, CodedEchoesBitExact) {
  SosBench b("tb_bandpass_sos", 11);
  std::uint64_t offered = 0;
  std::uint64_t seed = 100;
  int run_index = 0;
  for (const char* fam : {"M1", "Gold4"}) {
    const CodeFamily f = code_family(fam);
    for (const Code& code : f.codes) {
      for (double d : {0.100, 0.550, 1.000}) {
        for (double noise : {0.0, 0.02}) {
          const auto x = coded_echo(code, d, noise, ++seed, b.in_bits());
          // Every fourth run with gaps and back-pressure, the rest at full rate.
          const bool gaps = (run_index++ % 4) == 3;
          b.stream(x, gaps ? 0.8 : 1.0, gaps ? 0.7 : 1.0);
          offered += x.size();
        }
      }
    }
  }
  // Every code of the other paper families once: a noisy echo from 100 mm.
  for (const std::string& fam : code_family_names()) {
    if (fam == "M1" || fam == "Gold4" || !(fam[0] == 'M' || fam.rfind("Gold", 0) == 0)) continue;
    for (const Code& code : code_family(fam).codes) {
      const auto x = coded_echo(code, 0.100, 0.02, ++seed, b.in_bits());
      b.stream(x, 1.0, 1.0);
      offered += x.size();
    }
  }
  expect_clean("coded echoes (M1, Gold4 at 100/550/1000 mm with and without noise; M2-M4, Gold1-7 at 100 mm)", b, offered);
}

TEST(BandpassSosRtl, WorstCaseNoiseStepsImpulsesBitExact) {
  SosBench b("tb_bandpass_sos_fullscale", 12);
  const std::size_t len = 3000;
  std::uint64_t offered = 0;
  const BandpassHeadroom hr = bandpass_headroom(b.model().config(), default_design().filter);
  const double lsb = std::ldexp(1.0, -b.model().config().data_frac);
  for (bool neg : {false, true}) {
    const auto x = worst_case(b.model(), b.in_bits(), neg, len);
    b.stream(x, 1.0, 1.0);
    offered += x.size();
    // The stimulus is what it claims: the last output reaches the L1 bound of the cascade.
    const double peak = std::abs(static_cast<double>(b.model().section_outputs().back())) * lsb;
    EXPECT_GT(peak, 0.99 * hr.signal_gain.back()) << "worst-case input, negated=" << neg;
  }
  for (int r = 0; r < 3; ++r) {
    const auto x = uniform_noise(40000, b.in_bits(), 7 + static_cast<std::uint64_t>(r));
    b.stream(x, r == 0 ? 1.0 : 0.6, r == 2 ? 0.5 : 1.0);
    offered += x.size();
  }
  const auto s = steps_and_impulses(b.in_bits(), 3000);
  b.stream(s, 1.0, 1.0);
  b.stream(s, 0.7, 0.4);
  offered += 2 * s.size();
  expect_clean("worst case, full-scale noise, steps, impulses", b, offered);
}

TEST(BandpassSosRtl, GapsAndBackPressureLoseNothing) {
  SosBench b("tb_bandpass_sos_backpressure", 13);
  std::uint64_t offered = 0;
  const double patterns[][2] = {{0.5, 0.3}, {1.0, 0.05}, {0.05, 1.0}, {0.9, 0.9}, {0.3, 0.6}};
  std::uint64_t seed = 500;
  for (const auto& p : patterns) {
    const auto x = uniform_noise(6000, b.in_bits(), ++seed);
    b.stream(x, p[0], p[1]);
    const auto e = coded_echo(code_family("Gold4").codes[seed % 9], 0.12, 0.01, seed, b.in_bits());
    b.stream(e, p[0], p[1]);
    offered += x.size() + e.size();
  }
  expect_clean("random gaps and back-pressure", b, offered);
}

TEST(BandpassSosRtl, ResetMidStreamGivesAFreshFilter) {
  SosBench b("tb_bandpass_sos_reset", 14);
  const auto junk = uniform_noise(400, b.in_bits(), 99);
  std::uint64_t offered = 0;
  // Reset at every phase of the pipeline (mid-products, mid-handover, full output registers).
  for (std::size_t cut = 1; cut <= 60; ++cut) {
    b.push_unchecked(junk, 40 + cut);
    Dut& t = b.harness().top();
    t.s_valid = 0;
    b.harness().reset(1 + static_cast<int>(cut % 3));
    t.m_ready = 1;
    b.harness().settle();
    EXPECT_FALSE(t.m_valid) << "an output survived the reset (cut " << cut << ")";
    b.model().reset();
    const auto x = uniform_noise(300, b.in_bits(), 1000 + cut);
    b.stream(x, cut % 2 ? 1.0 : 0.7, cut % 3 ? 1.0 : 0.5);
    offered += x.size();
  }
  expect_clean("reset in the middle of a stream", b, offered);
}

// The schedule the header documents: shared multipliers (two sections per SB_MAC16, one
// sample every 6 clocks) when every section is a g*[1,0,-1] numerator with 2*b0, -a1, -a2
// representable; otherwise one multiplier per section, P = 4 + (b1 != 0) clocks.
struct Schedule {
  bool shared = true;
  int period = 0, latency = 0;
};

Schedule documented_schedule(const BandpassFixed& m) {
  const int cb = m.config().coef_bits;
  const std::int64_t lo = -(std::int64_t{1} << (cb - 1)), half = std::int64_t{1} << (cb - 2);
  Schedule s;
  for (const auto& c : m.coefficients()) {
    if (c[1] != 0 || c[2] != -c[0] || c[0] < -half || c[0] >= half || c[3] == lo || c[4] == lo) s.shared = false;
  }
  const int n = static_cast<int>(m.coefficients().size());
  if (s.shared) {
    s.period = 6;
    s.latency = 2 + 13 * ((n - 1) / 2) + 9 * ((n - 1) % 2) + 2;
  } else {
    s.latency = -1;
    for (const auto& c : m.coefficients()) {
      const int p = 4 + (c[1] != 0 ? 1 : 0);
      s.latency += p + 4;
      s.period = std::max(s.period, p);
    }
  }
  return s;
}

TEST(BandpassSosRtl, LatencyAndThroughputAsDocumented) {
  SosBench b("tb_bandpass_sos_timing", 15);
  const Schedule sch = documented_schedule(b.model());
  EXPECT_TRUE(sch.shared) << "the default filter should use the shared-multiplier schedule";
  const int latency = sch.latency, period = sch.period;
  Dut& t = b.harness().top();
  t.m_ready = 1;
  for (int c = 0; c < 8; ++c) b.harness().tick();  // idle: the shared schedule parks at its input slot
  t.s_valid = 1;
  tb::set_port(t.s_data, 1000, b.in_bits());
  b.harness().settle();
  ASSERT_TRUE(t.s_ready);
  b.harness().tick();  // accepted at this edge
  t.s_valid = 0;
  int cycles = 0;
  for (b.harness().settle(); !t.m_valid && cycles < 1000; b.harness().settle()) {
    b.harness().tick();
    ++cycles;
  }
  EXPECT_EQ(cycles, latency);
  b.harness().tick();
  // Throughput: with s_valid and m_ready held high, one sample every `period` cycles (the
  // shared schedule's input register takes a second sample right after the first).
  b.harness().reset(2);
  t.s_valid = 1;
  t.m_ready = 1;
  std::vector<std::uint64_t> accept_at;
  for (int c = 0; c < 400; ++c) {
    b.harness().settle();
    if (t.s_ready) accept_at.push_back(b.harness().cycles());
    b.harness().tick();
  }
  ASSERT_GT(accept_at.size(), 10u);
  for (std::size_t i = sch.shared ? 2 : 1; i < accept_at.size(); ++i) {
    EXPECT_EQ(accept_at[i] - accept_at[i - 1], static_cast<std::uint64_t>(period)) << "accept " << i;
  }
}

// The 5 MS/s stream at a 30 MHz clock: one sample offered every 6 clocks (for one clock),
// m_ready always high. The filter must be ready every time (it never stalls the ADC) and
// still match the model bit for bit.
TEST(BandpassSosRtl, OneSampleEverySixClocksNeverStalls) {
  SosBench b("tb_bandpass_sos_6clk", 16);
  std::uint64_t seed = 900, offered = 0;
  for (const Code& code : code_family("Gold4").codes) {
    const auto x = coded_echo(code, 0.100, 0.02, ++seed, b.in_bits());
    const std::uint64_t refused = b.stream_every(x, 6);
    offered += x.size();
    EXPECT_EQ(refused, 0u) << "s_ready low when a sample was offered";
  }
  expect_clean("one sample every 6 clocks", b, offered);
}

TEST(BandpassSosRtl, VerilatorLintClean) {
  const CmdResult r = lint(generated_params());
  EXPECT_EQ(r.rc, 0) << r.output;
  EXPECT_EQ(r.output, "");
}

// Icarus: the default (.vc) parameters, and configurations the Verilated build does not
// cover: truncate / convergent, wrap, narrow words that overflow, minimal accumulators, an
// input alignment of 5 bits, and coarse coefficients with b1 != 0 (frequent exact ties).
TEST(BandpassSosRtl, IcarusBitExactAcrossModes) {
  const ReceiverDesign& d = default_design();
  // Coarse coefficients (multiples of 1/8): the dropped bits tie often, so convergent and
  // round-half-up differ; b1 != 0 selects the 5-product schedule.
  SosFilter coarse = d.filter;
  coarse.sections = {Biquad{0.25, 0.125, -0.25, -1.5, 0.625}, Biquad{0.5, -0.375, 0.125, -1.25, 0.5}};
  // An even section count on the shared schedule (the last pair is full).
  SosFilter four = d.filter;
  four.sections.resize(4);
  struct Variant {
    std::string name;
    const SosFilter* filter;
    BandpassFixedConfig cfg;
    bool from_vc;
    bool min_acc;
    int sample_cycles = 6;  // < 6: the one-multiplier-per-section architecture
  };
  auto cfg = [&](Rounding r, Overflow o, int in_bits, int coef_frac, int data_bits, int data_frac) {
    BandpassFixedConfig c = d.config.bandpass;
    c.rounding = r;
    c.overflow = o;
    c.input_bits = in_bits;
    c.coef_frac = coef_frac;
    c.data_bits = data_bits;
    c.data_frac = data_frac;
    return c;
  };
  const std::vector<Variant> variants = {
      {"default_vc", &d.filter, d.config.bandpass, true, false},
      {"trunc_wrap_q1_12", &d.filter, cfg(Rounding::Truncate, Overflow::Wrap, 12, 14, 13, 12), false, true},
      {"conv_sat_coarse", &coarse, cfg(Rounding::Convergent, Overflow::Saturate, 12, 14, 12, 11), false, true},
      {"conv_wrap_coarse", &coarse, cfg(Rounding::Convergent, Overflow::Wrap, 12, 14, 12, 11), false, false},
      {"conv_wrap_default_filter_coef10", &d.filter, cfg(Rounding::Convergent, Overflow::Wrap, 12, 10, 13, 12), false, true},
      {"trunc_sat_four_sections", &four, cfg(Rounding::Truncate, Overflow::Saturate, 12, 14, 13, 12), false, true},
      {"halfup_wrap_in10_coef13", &d.filter, cfg(Rounding::RoundHalfUp, Overflow::Wrap, 10, 13, 16, 14), false, true},
      {"default_per_section_mac", &d.filter, d.config.bandpass, false, false, 4},
  };
  int seed = 1;
  long total = 0;
  for (const Variant& var : variants) {
    BandpassFixedConfig c = var.cfg;
    if (var.min_acc) c.acc_bits = bandpass_min_acc_bits(c, *var.filter);
    BandpassFixed m(*var.filter, c);
    const int in_w = c.input_bits;
    std::vector<std::int64_t> x = coded_echo(code_family("Gold4").codes[0], 0.1, 0.01, 3, in_w);
    x.resize(std::min<std::size_t>(x.size(), 2500));
    for (bool neg : {false, true}) {
      const auto w = worst_case(m, in_w, neg, 600);
      x.insert(x.end(), w.begin(), w.end());
    }
    const auto nz = uniform_noise(1500, in_w, 77);
    x.insert(x.end(), nz.begin(), nz.end());
    const auto st = steps_and_impulses(in_w, 150);
    x.insert(x.end(), st.begin(), st.end());

    // The stimulus exercises what the variant is about.
    m.reset();
    for (auto v : x) m.execute_raw(v);
    const OverflowCounter ev = m.overflow_events();
    if (c.data_bits < 16) {
      EXPECT_GT(c.overflow == Overflow::Wrap ? ev.wraps : ev.saturations, 0u) << var.name << ": no overflow exercised";
    }
    if (c.rounding == Rounding::Convergent) {
      BandpassFixedConfig h = c;
      h.rounding = Rounding::RoundHalfUp;
      BandpassFixed mh(*var.filter, h);
      m.reset();
      bool differs = false;
      for (auto v : x) differs |= (m.execute_raw(v) != mh.execute_raw(v));
      EXPECT_TRUE(differs) << var.name << ": no exact tie exercised";
    }

    const ParamList params = var.from_vc ? generated_params() : params_for(m, var.sample_cycles);
    const CmdResult l = lint(params);
    EXPECT_EQ(l.rc, 0) << var.name << ": " << l.output;
    EXPECT_EQ(l.output, "") << var.name;

    const IcarusOutcome o = run_icarus(std::string(RANGING_TB_WORK_DIR) + "/icarus_" + var.name, params, m, x, seed++);
    EXPECT_EQ(o.compared, static_cast<long>(x.size())) << var.name << ":\n" << o.log;
    EXPECT_EQ(o.mismatches, 0) << var.name << ":\n" << o.log;
    EXPECT_EQ(o.xs, 0) << var.name << ": X on an output after reset\n" << o.log;
    EXPECT_EQ(o.timeout, 0) << var.name << ":\n" << o.log;
    std::cout << "bandpass_sos (Icarus, " << var.name << "): " << o.compared << " samples compared, " << o.mismatches
              << " mismatches, " << o.xs << " X\n";
    total += std::max(0L, o.compared);
  }
  g_total_compared += static_cast<std::uint64_t>(total);
}

}  // namespace
