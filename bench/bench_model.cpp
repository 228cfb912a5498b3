// The golden model stage by stage (Google Benchmark; timing lives here, never in tests), on the
// default configuration (configs/default.yaml) and the paper's schedule: every code of the
// family once per 1400 samples, received at 0.5 m with noise (as tb/bench_receiver_top).
//   Fixed/Bandpass   BandpassFixed::execute_block (5 sections)
//   Fixed/Bank       CorrelatorBankFixed::feed on the filtered signal
//   Fixed/Receiver   ReceiverFixed::execute_block: bandpass + bank + detector
//   Fixed/ReceiverBatch8  ReceiverFixedBatch: 8 streams (the same capture with different noise)
//                    in the 8 lanes of the AVX-512 kernels (SIMD across streams); samples of
//                    all 8 streams per second, on one core (label says which path ran)
//   Float/ReceiverBatch8  ReceiverFloatBatch, the same for the float receiver
//   Float/...        the same stages of the double-precision reference, block forms
//                    (BandpassFloat::execute_block, CorrelatorBankFloat::feed,
//                    ReceiverFloat::execute_block: what scenes and decode run)
// The detector's share is Receiver - Bandpass - Bank. The channel's stages:
//   WhiteNoise      add_white_noise (Boost ziggurat + mt19937_64), the scenes' noise
//   StdNormalNoise  std::normal_distribution + std::mt19937_64, the generator it replaced
//   Adc             adc_quantize, the scenes' 12-bit ADC
//   ChannelClean    propagate without noise: two transducers and the 64-tap fractional delay
//                   (a scene computes this once per code and distance, then reuses it)
// The decode's metrics of one burst (streaming decode, ranging decode):
//   PearsonSearch   PearsonBank::search over the Gold4 decode's window: 9 references of 1000
//                   samples, lags +-700 (2400 samples, 2560-point transforms); items = bursts/s
//   DurationTd      duration_td_stream of one burst (noise median over 2000 samples, the walk)
// items_per_second = samples/s (bursts/s for the two above).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

#include "model/config/receiver_config.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/receiver.hpp"
#include "model/dsp/receiver_batch.hpp"
#include "model/sim/channel.hpp"
#include "model/sim/front_end.hpp"
#include "model/sim/metrics.hpp"
#include "model/sim/scene.hpp"

int sc_main(int, char**) { return 0; }  // the bench programs link libsystemc, which references it

namespace {

using namespace ranging;

struct Setup {
  ReceiverDesign d = design_receiver(load_receiver_config(RANGING_CONFIG));
  std::vector<double> x;           // full-scale units
  std::vector<std::int64_t> codes; // ADC codes
  std::vector<std::int64_t> filtered;
  std::vector<double> filtered_float;
  Setup() {
    ExcitationParams ex;
    const int period = 1400, eta = d.family.eta();
    const std::size_t n = 7353 + static_cast<std::size_t>(eta * period) + 3000;
    x.assign(n, 0.0);
    for (int j = 0; j < eta; ++j) {
      ChannelParams ch;
      ch.distance_m = 0.5;
      ch.gain = 0.5;
      ch.noise_rms = 0.002;
      ch.seed = static_cast<std::uint64_t>(j + 1);
      const auto rx = propagate(bpsk_excitation(d.family.codes[j], ex), ch, d.config.fs,
                                n - static_cast<std::size_t>(j * period));
      for (std::size_t k = 0; k < rx.size(); ++k) x[k + static_cast<std::size_t>(j * period)] += rx[k];
    }
    for (double v : x) codes.push_back(quantize_input(v, d.config.bandpass.input_bits, nullptr));
    BandpassFixed bp(d.filter, d.config.bandpass);
    filtered.resize(codes.size());
    bp.execute_block(codes, filtered);
    BandpassFloat bf(d.filter);
    for (double v : x) filtered_float.push_back(bf.execute(v));
  }
};

const Setup& setup() {
  static const Setup s;
  return s;
}

void items(benchmark::State& state) {
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(setup().x.size()));
}

void BM_FixedBandpass(benchmark::State& state) {
  const Setup& s = setup();
  BandpassFixed bp(s.d.filter, s.d.config.bandpass);
  std::vector<std::int64_t> out(s.codes.size());
  for (auto _ : state) {
    bp.reset();
    bp.execute_block(s.codes, out);
    benchmark::DoNotOptimize(out.data());
  }
  items(state);
}

// The bank as the receiver runs it on this block: time-split on the SIMD lanes when it can
// (CorrelatorBankFixed::feed_split; the label says), else the plain feed loop.
void BM_FixedBank(benchmark::State& state) {
  const Setup& s = setup();
  CorrelatorBankFixed bank(s.d.reference, s.d.config.correlator);
  for (auto _ : state) {
    bank.reset();
    std::uint64_t outputs = 0;
    if (!bank.feed_split(s.filtered, [&](std::span<const std::uint64_t>, std::span<const std::uint64_t>, std::int64_t, std::uint64_t) {
          ++outputs;
        })) {
      std::span<const std::int64_t> rest(s.filtered);
      while (!rest.empty()) {
        rest = rest.subspan(bank.feed(rest));
        outputs += bank.output_ready();
      }
    }
    benchmark::DoNotOptimize(outputs);
  }
  items(state);
  state.SetLabel(bank.split_blocks() > 0 ? "time split" : "plain");
}

void BM_FixedReceiver(benchmark::State& state) {
  const Setup& s = setup();
  ReceiverFixed rx(s.d);
  std::vector<EventFixed> ev;
  for (auto _ : state) {
    rx.reset();
    ev.clear();
    rx.execute_block(s.codes, ev);
    benchmark::DoNotOptimize(ev.data());
  }
  items(state);
}

void BM_FixedReceiverBatch8(benchmark::State& state) {
  const Setup& s = setup();
  // 8 streams: the capture with 8 noise draws (the same events, different codes)
  std::vector<std::vector<std::int64_t>> streams;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.003);
  for (int l = 0; l < 8; ++l) {
    std::vector<std::int64_t> q;
    for (double v : s.x) q.push_back(quantize_input(std::clamp(v + noise(rng), -1.0, 1.0), s.d.config.bandpass.input_bits, nullptr));
    streams.push_back(std::move(q));
  }
  std::vector<std::span<const std::int64_t>> spans(streams.begin(), streams.end());
  ReceiverFixedBatch batch(s.d);
  std::vector<std::vector<EventFixed>> ev;
  std::vector<OverflowCounter> ovf;
  for (auto _ : state) {
    batch.run(spans, ev, ovf);
    benchmark::DoNotOptimize(ev.data());
  }
  state.SetItemsProcessed(state.iterations() * 8 * static_cast<std::int64_t>(s.x.size()));
  state.SetLabel(batch.vectorized() ? "AVX-512" : "scalar per stream");
}

void BM_FloatReceiverBatch8(benchmark::State& state) {
  const Setup& s = setup();
  std::vector<std::vector<double>> streams;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.003);
  for (int l = 0; l < 8; ++l) {
    std::vector<double> v;
    for (double x : s.x) v.push_back(x + noise(rng));
    streams.push_back(std::move(v));
  }
  std::vector<std::span<const double>> spans(streams.begin(), streams.end());
  ReceiverFloatBatch batch(s.d);
  std::vector<std::vector<Event>> ev;
  for (auto _ : state) {
    batch.run(spans, 1.0, ev);
    benchmark::DoNotOptimize(ev.data());
  }
  state.SetItemsProcessed(state.iterations() * 8 * static_cast<std::int64_t>(s.x.size()));
  state.SetLabel(batch.vectorized() ? "AVX-512" : "scalar per stream");
}

void BM_FixedReceiverPerSample(benchmark::State& state) {
  const Setup& s = setup();
  ReceiverFixed rx(s.d);
  for (auto _ : state) {
    rx.reset();
    std::size_t n = 0;
    for (auto v : s.codes) n += rx.execute_raw(v).has_value();
    benchmark::DoNotOptimize(n);
  }
  items(state);
}

void BM_FloatBandpass(benchmark::State& state) {
  const Setup& s = setup();
  BandpassFloat bp(s.d.filter);
  std::vector<double> out(s.x.size());
  for (auto _ : state) {
    bp.reset();
    bp.execute_block(s.x, out);
    benchmark::DoNotOptimize(out.data());
  }
  items(state);
}

void BM_FloatBank(benchmark::State& state) {
  const Setup& s = setup();
  CorrelatorBankFloat bank(s.d.reference);
  // as ReceiverFloat runs it: runs of outputs computed across the outputs, handed over
  for (auto _ : state) {
    bank.reset();
    std::size_t n = 0;
    bank.feed_outputs(s.filtered_float,
                      [&](std::span<const double>, std::span<const double>, std::int64_t, double) { ++n; });
    benchmark::DoNotOptimize(n);
  }
  items(state);
  state.SetLabel("output runs");
}

void BM_FloatReceiver(benchmark::State& state) {
  const Setup& s = setup();
  ReceiverFloat rx(s.d);
  std::vector<Event> ev;
  for (auto _ : state) {
    rx.reset();
    ev.clear();
    rx.execute_block(s.x, ev);
    benchmark::DoNotOptimize(ev.data());
  }
  items(state);
}

// One long stream (the capture tiled to 2^21 samples, as decode's blocks): the bandpass takes
// its time split on the SIMD lanes (BandpassSplitStats), and the fixed bank its own
// (CorrelatorBankFixed::feed_split); the label says how often each ran.
template <class Sample>
std::vector<Sample> tiled(const std::vector<Sample>& v) {
  std::vector<Sample> t;
  while (t.size() < (std::size_t{1} << 21)) t.insert(t.end(), v.begin(), v.end());
  t.resize(std::size_t{1} << 21);
  return t;
}

template <class Receiver, class EventT, class Sample>
void long_stream(benchmark::State& state, const std::vector<Sample>& in) {
  Receiver rx(setup().d);
  std::vector<EventT> ev;
  for (auto _ : state) {
    rx.reset();
    ev.clear();
    rx.execute_block(in, ev);
    benchmark::DoNotOptimize(ev.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(in.size()));
  if constexpr (requires { rx.filter().split_stats(); }) {
    const auto st = rx.filter().split_stats();
    std::string label = "bandpass: " + std::to_string(st.blocks) + " split blocks, " + std::to_string(st.recomputed) +
                        " lanes redone";
    if constexpr (requires { rx.bank().split_blocks(); }) {  // fixed: the bank's split too
      label += "; bank: " + std::to_string(rx.bank().split_blocks()) + " split blocks";
    }
    state.SetLabel(label);
  }
}

void BM_FixedReceiverLong(benchmark::State& state) {
  static const std::vector<std::int64_t> in = tiled(setup().codes);
  long_stream<ReceiverFixed, EventFixed>(state, in);
}

void BM_FloatReceiverLong(benchmark::State& state) {
  static const std::vector<double> in = tiled(setup().x);
  long_stream<ReceiverFloat, Event>(state, in);
}

void BM_WhiteNoise(benchmark::State& state) {
  const Setup& s = setup();
  std::vector<double> y(s.x);
  std::uint64_t seed = 1;
  for (auto _ : state) {
    add_white_noise(y, 0.002, seed++);
    benchmark::DoNotOptimize(y.data());
  }
  items(state);
}

void BM_StdNormalNoise(benchmark::State& state) {
  const Setup& s = setup();
  std::vector<double> y(s.x);
  std::uint64_t seed = 1;
  for (auto _ : state) {
    std::mt19937_64 rng(seed++);
    std::normal_distribution<double> nd(0.0, 0.002);
    for (double& v : y) v += nd(rng);
    benchmark::DoNotOptimize(y.data());
  }
  items(state);
}

void BM_Adc(benchmark::State& state) {
  const Setup& s = setup();
  SceneAdc adc;  // scenes/default.yaml: 12 bits, +-2 V
  adc.bits = 12;
  adc.full_scale_v = 2.0;
  std::vector<double> y(s.x.size());
  std::vector<std::size_t> clipped;
  for (auto _ : state) {
    std::copy(s.x.begin(), s.x.end(), y.begin());
    clipped.clear();
    benchmark::DoNotOptimize(adc_quantize(y, adc, &clipped));
  }
  items(state);
}

void BM_ChannelClean(benchmark::State& state) {
  const Setup& s = setup();
  ExcitationParams ex;
  const auto e = bpsk_excitation(s.d.family.codes[0], ex);
  ChannelParams ch;
  ch.distance_m = 0.5;
  for (auto _ : state) {
    const auto y = propagate(e, ch, s.d.config.fs, s.x.size());
    benchmark::DoNotOptimize(y.data());
  }
  items(state);
}

// A burst of reference 3 at lag 611 of a noisy 2400-sample window; every reference random.
struct PearsonSetup {
  std::vector<std::vector<double>> refs;
  std::vector<double> x;
};
const PearsonSetup& pearson_setup() {
  static const PearsonSetup s = [] {
    PearsonSetup p;
    std::mt19937_64 rng(3);
    std::normal_distribution<double> g(0, 1);
    for (int j = 0; j < 9; ++j) {
      p.refs.emplace_back(1000);
      for (double& v : p.refs.back()) v = g(rng);
    }
    p.x.resize(2400);
    for (double& v : p.x) v = 0.3 * g(rng);
    for (std::size_t i = 0; i < 1000; ++i) p.x[611 + i] += p.refs[2][i];
    return p;
  }();
  return s;
}

void BM_PearsonSearch(benchmark::State& state) {
  const PearsonSetup& s = pearson_setup();
  PearsonBank bank(s.refs);
  for (auto _ : state) benchmark::DoNotOptimize(bank.search(s.x, 0, 1400));
  state.SetItemsProcessed(state.iterations());
}

void BM_DurationTd(benchmark::State& state) {
  const PearsonSetup& s = pearson_setup();
  std::vector<double> x(2000, 0.0);
  x.insert(x.end(), s.x.begin(), s.x.end());
  for (auto _ : state) benchmark::DoNotOptimize(duration_td_stream(x, 2000, x.size(), 2611, 3611, 200, 5e6));
  state.SetItemsProcessed(state.iterations());
}

BENCHMARK(BM_PearsonSearch)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DurationTd)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FixedBandpass)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FixedBank)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FixedReceiver)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FixedReceiverBatch8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FixedReceiverPerSample)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FixedReceiverLong)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FloatReceiverLong)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FloatBandpass)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FloatBank)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FloatReceiver)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FloatReceiverBatch8)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_WhiteNoise)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_StdNormalNoise)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Adc)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ChannelClean)->Unit(benchmark::kMicrosecond);

}  // namespace
