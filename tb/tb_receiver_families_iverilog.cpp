// The second simulator: Icarus Verilog (iverilog -g2012) runs the generated receiver_top for
// every family of the paper's 7-bit codes (M1, M2, Gold1-7: each its own generated top, since
// the code bits and weights are parameters), on vector files written by the golden model.
// Every code of the family is sent (one burst per period, several in flight); every decimated
// correlator output (chip filter F, weighted power Q of every code, energy, index) and every
// event must equal ReceiverFixed's; no output may be X after reset. This also proves the RTL uses no
// Verilator-only construct.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "model/config/receiver_config.hpp"
#include "model/sim/channel.hpp"
#include "model/dsp/excitation.hpp"
#include "model/hw/hw_generator.hpp"
#include "model/hw/hw_params.hpp"
#include "model/hw/ip_package.hpp"
#include "model/dsp/receiver.hpp"

using namespace ranging;
namespace fs = std::filesystem;

namespace {

// Self-checking bench: feeds samples.hex, writes one line per event; flags X on any output
// after reset.
std::string bench(const ReceiverDesign& d, std::size_t n_samples) {
  const auto mods = hardware_parameters(d);
  const int in_w = static_cast<int>(mods[0].value("IN_W"));
  const int code_w = static_cast<int>(mods[2].value("CODE_W"));
  const int arrival_w = static_cast<int>(mods[1].value("TIME_W") + mods[2].value("FRAC_W") + 1);
  const int score_w = static_cast<int>(mods[2].value("SCORE_W"));
  const int ev_w = code_w + arrival_w + 2 * score_w;
  const auto& bank = mods[1];
  const int codes = static_cast<int>(bank.value("CODES")), qw = static_cast<int>(bank.value("WEIGHTED_W"));
  const int ew = static_cast<int>(bank.value("ENERGY_W")), tw = static_cast<int>(bank.value("TIME_W"));
  const int fw = static_cast<int>(bank.value("CHIP_W"));
  std::ostringstream os;
  os << "`timescale 1ns/1ps\n"
        "module iv_top;\n"
        "  reg clk = 0, rst = 1;\n"
        "  reg signed [" << in_w - 1 << ":0] tdata = 0;\n"
        "  reg tvalid = 0, m_tready = 1;\n"
        "  wire tready, m_tvalid;\n"
        "  wire [" << ev_w - 1 << ":0] m_tdata;\n"
        "  wire bank_valid;\n"
        "  wire [" << qw - 1 << ":0] weighted;\n"
        "  reg [" << qw - 1 << ":0] group_q [0:" << codes - 1 << "];  // the beats of one output\n"
        "  wire [" << code_w - 1 << ":0] bank_code;\n"
        "  wire bank_last;\n"
        "  wire [" << ew - 1 << ":0] energy;\n"
        "  wire [" << tw - 1 << ":0] index;\n"
        "  wire signed [" << fw - 1 << ":0] chip_re, chip_im;\n"
        "  integer k;\n"
        "  reg [" << in_w - 1 << ":0] mem [0:" << n_samples - 1 << "];\n"
        "  integer i = 0, f, xs = 0, cycles = 0;\n"
        "  receiver_top dut(.clk(clk), .rst(rst), .s_axis_tdata(tdata), .s_axis_tvalid(tvalid),\n"
        "    .s_axis_tready(tready), .m_axis_tdata(m_tdata), .m_axis_tvalid(m_tvalid), .m_axis_tready(m_tready),\n"
        "    .dbg_filter_valid(), .dbg_filter_data(), .dbg_filter_sections(), .dbg_bank_valid(bank_valid),\n"
        "    .dbg_weighted(weighted), .dbg_code(bank_code), .dbg_last(bank_last),\n"
        "    .dbg_energy(energy), .dbg_index(index), .dbg_chip_re(chip_re),\n"
        "    .dbg_chip_im(chip_im),\n"
        "    .dbg_corr_re(), .dbg_corr_im());\n"
        "  always #5 clk = ~clk;\n"
        "  initial begin\n"
        "    $readmemh(\"samples.hex\", mem);\n"
        "    f = $fopen(\"events.txt\", \"w\");\n"
        "    repeat (4) @(posedge clk);\n"
        "    rst <= 0;\n"
        "  end\n"
        "  always @(posedge clk) if (!rst) begin\n"
        "    cycles <= cycles + 1;\n"
        "    m_tready <= ($random & 3) != 0;\n"
        "    if ((^{tready, m_tvalid}) === 1'bx) xs = xs + 1;\n"
        "    // Every decimated correlator output (CODES beats, one per code): index, energy, F, Q of\n"
        "    // every code, written at the group's last beat.\n"
        "    if (bank_valid) begin\n"
        "      group_q[bank_code] = weighted;\n"
        "      if (bank_last) begin\n"
        "        $fwrite(f, \"B %0d %0d %0d %0d\", index, energy, chip_re, chip_im);\n"
        "        for (k = 0; k < " << codes << "; k = k + 1) $fwrite(f, \" %0d\", group_q[k]);\n"
        "        $fwrite(f, \"\\n\");\n"
        "      end\n"
        "    end\n"
        "    if (m_tvalid && m_tready) begin\n"
        "      if ((^m_tdata) === 1'bx) xs = xs + 1;\n"
        "      $fwrite(f, \"%0d %0d %0d %0d\\n\", m_tdata[" << code_w - 1 << ":0], $signed(m_tdata["
     << code_w + arrival_w - 1 << ":" << code_w << "]), m_tdata[" << code_w + arrival_w + score_w - 1 << ":"
     << code_w + arrival_w << "], m_tdata[" << ev_w - 1 << ":" << code_w + arrival_w + score_w << "]);\n"
        "    end\n"
        "    if (tvalid && tready) i = i + 1;\n"
        "    // Offer the next sample (with random gaps); i counts accepted samples.\n"
        "    if (i < " << n_samples << " && ($random & 7) != 0) begin tvalid <= 1; tdata <= mem[i]; end\n"
        "    else tvalid <= 0;\n"
        "  end\n"
        "  // Drain: stop a fixed number of cycles after the last sample was taken.\n"
        "  integer done_at = -1;\n"
        "  always @(posedge clk) if (i >= " << n_samples << " && done_at < 0) done_at = cycles;\n"
        "  always @(posedge clk) if (done_at >= 0 && cycles > done_at + 5000) begin\n"
        "    $fwrite(f, \"X %0d\\n\", xs);\n"
        "    $fclose(f);\n"
        "    $finish;\n"
        "  end\n"
        "endmodule\n";
  return os.str();
}

std::vector<std::int64_t> stimulus(const ReceiverDesign& d, double distance, std::uint64_t seed) {
  ExcitationParams ex;
  const int period = 1400, eta = d.family.eta();
  const std::size_t tof = static_cast<std::size_t>(distance / 340.0 * d.config.fs);
  const std::size_t n = tof + static_cast<std::size_t>(eta * period) + 2500;
  std::vector<double> sum(n, 0.0);
  for (int j = 0; j < eta; ++j) {
    ChannelParams ch;
    ch.distance_m = distance;
    ch.gain = 0.5;
    ch.noise_rms = 0.002;
    ch.seed = seed + static_cast<std::uint64_t>(j);
    const auto rx = propagate(bpsk_excitation(d.family.codes[j], ex), ch, d.config.fs,
                              n - static_cast<std::size_t>(j * period));
    for (std::size_t k = 0; k < rx.size(); ++k) sum[k + static_cast<std::size_t>(j * period)] += rx[k];
  }
  std::vector<std::int64_t> x;
  for (double v : sum) x.push_back(quantize_input(v, d.config.bandpass.input_bits, nullptr));
  return x;
}

}  // namespace

class ReceiverFamiliesIcarus : public ::testing::TestWithParam<const char*> {};

TEST_P(ReceiverFamiliesIcarus, EveryCodeDecodesIdenticallyToTheModel) {
  ReceiverConfig cfg = load_receiver_config(RANGING_CONFIG);
  cfg.family = GetParam();
  cfg.name = std::string("family-") + GetParam();
  const ReceiverDesign d = design_receiver(cfg);
  const fs::path dir = fs::path(RANGING_TRACE_DIR) / "iverilog_families" / GetParam();
  fs::remove_all(dir);
  write_hardware_files(generate_hardware_files(d, "test " + cfg.name), dir.string());

  const double distance = 0.1 + 0.05 * (std::string(GetParam()).back() % 9);  // 0.1 .. 0.5 m
  const auto x = stimulus(d, distance, 1234);
  std::vector<EventFixed> expected;
  std::vector<std::string> expected_bank;  // "index energy F_re F_im Q_1 .. Q_eta" per decimated output
  {
    ReceiverFixed rx(d);
    for (auto v : x) {
      if (auto e = rx.execute_raw(v)) expected.push_back(*e);
      const auto& b = rx.bank();
      if ((b.sample_index() + 1) % b.layout().decimation == 0) {
        std::ostringstream os;
        os << b.sample_index() << " " << b.energy() << " " << b.chip_re() << " " << b.chip_im();
        for (auto q : b.weighted_power()) os << " " << q;
        expected_bank.push_back(os.str());
      }
    }
  }
  {
    std::ofstream hex(dir / "samples.hex");
    const int w = d.config.bandpass.input_bits;
    for (auto v : x) hex << std::hex << (static_cast<std::uint64_t>(v) & ((1u << w) - 1)) << "\n";
    std::ofstream(dir / "bench.v") << bench(d, x.size());
  }
  std::string cmd = "cd " + dir.string() + " && iverilog -g2012 -s iv_top -o sim.vvp bench.v rtl/receiver_top.v";
  for (const auto& f : receiver_rtl_sources()) cmd += " " + std::string(RANGING_SOURCE_DIR) + "/rtl/" + f;
  cmd += " > build.log 2>&1 && vvp -n sim.vvp > run.log 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << "see " << dir.string() << "/build.log and run.log";

  std::ifstream ev(dir / "events.txt");
  std::vector<EventFixed> got;
  std::vector<std::string> got_bank;
  std::string line;
  long xs = -1;
  while (std::getline(ev, line)) {
    std::istringstream is(line);
    if (line.rfind("B ", 0) == 0) {
      got_bank.push_back(line.substr(2));
      continue;
    }
    if (line.rfind("X ", 0) == 0) {
      std::string tag;
      is >> tag >> xs;
      continue;
    }
    EventFixed e;
    is >> e.code >> e.arrival >> e.score >> e.margin;
    got.push_back(e);
  }
  EXPECT_EQ(xs, 0) << "X on an output after reset";
  ASSERT_EQ(got_bank.size(), expected_bank.size()) << "decimated correlator outputs";
  for (std::size_t i = 0; i < got_bank.size(); ++i) {
    ASSERT_EQ(got_bank[i], expected_bank[i]) << "first mismatch: correlator output " << i
                                             << " (index energy F_re F_im Q_1..Q_eta)";
  }
  ASSERT_EQ(got.size(), expected.size());
  int codes_seen = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i], expected[i]) << "event " << i << ": rtl {" << got[i].code << ", " << got[i].arrival
                                   << "} model {" << expected[i].code << ", " << expected[i].arrival << "}";
    codes_seen |= 1 << expected[i].code;
  }
  for (int j = 1; j <= d.family.eta(); ++j) EXPECT_TRUE(codes_seen & (1 << j)) << "code " << j << " not decoded";
  std::cout << "iverilog " << GetParam() << ": " << x.size() << " samples, " << got_bank.size()
            << " correlator outputs (F, Q of every code, energy) and " << got.size() << " events compared, 0 X\n";
}

INSTANTIATE_TEST_SUITE_P(Paper, ReceiverFamiliesIcarus,
                         ::testing::Values("M1", "M2", "Gold1", "Gold2", "Gold3", "Gold4", "Gold5", "Gold6",
                                           "Gold7"));
