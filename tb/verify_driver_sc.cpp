// SystemC stimulus driver of the Verilated receiver (verilator --sc: receiver_top as an
// SC_MODULE) for `ranging simulate --precision rtl --rtl-simulator systemc` (tool/rtl_runner.cpp
// builds it at run time against the IP folder of any configuration). The SystemC twin of
// tb/verify_driver.cpp: the same stimulus and output formats (see there), the clock and the
// handshakes driven through sc_signals under the SystemC kernel.
//
// Usage: verify_driver_sc STIMULUS OUTPUT
#include <systemc>

#include <cinttypes>
#include <cstdio>
#include <random>
#include <string>
#include <type_traits>
#include <vector>

#include "driver_stimulus.hpp"  // next to this file

#include "Vreceiver_top.h"

namespace {

// A port value as hex, most significant digit first: integral ports (Verilator maps <= 64 bits
// to bool / uint32_t / uint64_t) and sc_bv<N> for wider ones.
template <class T>
void hex(std::FILE* f, const T& v) {
  if constexpr (std::is_integral_v<T>) {
    std::fprintf(f, " %" PRIx64, static_cast<std::uint64_t>(v));
  } else {
    const std::string bits = v.to_string();  // N characters '0'/'1', MSB first
    std::string out;
    const std::size_t pad = (4 - bits.size() % 4) % 4;
    const std::string b = std::string(pad, '0') + bits;
    for (std::size_t i = 0; i < b.size(); i += 4) {
      const int d = (b[i] - '0') * 8 + (b[i + 1] - '0') * 4 + (b[i + 2] - '0') * 2 + (b[i + 3] - '0');
      out += "0123456789abcdef"[d];
    }
    std::fprintf(f, " %s", out.c_str());
  }
}

template <class Port>
using value_t = typename std::remove_reference_t<Port>::data_type;

}  // namespace

int sc_main(int argc, char** argv) {
  sc_core::sc_report_handler::set_actions(sc_core::SC_INFO, sc_core::SC_DO_NOTHING);
  Vreceiver_top top("top");
#define RANGING_SIG(port) sc_core::sc_signal<value_t<decltype(top.port)>> port{#port}; top.port(port)
  RANGING_SIG(clk);
  RANGING_SIG(rst);
  RANGING_SIG(s_axis_tdata);
  RANGING_SIG(s_axis_tvalid);
  RANGING_SIG(s_axis_tready);
  RANGING_SIG(m_axis_tdata);
  RANGING_SIG(m_axis_tvalid);
  RANGING_SIG(m_axis_tready);
  RANGING_SIG(dbg_filter_valid);
  RANGING_SIG(dbg_filter_data);
  RANGING_SIG(dbg_filter_sections);
  RANGING_SIG(dbg_bank_valid);
  RANGING_SIG(dbg_weighted);
  RANGING_SIG(dbg_code);
  RANGING_SIG(dbg_last);
  RANGING_SIG(dbg_energy);
  RANGING_SIG(dbg_index);
  RANGING_SIG(dbg_chip_re);
  RANGING_SIG(dbg_chip_im);
  RANGING_SIG(dbg_corr_re);
  RANGING_SIG(dbg_corr_im);
#undef RANGING_SIG
  using sc_core::SC_NS;
  sc_core::sc_start(sc_core::SC_ZERO_TIME);
  auto half = [&](bool level) {
    clk.write(level);
    sc_core::sc_start(5, SC_NS);
  };
  auto reset = [&] {
    s_axis_tvalid.write(false);
    m_axis_tready.write(false);
    rst.write(true);
    for (int i = 0; i < 4; ++i) {
      half(true);
      half(false);
    }
    rst.write(false);
    sc_core::sc_start(1, SC_NS);
  };
  return ranging::tb::driver_main(argc, argv, "verify_driver_sc", [&](const ranging::tb::DriverRun& run, std::FILE* out) {
    ranging::tb::drive_stream(run, out, reset, [&](bool offer, std::uint64_t data, bool ready, bool* taken) {
      s_axis_tvalid.write(offer);
      if (offer) s_axis_tdata.write(static_cast<value_t<decltype(top.s_axis_tdata)>>(data));
      m_axis_tready.write(ready);
      sc_core::sc_start(1, SC_NS);  // settle the combinational outputs (clock low)
      *taken = s_axis_tready.read();
      bool beat = false;
      if (dbg_filter_valid.read()) {
        std::fputc('F', out);
        hex(out, dbg_filter_data.read());
        hex(out, dbg_filter_sections.read());
        std::fputc('\n', out);
        beat = true;
      }
      if (dbg_bank_valid.read()) {
        std::fputc('B', out);
        hex(out, dbg_code.read());
        hex(out, dbg_last.read());
        hex(out, dbg_weighted.read());
        hex(out, dbg_energy.read());
        hex(out, dbg_index.read());
        hex(out, dbg_chip_re.read());
        hex(out, dbg_chip_im.read());
        hex(out, dbg_corr_re.read());
        hex(out, dbg_corr_im.read());
        std::fputc('\n', out);
        beat = true;
      }
      if (m_axis_tvalid.read() && m_axis_tready.read()) {
        std::fputc('E', out);
        hex(out, m_axis_tdata.read());
        std::fputc('\n', out);
        beat = true;
      }
      half(true);   // rising edge
      clk.write(false);
      sc_core::sc_start(4, SC_NS);
      return beat;
    });
  });
}
