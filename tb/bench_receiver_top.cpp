// Benchmark (not a test): simulated samples per second of the Verilated receiver_top (default
// configuration) and of the fixed-point golden model on the same input, and their ratio.
//   build/tb/bench_receiver_top [CPU seconds per measurement]
// Rates are samples per second of this thread's CPU time, so a busy machine does not scale
// them down (wall time would).
#include <algorithm>
#include <ctime>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <random>
#include <vector>

#include "Vreceiver_top.h"
#include "model/config/receiver_config.hpp"
#include "model/sim/channel.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/receiver.hpp"
#include "tb/verilator_harness.hpp"

using namespace ranging;

#ifndef RANGING_BENCH_BUILD
#define RANGING_BENCH_BUILD "unknown compiler"
#endif

namespace {
double cpu_seconds() {  // CPU time of this thread: per-core figures on a shared machine
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
volatile std::uint64_t benchmark_sink = 0;
}  // namespace

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

  // Golden model: the block API (what a decode or a scene runs), the per-sample API (what the
  // testbenches drive) and the float reference; the block and per-sample events must agree.
  std::vector<EventFixed> ev_sample, ev_block;
  {
    ReceiverFixed rx(d);
    for (auto v : x) {
      if (auto e = rx.execute_raw(v)) ev_sample.push_back(*e);
    }
    if (auto e = rx.flush_raw()) ev_sample.push_back(*e);
    ReceiverFixed rb(d);
    rb.execute_block(x, ev_block);
    if (auto e = rb.flush_raw()) ev_block.push_back(*e);
    if (ev_sample != ev_block || rx.overflow_events().total() != rb.overflow_events().total()) {
      std::fprintf(stderr, "bench_receiver_top: block and per-sample models disagree\n");
      return 1;
    }
  }
  const auto timed = [&](auto&& pass) {  // samples per second of CPU time of this thread
    std::uint64_t samples = 0;
    const double c0 = cpu_seconds();
    while (cpu_seconds() - c0 < budget) {
      pass();
      samples += x.size();
    }
    return static_cast<double>(samples) / (cpu_seconds() - c0);
  };
  std::uint64_t model_events = 0;
  const double block_rate = timed([&] {
    ReceiverFixed rx(d);
    std::vector<EventFixed> ev;
    rx.execute_block(x, ev);
    model_events += ev.size();
  });
  const double sample_rate = timed([&] {
    ReceiverFixed rx(d);
    for (auto v : x) benchmark_sink = benchmark_sink + rx.execute_raw(v).has_value();
  });
  const double float_rate = timed([&] {
    ReceiverFloat rx(d);
    for (double v : sum) benchmark_sink = benchmark_sink + rx.execute(v).has_value();
  });
  const double model_rate = block_rate;

  // Verilated RTL, samples offered back to back, events always accepted.
  tb::Harness<Vreceiver_top> h("bench_receiver_top");  // tb/verilator_harness.hpp (no trace compiled in)
  Vreceiver_top& dut = h.top();
  std::uint64_t rtl_samples = 0, rtl_events = 0, cycles = 0;
  // Each pass's rate too: other jobs on a shared machine only ever slow a pass down, so the
  // median pass and the fastest one say how much of the mean is the machine, not the model.
  std::vector<double> pass_rates;
  const double t1 = cpu_seconds();
  while (cpu_seconds() - t1 < budget) {
    const double p0 = cpu_seconds();
    h.reset(4);
    dut.m_axis_tready = 1;
    std::size_t next = 0;
    // Two evaluations per cycle, the least an edge needs: the falling edge and the new inputs
    // in one (the design has no negedge logic), then the rising edge. Harness::tick()'s
    // three (plus settle) are for the testbenches' traces.
    while (next < x.size()) {
      dut.clk = 0;
      dut.s_axis_tvalid = 1;
      dut.s_axis_tdata = static_cast<std::uint16_t>(x[next]) & 0xfff;
      dut.eval();
      if (dut.s_axis_tready) ++next;
      rtl_events += dut.m_axis_tvalid;
      dut.clk = 1;
      dut.eval();
      ++cycles;
    }
    dut.clk = 0;
    dut.eval();
    rtl_samples += x.size();
    pass_rates.push_back(static_cast<double>(x.size()) / (cpu_seconds() - p0));
  }
  const double rtl_s = cpu_seconds() - t1;
  const double rtl_rate = rtl_samples / rtl_s;
  const double fs = d.config.fs;
  std::printf("receiver_top (default configuration, %s), samples per second of CPU time (one core):\n",
              d.family.name.c_str());
  std::printf("  (bench build: %s)\n", RANGING_BENCH_BUILD);
  std::printf("  golden model ReceiverFixed, block API: %12.0f samples/s  (%.1f x real time at %.0f MS/s)\n",
              block_rate, block_rate / fs, fs / 1e6);
  std::printf("  golden model ReceiverFixed, per sample:%12.0f samples/s  (%.1f x real time)\n", sample_rate,
              sample_rate / fs);
  std::printf("  float model ReceiverFloat, per sample: %12.0f samples/s  (%.1f x real time)\n", float_rate,
              float_rate / fs);
  std::printf("  Verilator RTL:                         %12.0f samples/s  (%.1f clock cycles/sample, %.0f cycles/s)\n",
              rtl_rate, static_cast<double>(cycles) / rtl_samples, cycles / rtl_s);
  std::sort(pass_rates.begin(), pass_rates.end());
  std::printf("  Verilator RTL, per pass:               %12.0f samples/s median, %.0f fastest (%zu passes)\n",
              pass_rates[pass_rates.size() / 2], pass_rates.back(), pass_rates.size());
  std::printf("  ratio model (block) / RTL:             %12.1f\n", model_rate / rtl_rate);
  std::printf("  events per pass of %zu samples: model %zu, RTL %.1f\n", x.size(), ev_block.size(),
              static_cast<double>(rtl_events) * x.size() / rtl_samples);
  (void)model_events;
  return 0;
}
