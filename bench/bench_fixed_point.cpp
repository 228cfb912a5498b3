// The bandpass kernel (5-section DF1 biquad cascade, 4096 samples, the paper's design with the
// default word lengths: 12-bit input, Q2.14 coefficients and data, RoundHalfUp + Saturate)
// written four ways, to price the bit-accurate model against SystemC:
//   BandpassFixed     the golden model's kernel per sample (execute_raw: a block of one)
//   BandpassFixedBlock  the same kernel through execute_block (what the model runs)
//   FixedType         the same rules spelled with ranging::Fixed / FixedWide / fixed_cast
//   ScFixed           sc_fixed<16,2,SC_RND,SC_SAT> data, full-precision sc_fxval sums
//   ScFix             sc_fix with runtime parameters (what a word-length sweep would need)
// All four produce the same output (checked once before timing).
#define SC_INCLUDE_FX
#define SC_CPLUSPLUS 201703L
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <span>
#include <string>
#include <systemc>
#include <vector>

#include "model/dsp/bandpass_filter.hpp"
#include "model/dsp/filter_design.hpp"
#include "model/dsp/fixed_point.hpp"

int sc_main(int, char**) { return 0; }  // libsystemc.so references it

namespace {

using namespace ranging;

constexpr int kSamples = 4096;

struct Setup {
  SosFilter design = design_bandpass(BandpassSpec{}, FilterType::Butterworth);
  BandpassFixedConfig cfg;
  std::vector<std::int64_t> input;  // 12-bit codes: a 200 kHz burst
  std::vector<std::vector<std::int64_t>> coef;
  Setup() {
    for (int n = 0; n < kSamples; ++n) {
      input.push_back(std::llround(0.9 * 2047 * std::sin(2 * std::numbers::pi * 200e3 * n / 5e6)));
    }
    coef = BandpassFixed(design, cfg).coefficients();
  }
};

const Setup& setup() {
  static const Setup s;
  return s;
}

std::vector<std::int64_t> run_model(BandpassFixed& f) {
  std::vector<std::int64_t> out(kSamples);
  f.reset();
  for (int n = 0; n < kSamples; ++n) out[n] = f.execute_raw(setup().input[n]);
  return out;
}

std::vector<std::int64_t> run_fixed_type() {
  const Setup& s = setup();
  const FixedFormat in_fmt{s.cfg.input_bits, s.cfg.input_bits - 1};
  const FixedFormat cf{s.cfg.coef_bits, s.cfg.coef_frac};
  const FixedFormat df{s.cfg.data_bits, s.cfg.data_frac, true, s.cfg.rounding, s.cfg.overflow};
  const std::size_t ns = s.coef.size();
  std::vector<std::vector<Fixed>> c(ns), st(ns, std::vector<Fixed>(4, Fixed::from_raw(0, df)));
  for (std::size_t k = 0; k < ns; ++k) {
    for (auto v : s.coef[k]) c[k].push_back(Fixed::from_raw(v, cf));
  }
  std::vector<std::int64_t> out(kSamples);
  OverflowCounter events;
  for (int n = 0; n < kSamples; ++n) {
    Fixed x = Fixed::from_raw(s.input[n], in_fmt);
    for (std::size_t k = 0; k < ns; ++k) {
      auto& q = st[k];
      const FixedWide acc = c[k][0] * x + c[k][1] * q[0] + c[k][2] * q[1] - c[k][3] * q[2] - c[k][4] * q[3];
      const Fixed y = fixed_cast(acc, df, &events);
      q[1] = q[0];
      q[0] = x;
      q[3] = q[2];
      q[2] = y;
      x = y;
    }
    out[n] = x.raw();
  }
  return out;
}

// T: the data type (sc_fixed<...> or sc_fix); make(v) builds one from an sc_fxval.
template <class T, class Make>
std::vector<std::int64_t> run_systemc(Make make) {
  const Setup& s = setup();
  const std::size_t ns = s.coef.size();
  std::vector<std::vector<sc_dt::sc_fxval>> c(ns);
  for (std::size_t k = 0; k < ns; ++k) {
    for (auto v : s.coef[k]) c[k].push_back(sc_dt::sc_fxval(static_cast<double>(v)) >> s.cfg.coef_frac);
  }
  std::vector<std::vector<T>> st(ns, std::vector<T>(4, make(sc_dt::sc_fxval(0.0))));
  std::vector<std::int64_t> out(kSamples);
  for (int n = 0; n < kSamples; ++n) {
    T x = make(sc_dt::sc_fxval(static_cast<double>(s.input[n])) >> (s.cfg.input_bits - 1));
    for (std::size_t k = 0; k < ns; ++k) {
      auto& q = st[k];
      const sc_dt::sc_fxval acc = c[k][0] * x + c[k][1] * q[0] + c[k][2] * q[1] - c[k][3] * q[2] - c[k][4] * q[3];
      const T y = make(acc);
      q[1] = q[0];
      q[0] = x;
      q[3] = q[2];
      q[2] = y;
      x = y;
    }
    out[n] = std::llround(std::ldexp(x.to_double(), s.cfg.data_frac));
  }
  return out;
}

using ScData = sc_dt::sc_fixed<16, 2, sc_dt::SC_RND, sc_dt::SC_SAT>;
ScData make_sc_fixed(const sc_dt::sc_fxval& v) { return ScData(v); }
sc_dt::sc_fix make_sc_fix(const sc_dt::sc_fxval& v) { return sc_dt::sc_fix(v, 16, 2, sc_dt::SC_RND, sc_dt::SC_SAT); }

// Refuse to time kernels that disagree.
void check_agreement() {
  BandpassFixed f(setup().design, setup().cfg);
  const auto ref = run_model(f);
  if (run_fixed_type() != ref || run_systemc<ScData>(make_sc_fixed) != ref ||
      run_systemc<sc_dt::sc_fix>(make_sc_fix) != ref) {
    std::fprintf(stderr, "bench_fixed_point: kernels disagree\n");
    std::exit(1);
  }
}

void BM_BandpassFixed(benchmark::State& state) {
  check_agreement();
  BandpassFixed f(setup().design, setup().cfg);
  for (auto _ : state) benchmark::DoNotOptimize(run_model(f));
  state.SetItemsProcessed(state.iterations() * kSamples);
}
void BM_BandpassFixedBlock(benchmark::State& state) {  // the block API on the same input
  BandpassFixed f(setup().design, setup().cfg);
  std::vector<std::int64_t> out(kSamples);
  {
    f.execute_block(setup().input, out);
    BandpassFixed g(setup().design, setup().cfg);
    if (out != run_model(g)) {
      std::fprintf(stderr, "bench_fixed_point: block and per-sample kernels disagree\n");
      std::exit(1);
    }
  }
  for (auto _ : state) {
    f.reset();
    f.execute_block(setup().input, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kSamples);
}
// The block API on 2^20 samples of the same sine (scipy's 1 M-sample case): one block, which
// the bandpass runs time-split on its SIMD lanes (BandpassSplitStats), checked against 4096-sample
// blocks first. A noiseless sine keeps the warm-up lanes an LSB off the true state, so the split
// fails and the filter backs off to the plain kernel (the label counts it).
void BM_BandpassFixedBlock1M(benchmark::State& state) {
  constexpr std::size_t n = std::size_t{1} << 20;
  std::vector<std::int64_t> in(n), out(n), ref(n);
  for (std::size_t i = 0; i < n; ++i) {
    in[i] = std::llround(0.9 * 2047 * std::sin(2 * std::numbers::pi * 200e3 * static_cast<double>(i) / 5e6));
  }
  BandpassFixed f(setup().design, setup().cfg), g(setup().design, setup().cfg);
  for (std::size_t i = 0; i < n; i += kSamples) {
    g.execute_block(std::span<const std::int64_t>(in).subspan(i, kSamples), std::span<std::int64_t>(ref).subspan(i, kSamples));
  }
  f.execute_block(in, out);
  if (out != ref) {
    std::fprintf(stderr, "bench_fixed_point: the 1 M-sample block and 4096-sample blocks disagree\n");
    std::exit(1);
  }
  for (auto _ : state) {
    f.reset();
    f.execute_block(in, out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
  const auto st = f.split_stats();
  state.SetLabel("time split " + std::to_string(st.blocks) + ", lanes redone " + std::to_string(st.recomputed) +
                 ", backed off " + std::to_string(st.skipped));
}
void BM_FixedType(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(run_fixed_type());
  state.SetItemsProcessed(state.iterations() * kSamples);
}
void BM_ScFixed(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(run_systemc<ScData>(make_sc_fixed));
  state.SetItemsProcessed(state.iterations() * kSamples);
}
void BM_ScFix(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(run_systemc<sc_dt::sc_fix>(make_sc_fix));
  state.SetItemsProcessed(state.iterations() * kSamples);
}

BENCHMARK(BM_BandpassFixed)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_BandpassFixedBlock)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_BandpassFixedBlock1M)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FixedType)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ScFixed)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_ScFix)->Unit(benchmark::kMicrosecond);

}  // namespace
