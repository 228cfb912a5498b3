// Benchmark (not a test): simulated samples per second of the Verilated receiver_top (default
// configuration) and of the fixed-point golden model on the same input, and their ratio.
//   build/tb/bench_receiver_top [seconds-per-measurement]
#include <verilated.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>

#include "Vreceiver_top.h"
#include "model/config/receiver_config.hpp"
#include "model/sim/channel.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/receiver.hpp"

using namespace ranging;
using Clock = std::chrono::steady_clock;

int main(int argc, char** argv) {
  const double budget = argc > 1 ? std::atof(argv[1]) : 2.0;
  const ReceiverDesign d = design_receiver(load_receiver_config(RANGING_CONFIG));
  // The paper's schedule: every code once per period, received at 0.5 m with noise.
  ExcitationParams ex;
  const int period = 1400, eta = d.family.eta();
  const std::size_t n = 7353 + static_cast<std::size_t>(eta * period) + 3000;
  std::vector<double> sum(n, 0.0);
  for (int j = 0; j < eta; ++j) {
    ChannelParams ch;
    ch.distance_m = 0.5;
    ch.gain = 0.5;
    ch.noise_rms = 0.002;
    ch.seed = static_cast<std::uint64_t>(j + 1);
    const auto rx = propagate(bpsk_excitation(d.family.codes[j], ex), ch, d.config.fs, n - static_cast<std::size_t>(j * period));
    for (std::size_t k = 0; k < rx.size(); ++k) sum[k + static_cast<std::size_t>(j * period)] += rx[k];
  }
  std::vector<std::int64_t> x;
  for (double v : sum) x.push_back(quantize_input(v, d.config.bandpass.input_bits, nullptr));

  // Golden model.
  std::uint64_t model_samples = 0, model_events = 0;
  const auto t0 = Clock::now();
  while (std::chrono::duration<double>(Clock::now() - t0).count() < budget) {
    ReceiverFixed rx(d);
    for (auto v : x) model_events += rx.execute_raw(v).has_value();
    model_samples += x.size();
  }
  const double model_s = std::chrono::duration<double>(Clock::now() - t0).count();

  // Verilated RTL, samples offered back to back, events always accepted.
  VerilatedContext ctx;
  Vreceiver_top dut(&ctx);
  std::uint64_t rtl_samples = 0, rtl_events = 0, cycles = 0;
  const auto t1 = Clock::now();
  while (std::chrono::duration<double>(Clock::now() - t1).count() < budget) {
    dut.rst = 1;
    for (int i = 0; i < 4; ++i) {
      dut.clk = 0; dut.eval(); dut.clk = 1; dut.eval();
    }
    dut.rst = 0;
    dut.m_axis_tready = 1;
    std::size_t next = 0;
    while (next < x.size()) {
      dut.s_axis_tvalid = 1;
      dut.s_axis_tdata = static_cast<std::uint16_t>(x[next]) & 0xfff;
      dut.clk = 0;
      dut.eval();
      if (dut.s_axis_tready) ++next;
      rtl_events += dut.m_axis_tvalid;
      dut.clk = 1;
      dut.eval();
      ++cycles;
    }
    rtl_samples += x.size();
  }
  const double rtl_s = std::chrono::duration<double>(Clock::now() - t1).count();
  const double model_rate = model_samples / model_s, rtl_rate = rtl_samples / rtl_s;
  std::printf("receiver_top (default configuration, %s):\n", d.family.name.c_str());
  std::printf("  golden model (ReceiverFixed): %10.0f samples/s  (%.1f x real time at %.0f MS/s)\n", model_rate,
              model_rate / d.config.fs, d.config.fs / 1e6);
  std::printf("  Verilator RTL:                %10.0f samples/s  (%.1f clock cycles/sample, %.0f cycles/s)\n",
              rtl_rate, static_cast<double>(cycles) / rtl_samples, cycles / rtl_s);
  std::printf("  ratio model / RTL:            %10.1f\n", model_rate / rtl_rate);
  std::printf("  events per pass of %zu samples: model %.1f, RTL %.1f\n", x.size(),
              static_cast<double>(model_events) * x.size() / model_samples,
              static_cast<double>(rtl_events) * x.size() / rtl_samples);
  dut.final();
  return 0;
}
