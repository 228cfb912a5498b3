// Post-synthesis equivalence (issue 5): the generated receiver_top is synthesized for the
// iCE40 exactly as the bitstream flow does (yosys synth_ice40 -dsp, write_verilog), and the
// gate-level netlist (SB_LUT4, SB_CARRY, SB_DFF*, SB_MAC16, SB_RAM40_4K from yosys'
// cells_sim.v) is simulated with Verilator on a short vector set: one received burst
// through the channel model. Every filter output, every correlator-bank output (index,
// energy, chip filter, weighted powers) and every event must equal ReceiverFixed bit for bit.
// Also checked: every multiplier mapped to SB_MAC16 (none left in LUTs).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "model/config/receiver_config.hpp"
#include "model/sim/channel.hpp"
#include "model/dsp/excitation.hpp"
#include "model/hw/hw_params.hpp"
#include "model/hw/ip_package.hpp"
#include "model/dsp/receiver.hpp"
#include "tb/bits.hpp"

using namespace ranging;
namespace fs = std::filesystem;

namespace {

int run(const std::string& cmd) {
  const int st = std::system(cmd.c_str());
  return st == -1 ? -1 : WEXITSTATUS(st);
}

std::string read(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Bits [lo, lo+w) of a hex string (MSB first), w <= 64.
std::uint64_t hex_bits(const std::string& hex, int lo, int w) {
  std::uint64_t out = 0;
  const int n = static_cast<int>(hex.size());
  for (int b = 0; b < w; ++b) {
    const int bit = lo + b;
    const int digit = n - 1 - bit / 4;
    if (digit < 0) break;
    const char c = hex[static_cast<std::size_t>(digit)];
    const int v = c >= '0' && c <= '9' ? c - '0' : (c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1);
    if (v < 0) throw std::runtime_error("x or z in netlist output: " + hex);
    if ((v >> (bit % 4)) & 1) out |= std::uint64_t{1} << b;
  }
  return out;
}

using tb::sign_extend;

struct BankState {
  std::uint64_t energy;
  std::int64_t chip_re, chip_im;
  std::vector<std::uint64_t> q;
};

TEST(PostSynthesis, NetlistMatchesGoldenModel) {
  const ReceiverDesign d = design_receiver(load_receiver_config(RANGING_CONFIG));
  const auto mods = hardware_parameters(d);
  auto val = [&](const std::string& m, const std::string& p) {
    for (const auto& x : mods) {
      if (x.module == m) return static_cast<int>(x.value(p));
    }
    throw std::logic_error(m);
  };
  const int in_w = val("bandpass_sos", "IN_W"), data_w = val("bandpass_sos", "DATA_W");
  const int codes = val("correlator_bank", "CODES"), qw = val("correlator_bank", "WEIGHTED_W");
  const int ew = val("correlator_bank", "ENERGY_W"), tw = val("correlator_bank", "TIME_W");
  const int cw = val("correlator_bank", "CHIP_W");
  const int code_w = val("peak_detector", "CODE_W"), frac_w = val("peak_detector", "FRAC_W");
  const int sw = val("peak_detector", "SCORE_W");
  const int arr_w = tw + frac_w + 1;

  // Vectors: code 1 sent at sample 0, received 30 mm away, through the reference transducers.
  const ExcitationParams ex = receiver_excitation(d.config);
  const auto drive = hbridge_drive(d.family.codes[0], ex);
  ChannelParams ch;
  ch.distance_m = 0.03;
  ch.gain = 0.5;
  ch.tx = ch.rx = d.config.reference_transducer;
  ch.noise_rms = 0.003;
  const std::size_t n = static_cast<std::size_t>(drive.size() + 90 + 2 * d.layout.window + 500);
  const auto y = propagate(std::vector<double>(drive.begin(), drive.end()), ch, d.config.fs, n);
  std::vector<std::int64_t> x(n);
  for (std::size_t k = 0; k < n; ++k) x[k] = quantize_input(y[k], in_w, nullptr);

  ReceiverFixed rx(d);
  std::vector<std::int64_t> filt(n);
  std::vector<BankState> bank(n);
  std::vector<EventFixed> events;
  for (std::size_t k = 0; k < n; ++k) {
    if (auto e = rx.execute_raw(x[k])) events.push_back(*e);
    filt[k] = rx.filtered();
    const auto& b = rx.bank();
    bank[k] = BankState{b.energy(), b.chip_re(), b.chip_im(), b.weighted_power()};
  }
  ASSERT_FALSE(events.empty()) << "the vector set must produce an event";

  const fs::path work = RANGING_POSTSYNTH_WORK_DIR;
  fs::create_directories(work);
  {
    std::ofstream stim(work / "stim.hex");
    const std::uint64_t mask = (std::uint64_t{1} << in_w) - 1;
    for (auto v : x) stim << std::hex << (static_cast<std::uint64_t>(v) & mask) << "\n";
  }
  // Synthesis as in scripts/build_bitstream.sh.
  const std::string gen = RANGING_GENERATED_DIR;
  const std::string src = RANGING_SOURCE_DIR;
  std::string reads;
  for (const std::string& f : receiver_rtl_sources()) reads += "read_verilog -defer " + src + "/rtl/" + f + "; ";
  reads += "read_verilog -defer " + gen + "/rtl/receiver_top.v; ";
  const fs::path netlist = work / "receiver_top_syn.v";
  ASSERT_EQ(run("nice " RANGING_YOSYS_BIN " -q -l " + (work / "yosys.log").string() + " -p '" + reads +
                "synth_ice40 -dsp -top receiver_top; tee -q -o " + (work / "stat.txt").string() +
                " stat; write_verilog -noattr " + netlist.string() + "' > /dev/null"),
            0)
      << "yosys failed: " << (work / "yosys.log");
  const std::string stat = read(work / "stat.txt");
  EXPECT_NE(stat.find("SB_MAC16"), std::string::npos) << "no multiplier mapped to SB_MAC16";
  EXPECT_EQ(stat.find("$mul"), std::string::npos) << "multipliers left in LUTs";
  EXPECT_EQ(stat.find("$macc"), std::string::npos) << "multiply-adds left in LUTs";

  // Icarus testbench: drives the samples, logs every stage beat.
  const int event_w = code_w + arr_w + 2 * sw;
  std::ostringstream tb;
  tb << "`timescale 1ns/1ps\nmodule tb;\n  reg clk = 0, rst = 1;\n  always #5 clk = ~clk;\n"
     << "  reg [" << in_w - 1 << ":0] mem [0:" << n - 1 << "];\n  integer i = 0, fd, cyc = 0;\n"
     << "  wire ready, fv, bv, ev;\n  wire [" << data_w - 1 << ":0] fd_data;\n"
     << "  wire [" << qw - 1 << ":0] wq;\n  wire [" << ew - 1 << ":0] en;\n  wire [" << code_w - 1 << ":0] bj;\n  wire bl;\n"
     << "  wire [" << tw - 1 << ":0] idx;\n  wire [" << cw - 1 << ":0] cre, cim;\n"
     << "  wire [" << event_w - 1 << ":0] evd;\n"
     << "  receiver_top dut(.clk(clk), .rst(rst), .s_axis_tdata(mem[i]), .s_axis_tvalid(i < " << n
     << " && !rst), .s_axis_tready(ready), .m_axis_tdata(evd), .m_axis_tvalid(ev), .m_axis_tready(1'b1),\n"
     << "    .dbg_filter_valid(fv), .dbg_filter_data(fd_data), .dbg_filter_sections(), .dbg_bank_valid(bv),\n"
     << "    .dbg_weighted(wq), .dbg_code(bj), .dbg_last(bl), .dbg_energy(en), .dbg_index(idx),\n"
     << "    .dbg_chip_re(cre), .dbg_chip_im(cim),\n"
     << "    .dbg_corr_re(), .dbg_corr_im());\n"
     << "  initial begin\n    $readmemh(\"" << (work / "stim.hex").string() << "\", mem);\n"
     << "    fd = $fopen(\"" << (work / "out.txt").string() << "\", \"w\");\n"
     << "    repeat (4) @(posedge clk);\n    #1 rst = 0;\n  end\n"
     << "  always @(posedge clk) if (!rst) begin\n"
     << "    cyc = cyc + 1;\n"
     << "    if (fv) $fwrite(fd, \"F %h\\n\", fd_data);\n"
     << "    if (bv) $fwrite(fd, \"B %h %h %h %h %h %h %h\\n\", idx, en, cre, cim, bj, bl, wq);\n"
     << "    if (ev) $fwrite(fd, \"E %h\\n\", evd);\n"
     << "    if (i < " << n << " && ready) i <= i + 1;\n"
     << "    if (i >= " << n << " && cyc > 0 && $time > 0 && (cyc > " << 64 * n + 20000 << ")) begin $fclose(fd); $finish; end\n"
     << "  end\n"
     << "  reg [31:0] tail = 0;\n"
     << "  always @(posedge clk) if (i >= " << n << ") begin tail <= tail + 1; if (tail == 3000) begin $fwrite(fd, \"DONE %0d\\n\", cyc); $fclose(fd); $finish; end end\n"
     << "endmodule\n";
  std::ofstream(work / "tb.v") << tb.str();
  // Verilator (--binary --timing) runs the gate-level netlist in seconds; Icarus takes hours.
  fs::remove_all(work / "vobj");
  ASSERT_EQ(run("nice " RANGING_VERILATOR_BIN " --binary --timing -Wno-fatal -Wno-lint -Wno-style "
                "-DNO_ICE40_DEFAULT_ASSIGNMENTS --top-module tb -j 2 -Mdir " + (work / "vobj").string() + " " +
                (work / "tb.v").string() + " " + netlist.string() + " " RANGING_YOSYS_DATDIR "/ice40/cells_sim.v > " +
                (work / "verilator.log").string() + " 2>&1"),
            0)
      << read(work / "verilator.log");
  ASSERT_EQ(run((work / "vobj" / "Vtb").string() + " > " + (work / "sim.log").string() + " 2>&1"), 0)
      << read(work / "sim.log");

  std::ifstream out(work / "out.txt");
  std::string tag, line;
  std::size_t nf = 0, nb = 0, ne = 0;
  int beat = 0;
  bool done = false;
  while (std::getline(out, line)) {
    std::istringstream ls(line);
    ls >> tag;
    if (tag == "F") {
      std::string h;
      ls >> h;
      ASSERT_LT(nf, n);
      ASSERT_EQ(sign_extend(hex_bits(h, 0, data_w), data_w), filt[nf]) << "filter output, sample " << nf;
      ++nf;
    } else if (tag == "B") {
      std::string hi, he, hr, hm, hj, hl, hq;  // one beat per code
      ls >> hi >> he >> hr >> hm >> hj >> hl >> hq;
      const std::uint64_t i = hex_bits(hi, 0, tw);
      ASSERT_LT(i, n);
      const BankState& b = bank[i];
      ASSERT_EQ(hex_bits(he, 0, ew), b.energy) << "energy at index " << i;
      ASSERT_EQ(sign_extend(hex_bits(hr, 0, cw), cw), b.chip_re) << "chip filter (re) at index " << i;
      ASSERT_EQ(sign_extend(hex_bits(hm, 0, cw), cw), b.chip_im) << "chip filter (im) at index " << i;
      const int j = static_cast<int>(hex_bits(hj, 0, code_w));
      ASSERT_EQ(j, beat) << "beat order at index " << i;
      ASSERT_EQ(hex_bits(hl, 0, 1) == 1, j == codes - 1) << "last flag at index " << i;
      ASSERT_EQ(hex_bits(hq, 0, qw), b.q[static_cast<std::size_t>(j)]) << "Q_" << j + 1 << " at index " << i;
      if (++beat == codes) {
        beat = 0;
        ++nb;
      }
    } else if (tag == "E") {
      std::string h;
      ls >> h;
      ASSERT_LT(ne, events.size()) << "extra event";
      const EventFixed& e = events[ne];
      EXPECT_EQ(static_cast<int>(hex_bits(h, 0, code_w)), e.code);
      EXPECT_EQ(sign_extend(hex_bits(h, code_w, arr_w), arr_w), e.arrival);
      EXPECT_EQ(hex_bits(h, code_w + arr_w, sw), e.score);
      EXPECT_EQ(hex_bits(h, code_w + arr_w + sw, sw), e.margin);
      ++ne;
    } else if (tag == "DONE") {
      done = true;
    }
  }
  std::cout << "post-synthesis netlist: " << nf << " filter outputs, " << nb << " bank outputs, " << ne
            << " events compared bit for bit with ReceiverFixed (" << n << " samples)\n";
  EXPECT_TRUE(done) << "simulation did not finish";
  EXPECT_EQ(nf, n);
  EXPECT_GE(nb, n / static_cast<std::size_t>(d.layout.decimation) - 30);
  EXPECT_EQ(ne, events.size());
}

}  // namespace
