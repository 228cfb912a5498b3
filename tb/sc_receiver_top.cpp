// SystemC testbench: the Verilated receiver (verilator --sc) beside the golden model wrapped
// as an SC_MODULE, fed by the same sample stream through sc_fifo channels; a checker compares
// their event streams. Exit status 0 only when both produced the same events, bit for bit.
//
//   Source --sc_fifo--> DutAdapter (AXI-Stream handshake on Vreceiver_top) --sc_fifo--> Checker
//          --sc_fifo--> GoldenModel (ReceiverFixed)                        --sc_fifo--> Checker
#include <systemc>

#include <iostream>
#include <type_traits>
#include <random>

#include "Vreceiver_top.h"
#include "model/config/receiver_config.hpp"
#include "model/sim/channel.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/receiver.hpp"

using namespace sc_core;
using ranging::EventFixed;

namespace {

const ranging::ReceiverDesign& design() {
  static const ranging::ReceiverDesign d =
      ranging::design_receiver(ranging::load_receiver_config(RANGING_CONFIG));
  return d;
}

// Gold4 bursts 1..eta every 1400 samples, received at 0.3 m with a little noise, ADC-quantized.
std::vector<std::int64_t> stimulus() {
  const auto& d = design();
  ranging::ExcitationParams ex;
  const int period = 1400, eta = d.family.eta();
  const std::size_t n = 5000 + static_cast<std::size_t>(eta * period) + 3000;
  std::vector<double> sum(n, 0.0);
  for (int j = 0; j < eta; ++j) {
    ranging::ChannelParams ch;
    ch.distance_m = 0.3;
    ch.gain = 0.5;
    ch.noise_rms = 0.002;
    ch.seed = static_cast<std::uint64_t>(j + 1);
    const auto rx = ranging::propagate(ranging::bpsk_excitation(d.family.codes[j], ex), ch, 5e6,
                                       n - static_cast<std::size_t>(j * period));
    for (std::size_t k = 0; k < rx.size(); ++k) sum[k + static_cast<std::size_t>(j * period)] += rx[k];
  }
  std::vector<std::int64_t> x;
  for (double v : sum) x.push_back(ranging::quantize_input(v, d.config.bandpass.input_bits, nullptr));
  return x;
}

}  // namespace

namespace ranging {
// sc_fifo<T> prints its contents with operator<< (found by ADL).
inline std::ostream& operator<<(std::ostream& os, const EventFixed& e) {
  return os << "{code " << e.code << ", arrival " << e.arrival << ", score " << e.score << ", margin "
            << e.margin << "}";
}
}  // namespace ranging

// The value type of a Verilated SystemC port (sc_in<T> / sc_out<T>).
#define PORT_T(name) std::remove_reference_t<decltype(std::declval<Vreceiver_top>().name)>::data_type

SC_MODULE(Source) {
  sc_fifo_out<std::int64_t> to_dut, to_model;
  std::vector<std::int64_t> samples;
  void run() {
    for (auto v : samples) {
      to_dut.write(v);
      to_model.write(v);
    }
  }
  SC_CTOR(Source) { SC_THREAD(run); }
};

SC_MODULE(GoldenModel) {
  sc_fifo_in<std::int64_t> in;
  sc_fifo_out<EventFixed> events;
  void run() {
    ranging::ReceiverFixed rx(design());
    while (true) {
      if (auto e = rx.execute_raw(in.read())) events.write(*e);
    }
  }
  SC_CTOR(GoldenModel) { SC_THREAD(run); }
};

SC_MODULE(DutAdapter) {
  sc_in<bool> clk;
  sc_out<bool> rst;
  sc_fifo_in<std::int64_t> in;
  sc_fifo_out<EventFixed> events;
  sc_out<PORT_T(s_axis_tdata)> tdata;
  sc_out<bool> tvalid, m_tready;
  sc_in<bool> tready, m_tvalid;
  sc_in<PORT_T(m_axis_tdata)> m_tdata;
  std::uint64_t accepted = 0;

  void drive() {
    std::mt19937 rng(5);
    rst.write(true);
    tvalid.write(false);
    for (int i = 0; i < 4; ++i) wait(clk.posedge_event());
    rst.write(false);
    bool have = false;
    std::int64_t sample = 0;
    while (true) {
      if (!have && in.num_available() > 0) {
        sample = in.read();
        have = true;
      }
      const bool offer = have && (rng() % 4 != 0);  // random gaps in tvalid
      tvalid.write(offer);
      tdata.write(static_cast<std::uint32_t>(sample) & ((1u << design().config.bandpass.input_bits) - 1));
      wait(clk.posedge_event());
      if (offer && tready.read()) {
        have = false;
        ++accepted;
      }
    }
  }
  void collect() {
    std::mt19937 rng(9);
    const int code_w = 4, arrival_w = 40 + design().config.detector.frac_bits + 1;
    const int score_w = design().config.correlator.score_bits;
    while (true) {
      const bool ready = rng() % 3 != 0;  // random back-pressure
      m_tready.write(ready);
      wait(clk.posedge_event());
      if (ready && m_tvalid.read()) {
        const auto w = m_tdata.read();
        auto field = [&](int lo, int width) { return w.range(lo + width - 1, lo).to_uint64(); };
        EventFixed e;
        e.code = static_cast<int>(field(0, code_w));
        const std::uint64_t a = field(code_w, arrival_w);
        const std::uint64_t m = std::uint64_t{1} << (arrival_w - 1);
        e.arrival = static_cast<std::int64_t>((a ^ m) - m);
        e.score = field(code_w + arrival_w, score_w);
        e.margin = field(code_w + arrival_w + score_w, score_w);
        events.write(e);
      }
    }
  }
  SC_CTOR(DutAdapter) {
    SC_THREAD(drive);
    SC_THREAD(collect);
  }
};

SC_MODULE(Checker) {
  sc_in<bool> clk;
  sc_fifo_in<EventFixed> dut, model;
  const DutAdapter* adapter = nullptr;
  std::size_t expected = 0, samples = 0, compared = 0, mismatches = 0, extra = 0;
  void run() {
    while (compared < expected) {
      const EventFixed a = dut.read();
      const EventFixed b = model.read();
      if (!(a == b)) {
        ++mismatches;
        std::cerr << "event " << compared << ": rtl " << a << " model " << b << "\n";
      }
      ++compared;
    }
    // Every sample must go through, and no further event may come out of the drained RTL.
    while (adapter->accepted < samples) wait(clk.posedge_event());
    for (int i = 0; i < 20000; ++i) wait(clk.posedge_event());
    extra = static_cast<std::size_t>(dut.num_available());
    sc_stop();
  }
  SC_CTOR(Checker) { SC_THREAD(run); }
};

int sc_main(int, char**) {
  const auto samples = stimulus();
  // How many events the model gives for the whole stream (the checker waits for them all).
  std::size_t expected = 0;
  {
    ranging::ReceiverFixed rx(design());
    for (auto v : samples) expected += rx.execute_raw(v).has_value();
  }
  sc_clock clk("clk", 10, SC_NS);
  sc_signal<bool> rst, tvalid, tready, m_tvalid, m_tready;
  sc_signal<PORT_T(s_axis_tdata)> tdata;
  sc_signal<PORT_T(m_axis_tdata)> m_tdata;
  sc_signal<PORT_T(dbg_filter_valid)> d0;
  sc_signal<PORT_T(dbg_filter_data)> d1;
  sc_signal<PORT_T(dbg_filter_sections)> d2;
  sc_signal<PORT_T(dbg_bank_valid)> d3;
  sc_signal<PORT_T(dbg_weighted)> d4;
  sc_signal<PORT_T(dbg_energy)> d5;
  sc_signal<PORT_T(dbg_index)> d6;
  sc_signal<PORT_T(dbg_chip_re)> d7, d8;
  sc_signal<PORT_T(dbg_corr_re)> d9, d10;
  sc_signal<PORT_T(dbg_code)> d11;
  sc_signal<PORT_T(dbg_last)> d12;

  Vreceiver_top dut("dut");
  dut.clk(clk);
  dut.rst(rst);
  dut.s_axis_tdata(tdata);
  dut.s_axis_tvalid(tvalid);
  dut.s_axis_tready(tready);
  dut.m_axis_tdata(m_tdata);
  dut.m_axis_tvalid(m_tvalid);
  dut.m_axis_tready(m_tready);
  dut.dbg_filter_valid(d0);
  dut.dbg_filter_data(d1);
  dut.dbg_filter_sections(d2);
  dut.dbg_bank_valid(d3);
  dut.dbg_weighted(d4);
  dut.dbg_energy(d5);
  dut.dbg_index(d6);
  dut.dbg_chip_re(d7);
  dut.dbg_chip_im(d8);
  dut.dbg_corr_re(d9);
  dut.dbg_corr_im(d10);
  dut.dbg_code(d11);
  dut.dbg_last(d12);

  sc_fifo<std::int64_t> src_dut(64), src_model(64);
  sc_fifo<EventFixed> ev_dut(16), ev_model(static_cast<int>(expected) + 1);
  Source source("source");
  source.samples = samples;
  source.to_dut(src_dut);
  source.to_model(src_model);
  GoldenModel model("model");
  model.in(src_model);
  model.events(ev_model);
  DutAdapter adapter("adapter");
  adapter.clk(clk);
  adapter.rst(rst);
  adapter.in(src_dut);
  adapter.events(ev_dut);
  adapter.tdata(tdata);
  adapter.tvalid(tvalid);
  adapter.tready(tready);
  adapter.m_tvalid(m_tvalid);
  adapter.m_tready(m_tready);
  adapter.m_tdata(m_tdata);
  Checker checker("checker");
  checker.clk(clk);
  checker.adapter = &adapter;
  checker.samples = samples.size();
  checker.expected = expected;
  checker.dut(ev_dut);
  checker.model(ev_model);

  sc_start(static_cast<double>(samples.size()) * 10 * 40, SC_NS);  // generous: stops at sc_stop
  std::cout << "systemc: " << adapter.accepted << "/" << samples.size() << " samples through the RTL, "
            << checker.compared << "/" << expected << " events compared, " << checker.mismatches
            << " mismatches, " << checker.extra << " extra events\n";
  const bool ok = expected > 0 && checker.compared == expected && checker.mismatches == 0 &&
                  checker.extra == 0 && adapter.accepted == samples.size();
  return ok ? 0 : 1;
}
