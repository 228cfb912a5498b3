// Stimulus driver of a Verilated receiver_top for `ranging verify` and `ranging simulate
// --precision rtl` (tool/rtl_runner.cpp builds it at run time with `verilator --build` against
// the generated IP folder of any configuration). It knows no model and no widths: it streams
// the samples it is given with random valid gaps and back-pressure, and writes every completed
// tap beat as raw hex port values; the tool decodes the fields and compares them with the
// golden model stage by stage.
//
// Usage: verify_driver STIMULUS OUTPUT
// STIMULUS (text), any number of runs:
//   run NAME VALID_PROB READY_PROB SEED RESET_AT QUIET N CADENCE
//   x_0 ... x_{N-1}              (s_axis_tdata values, already masked to IN_W bits)
// RESET_AT: the sample index before which rst is pulsed mid-stream (-1: none). QUIET: clock
// cycles without any output beat, after the last sample was taken, that end the run.
// CADENCE: 0, samples offered with probability VALID_PROB each cycle; K > 0, sample i is due at
// cycle i K (an ADC at clk / K; VALID_PROB unused) and one taken after its due cycle is late.
// OUTPUT, per run:
//   run NAME
//   F <dbg_filter_data> <dbg_filter_sections>                  a filter output (hex)
//   B <code> <last> <weighted> <energy> <index> <chip_re> <chip_im> <corr_re> <corr_im>
//   E <m_axis_tdata>                                           an event
//   R                                                          rst pulsed here
//   S <samples taken>                                          stalled: s_axis_tready stuck low
//   end <samples taken> <cycles> <late samples>
// Hex values are the whole port, most significant word first (VlWide: 32-bit words).
// RANGING_TRACE=1 writes $RANGING_TRACE_DIR/verify_<NAME>.fst (when compiled with --trace-fst;
// tb/verilator_harness.hpp, "." when RANGING_TRACE_DIR is unset).
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "Vreceiver_top.h"
#include "driver_stimulus.hpp"    // next to this file: the stimulus reader
#include "verilator_harness.hpp"  // next to this file: the shared harness

namespace {

template <class T>
void hex(std::FILE* f, const T& v) {
  static_assert(std::is_integral_v<T>);
  std::fprintf(f, " %" PRIx64, static_cast<std::uint64_t>(v));
}
template <std::size_t N>
void hex(std::FILE* f, const VlWide<N>& v) {
  std::fputc(' ', f);
  for (std::size_t i = N; i-- > 0;) std::fprintf(f, "%08" PRIx32, static_cast<std::uint32_t>(v.at(i)));
}

using Dut = ranging::tb::Harness<Vreceiver_top>;

void reset(Dut& d) {
  d.top().s_axis_tvalid = 0;
  d.top().m_axis_tready = 0;
  d.reset(4);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: verify_driver STIMULUS OUTPUT\n");
    return 2;
  }
  std::FILE* in = std::fopen(argv[1], "r");
  std::FILE* out = std::fopen(argv[2], "w");
  if (!in || !out) {
    std::fprintf(stderr, "verify_driver: cannot open %s or %s\n", argv[1], argv[2]);
    return 2;
  }
  ranging::tb::DriverRun run;
  int got = 0;
  while ((got = ranging::tb::read_run(in, run)) > 0) {
    const char* name = run.name.c_str();
    const double valid_prob = run.valid_prob, ready_prob = run.ready_prob;
    const unsigned long long seed = run.seed, quiet = run.quiet, cadence = run.cadence;
    long long reset_at = run.reset_at;
    const std::vector<std::uint64_t>& x = run.x;
    std::fprintf(out, "run %s\n", name);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Dut d(std::string("verify_") + name);
    reset(d);
    std::size_t next = 0;
    std::uint64_t cycles = 0, idle = 0, silent = 0, late = 0, due = 0;
    bool stalled = false;
    while (next < x.size() || silent < quiet) {
      if (reset_at >= 0 && next == static_cast<std::size_t>(reset_at)) {
        reset(d);
        std::fprintf(out, "R\n");
        reset_at = -1;
      }
      const bool offer = next < x.size() && (cadence ? cycles >= due : u(rng) < valid_prob);
      d.top().s_axis_tvalid = offer;
      if (offer) d.top().s_axis_tdata = static_cast<std::remove_reference_t<decltype(d.top().s_axis_tdata)>>(x[next]);
      d.top().m_axis_tready = u(rng) < ready_prob;
      d.settle();
      bool beat = false;
      if (offer && d.top().s_axis_tready) {
        ++next;
        idle = 0;
        if (cadence) {
          if (cycles > due) ++late;
          due += cadence;
        }
      }
      auto& t = d.top();
      if (t.dbg_filter_valid) {
        std::fputc('F', out);
        hex(out, t.dbg_filter_data);
        hex(out, t.dbg_filter_sections);
        std::fputc('\n', out);
        beat = true;
      }
      if (t.dbg_bank_valid) {
        std::fputc('B', out);
        hex(out, t.dbg_code);
        hex(out, t.dbg_last);
        hex(out, t.dbg_weighted);
        hex(out, t.dbg_energy);
        hex(out, t.dbg_index);
        hex(out, t.dbg_chip_re);
        hex(out, t.dbg_chip_im);
        hex(out, t.dbg_corr_re);
        hex(out, t.dbg_corr_im);
        std::fputc('\n', out);
        beat = true;
      }
      if (t.m_axis_tvalid && t.m_axis_tready) {
        std::fputc('E', out);
        hex(out, t.m_axis_tdata);
        std::fputc('\n', out);
        beat = true;
      }
      d.tick();
      ++cycles;
      silent = (beat || next < x.size()) ? 0 : silent + 1;
      if (next < x.size() && ++idle > 200000) {
        stalled = true;
        break;
      }
    }
    if (stalled) std::fprintf(out, "S %zu\n", next);
    std::fprintf(out, "end %zu %" PRIu64 " %" PRIu64 "\n", next, cycles, late);
  }
  std::fclose(out);
  std::fclose(in);
  if (got < 0) {
    std::fprintf(stderr, "verify_driver: run %s: short sample list\n", run.name.c_str());
    return 2;
  }
  return 0;
}
