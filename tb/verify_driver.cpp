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
  return ranging::tb::driver_main(argc, argv, "verify_driver", [](const ranging::tb::DriverRun& run, std::FILE* out) {
    Dut d(std::string("verify_") + run.name);
    auto& t = d.top();
    ranging::tb::drive_stream(
        run, out, [&] { reset(d); },
        [&](bool offer, std::uint64_t data, bool ready, bool* taken) {
          t.s_axis_tvalid = offer;
          if (offer) t.s_axis_tdata = static_cast<std::remove_reference_t<decltype(t.s_axis_tdata)>>(data);
          t.m_axis_tready = ready;
          d.settle();
          *taken = t.s_axis_tready;
          bool beat = false;
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
          return beat;
        });
  });
}
