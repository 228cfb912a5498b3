// C simulation of the HLS receiver (hls/receiver_hls.hpp) against the golden model
// ReceiverFixed, bit for bit: every bandpass section output, every mixer output, every
// decimated node (Bd, F, C, P, Q, E, index) and every event, on coded received signals, a
// full-scale worst case and random noise. (tests/test_generate.cpp checks that the committed
// generated/default is exactly what `ranging generate` writes for configs/default.yaml.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "generated/default/hls/receiver_config.hpp"
#include "hls/receiver_hls.hpp"
#include "model/config/receiver_config.hpp"
#include "model/sim/channel.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/receiver.hpp"

namespace fs = std::filesystem;
using namespace ranging;
using Cfg = ranging_hls::ReceiverConfig;
using HlsReceiver = ranging_hls::Receiver<Cfg>;

namespace {

const std::string kSource = RANGING_SOURCE_DIR;

const ReceiverDesign& default_design() {
  static const ReceiverDesign d = design_receiver(load_receiver_config(kSource + "/configs/default.yaml"));
  return d;
}

struct Totals {
  std::uint64_t samples = 0, decimated = 0, events = 0, signals = 0;
};
Totals& totals() {
  static Totals t;
  return t;
}

bool same_event(const EventFixed& m, const ranging_hls::EventBeat& h) {
  return m.code == h.code && m.arrival == h.arrival && m.score == h.score && m.margin == h.margin;
}

std::string describe(const EventFixed& m) {
  std::ostringstream os;
  os << "{code " << m.code << ", arrival " << m.arrival << ", score " << m.score << ", margin " << m.margin << "}";
  return os.str();
}
std::string describe(const ranging_hls::EventBeat& h) {
  std::ostringstream os;
  os << "{code " << h.code << ", arrival " << h.arrival << ", score " << h.score << ", margin " << h.margin << "}";
  return os.str();
}

struct CsimRun {
  std::string mismatch;          // first difference, empty if bit-exact
  std::vector<EventFixed> events;  // the model's events (flush included)
  OverflowCounter overflows;     // the model's saturations (filter + bank)
};

// Runs the model and the HLS receiver (reset first: one HLS object serves every signal, so
// reset is exercised too) over x and compares every node on every sample.
CsimRun compare(HlsReceiver& hls, const std::vector<std::int64_t>& x) {
  const ReceiverDesign& d = default_design();
  ReceiverFixed model(d);
  hls.reset();
  CsimRun run;
  const int sections = static_cast<int>(Cfg::SOS_SECTIONS);
  const int codes = static_cast<int>(Cfg::BANK_CODES);
  const int decim = static_cast<int>(Cfg::BANK_DECIM);
  auto fail = [&](std::size_t n, const std::string& what, long long m, long long h) {
    std::ostringstream os;
    os << "sample " << n << ": " << what << ": model " << m << ", hls " << h;
    run.mismatch = os.str();
  };
  for (std::size_t n = 0; n < x.size(); ++n) {
    const std::optional<EventFixed> em = model.execute_raw(x[n]);
    ranging_hls::EventBeat eh;
    const bool got = hls.step(x[n], eh);
    ++totals().samples;
    if (model.filtered() != hls.filtered()) return fail(n, "bandpass output", model.filtered(), hls.filtered()), run;
    for (int k = 0; k < sections; ++k) {
      const auto m = model.filter().section_outputs()[static_cast<std::size_t>(k)];
      if (m != hls.section_output(k)) return fail(n, "section " + std::to_string(k), m, hls.section_output(k)), run;
    }
    const auto& bank = model.bank();
    const auto& taps = hls.bank_taps();
    if (bank.mix_re() != taps.mix_re) return fail(n, "mixer re", bank.mix_re(), taps.mix_re), run;
    if (bank.mix_im() != taps.mix_im) return fail(n, "mixer im", bank.mix_im(), taps.mix_im), run;
    const bool model_dec = (bank.sample_index() + 1) % decim == 0;
    if (model_dec != hls.decimated()) return fail(n, "decimated strobe", model_dec, hls.decimated()), run;
    if (model_dec) {
      ++totals().decimated;
      const auto& out = hls.bank_output();
      if (bank.dec_re() != taps.dec_re) return fail(n, "Bd re", bank.dec_re(), taps.dec_re), run;
      if (bank.dec_im() != taps.dec_im) return fail(n, "Bd im", bank.dec_im(), taps.dec_im), run;
      if (bank.chip_re() != taps.chip_re) return fail(n, "F re", bank.chip_re(), taps.chip_re), run;
      if (bank.chip_im() != taps.chip_im) return fail(n, "F im", bank.chip_im(), taps.chip_im), run;
      for (int j = 0; j < codes; ++j) {
        const auto u = static_cast<std::size_t>(j);
        const std::string c = " code " + std::to_string(j + 1);
        if (bank.corr_re()[u] != taps.corr_re[j]) return fail(n, "C re" + c, bank.corr_re()[u], taps.corr_re[j]), run;
        if (bank.corr_im()[u] != taps.corr_im[j]) return fail(n, "C im" + c, bank.corr_im()[u], taps.corr_im[j]), run;
        if (bank.power()[u] != taps.power[j]) {
          return fail(n, "P" + c, static_cast<long long>(bank.power()[u]), static_cast<long long>(taps.power[j])), run;
        }
        if (bank.weighted_power()[u] != out.weighted[j]) {
          return fail(n, "Q" + c, static_cast<long long>(bank.weighted_power()[u]),
                      static_cast<long long>(out.weighted[j])), run;
        }
      }
      if (bank.energy() != out.energy) {
        return fail(n, "energy", static_cast<long long>(bank.energy()), static_cast<long long>(out.energy)), run;
      }
      if (static_cast<std::uint64_t>(bank.sample_index()) != out.index) {
        return fail(n, "index", bank.sample_index(), static_cast<long long>(out.index)), run;
      }
    }
    if (em.has_value() != got) return fail(n, "event strobe", em.has_value(), got), run;
    if (em) {
      ++totals().events;
      run.events.push_back(*em);
      if (!same_event(*em, eh)) {
        run.mismatch = "sample " + std::to_string(n) + ": event: model " + describe(*em) + ", hls " + describe(eh);
        return run;
      }
    }
  }
  const std::optional<EventFixed> fm = model.flush_raw();
  ranging_hls::EventBeat fh;
  const bool fgot = hls.flush(fh);
  if (fm.has_value() != fgot) return fail(x.size(), "flush strobe", fm.has_value(), fgot), run;
  if (fm) {
    ++totals().events;
    run.events.push_back(*fm);
    if (!same_event(*fm, fh)) {
      run.mismatch = "flush: model " + describe(*fm) + ", hls " + describe(fh);
      return run;
    }
  }
  run.overflows = model.overflow_events();
  ++totals().signals;
  return run;
}

// The synthesis top through its streams (rst first, last on the final beat) must emit exactly
// the model's events, in order.
std::string compare_top(const std::vector<std::int64_t>& x, const std::vector<EventFixed>& expected) {
  ranging_hls::hls_stream<ranging_hls::AdcBeat> s_axis;
  ranging_hls::hls_stream<ranging_hls::EventBeat> m_axis;
  ranging_hls::receiver_top<Cfg>(s_axis, m_axis, true);
  for (std::size_t n = 0; n < x.size(); ++n) {
    s_axis.write(ranging_hls::AdcBeat{x[n], n + 1 == x.size()});
    ranging_hls::receiver_top<Cfg>(s_axis, m_axis, false);
  }
  if (!s_axis.empty()) return "top left input beats unread";
  std::size_t i = 0;
  while (!m_axis.empty()) {
    const ranging_hls::EventBeat e = m_axis.read();
    if (i >= expected.size()) return "top: extra event " + describe(e);
    if (!same_event(expected[i], e)) return "top event " + std::to_string(i) + ": model " + describe(expected[i]) + ", hls " + describe(e);
    ++i;
  }
  if (i != expected.size()) return "top emitted " + std::to_string(i) + " events, model " + std::to_string(expected.size());
  return "";
}

std::vector<std::int64_t> to_adc(const std::vector<double>& v) {
  const int bits = default_design().config.bandpass.input_bits;
  std::vector<std::int64_t> x;
  x.reserve(v.size());
  for (double s : v) x.push_back(quantize_input(s, bits, nullptr));
  return x;
}

// Received burst of one code at distance d (the demo's channel: 0.5 full scale at 0.1 m).
std::vector<std::int64_t> coded_signal(int code, double distance_m, double noise_rms, std::uint64_t seed,
                                       double gain = 0.5) {
  const ReceiverDesign& d = default_design();
  const ExcitationParams ex = receiver_excitation(d.config);
  const auto exc = bpsk_excitation(d.family.codes[static_cast<std::size_t>(code)], ex);
  ChannelParams c;
  c.distance_m = distance_m;
  c.gain = gain;
  c.noise_rms = noise_rms;
  c.seed = seed;
  const double delay = distance_m / c.speed_of_sound * d.config.fs;
  const std::size_t window = static_cast<std::size_t>(d.family.length * d.config.chip_samples());
  return to_adc(propagate(exc, c, d.config.fs, static_cast<std::size_t>(delay) + 3 * window + 2000));
}

// Prints how much a test compared (the counters are per process; ctest runs one test each).
void report(const char* what, const Totals& before) {
  const Totals& t = totals();
  std::cout << "[ csim     ] " << what << ": " << t.signals - before.signals << " signals, "
            << t.samples - before.samples << " samples, " << t.decimated - before.decimated
            << " decimated outputs, " << t.events - before.events << " events compared bit for bit\n";
}

HlsReceiver& shared_hls() {
  static auto r = std::make_unique<HlsReceiver>();
  return *r;
}

}  // namespace

// Every code at 100, 550 and 1000 mm, with and without noise: every node bit-exact, the
// events decode the sent code, and the synthesis top emits the same event stream.
TEST(HlsCsim, CodedSignalsBitExact) {
  const ReceiverDesign& d = default_design();
  const int eta = static_cast<int>(d.family.codes.size());
  ASSERT_EQ(eta, static_cast<int>(Cfg::BANK_CODES));
  const Totals before = totals();
  std::uint64_t seed = 7;
  std::size_t with_events = 0;
  for (double noise : {0.0, 0.002}) {
    for (double dist : {0.1, 0.55, 1.0}) {
      for (int j = 0; j < eta; ++j) {
        SCOPED_TRACE("code " + std::to_string(j + 1) + " at " + std::to_string(dist) + " m, noise " +
                     std::to_string(noise));
        const auto x = coded_signal(j, dist, noise, ++seed);
        const CsimRun run = compare(shared_hls(), x);
        ASSERT_EQ(run.mismatch, "");
        // The comparison covers the detector's event path: the strongest event is the sent code.
        ASSERT_FALSE(run.events.empty());
        const auto best = std::max_element(run.events.begin(), run.events.end(),
                                           [](const EventFixed& a, const EventFixed& b) { return a.score < b.score; });
        EXPECT_EQ(best->code, j + 1);
        ++with_events;
        if (dist == 1.0) {
          ASSERT_EQ(compare_top(x, run.events), "");
        }
      }
    }
  }
  EXPECT_EQ(with_events, static_cast<std::size_t>(6 * eta));
  report("coded signals", before);
}

// Full scale: clipped bursts (the ADC saturates), the bandpass's worst-case input (the sign of
// its time-reversed impulse response, which drives the peak gain) and a full-scale square
// carrier. The default design has headroom for all of them (docs/fixed-point.md), so the test
// asserts that they drive the filter output near the top of its word instead; the saturation
// and wrap paths are compared in BandpassVariantsBitExact and QuantizerMatchesModel.
TEST(HlsCsim, FullScaleWorstCaseBitExact) {
  const ReceiverDesign& d = default_design();
  const Totals before = totals();
  std::vector<std::vector<std::int64_t>> signals;
  for (int j : {0, 4, 8}) signals.push_back(coded_signal(j, 0.1, 0.0, 3, 16.0));  // 16x full scale, clipped
  // Worst case for the cascade: x[n] = -sign(h[N-1-n]) at full scale, repeated.
  BandpassFixed probe(d.filter, d.config.bandpass);
  const std::int64_t lo = -(std::int64_t{1} << (d.config.bandpass.input_bits - 1)), hi = -lo - 1;
  std::vector<double> h;
  const std::size_t len = 600;
  for (std::size_t n = 0; n < len; ++n) h.push_back(static_cast<double>(probe.execute_raw(n == 0 ? hi : 0)));
  std::vector<std::int64_t> worst;
  for (int rep = 0; rep < 20; ++rep) {
    for (std::size_t n = 0; n < len; ++n) worst.push_back(h[len - 1 - n] >= 0 ? hi : lo);
    for (std::size_t n = 0; n < len; ++n) worst.push_back(h[len - 1 - n] >= 0 ? lo : hi);
  }
  signals.push_back(worst);
  // Full-scale square carrier at f with a phase flip every chip-ish stretch.
  std::vector<std::int64_t> square;
  const int period = d.config.period();
  for (int n = 0; n < 40000; ++n) {
    const bool flip = (n / 700) % 2 == 1;
    square.push_back(((n % period) < period / 2) != flip ? hi : lo);
  }
  signals.push_back(square);
  for (std::size_t i = 0; i < signals.size(); ++i) {
    SCOPED_TRACE("full-scale signal " + std::to_string(i));
    const CsimRun run = compare(shared_hls(), signals[i]);
    ASSERT_EQ(run.mismatch, "");
  }
  // The worst case reaches 90 % of the filter word (the design's peak gain is ~1.93 of 2).
  const double top = std::ldexp(1.0, static_cast<int>(Cfg::SOS_DATA_W) - 1);
  ReceiverFixed model(d);
  std::int64_t peak = 0;
  for (std::int64_t v : worst) {
    model.execute_raw(v);
    peak = std::max<std::int64_t>(peak, std::abs(model.filtered()));
  }
  std::cout << "[ csim     ] worst-case filter output peak: " << static_cast<double>(peak) / top
            << " of full scale\n";
  EXPECT_GT(static_cast<double>(peak), 0.9 * top);
  report("full scale", before);
}

// Random full-range ADC codes and Gaussian noise: every node bit-exact.
TEST(HlsCsim, RandomNoiseBitExact) {
  const int bits = default_design().config.bandpass.input_bits;
  const Totals before = totals();
  const std::int64_t lo = -(std::int64_t{1} << (bits - 1)), hi = -lo - 1;
  std::mt19937_64 rng(12345);
  std::uniform_int_distribution<std::int64_t> uniform(lo, hi);
  std::vector<std::int64_t> x(200000);
  for (auto& v : x) v = uniform(rng);
  CsimRun run = compare(shared_hls(), x);
  ASSERT_EQ(run.mismatch, "");
  std::normal_distribution<double> gauss(0.0, 0.1);
  std::vector<double> g(200000);
  for (auto& v : g) v = gauss(rng);
  run = compare(shared_hls(), to_adc(g));
  ASSERT_EQ(run.mismatch, "");
  report("random noise", before);
}

// The HLS quantizer (round, then saturate or wrap) against the model's fx_quantize on random
// words, every rounding mode, both overflow rules, exact ties and the extremes.
template <int W, int K, int Mode, bool Sat>
void check_quantizer(std::mt19937_64& rng, int bits_in, std::uint64_t& overflows) {
  const Rounding r = Mode == 0 ? Rounding::Truncate : Mode == 1 ? Rounding::RoundHalfUp : Rounding::Convergent;
  const FixedFormat fmt{W, 0, true, r, Sat ? Overflow::Saturate : Overflow::Wrap};
  OverflowCounter counter;
  const std::int64_t hi = bits_in == 64 ? std::numeric_limits<std::int64_t>::max()
                                        : (std::int64_t{1} << (bits_in - 1)) - 1;
  const std::int64_t lo = -hi - 1;
  std::uniform_int_distribution<std::int64_t> dist(lo, hi);
  for (int i = 0; i < 20000; ++i) {
    std::int64_t v = dist(rng);
    if constexpr (K > 0) {
      if (i % 4 == 1) v = (v >> K << K) | (std::int64_t{1} << (K - 1));  // exact tie
    }
    if (i == 0) v = lo;
    if (i == 1) v = hi;
    const std::int64_t expected = fx_quantize(v, K, fmt, &counter);
    const std::int64_t got = ranging_hls::fx::quantize<W, K, Mode, Sat>(v);
    ASSERT_EQ(got, expected) << "W " << W << " K " << K << " mode " << Mode << " sat " << Sat << " v " << v;
  }
  overflows += counter.total();
}

TEST(HlsCsim, QuantizerMatchesModel) {
  std::mt19937_64 rng(99);
  std::uint64_t overflows = 0;
  check_quantizer<16, 14, 0, true>(rng, 40, overflows);
  check_quantizer<16, 14, 1, true>(rng, 40, overflows);
  check_quantizer<16, 14, 2, true>(rng, 40, overflows);
  check_quantizer<16, 14, 0, false>(rng, 40, overflows);
  check_quantizer<16, 14, 1, false>(rng, 40, overflows);
  check_quantizer<16, 14, 2, false>(rng, 40, overflows);
  check_quantizer<18, 13, 1, true>(rng, 33, overflows);
  check_quantizer<20, 22, 1, true>(rng, 44, overflows);
  check_quantizer<16, 6, 1, true>(rng, 23, overflows);
  check_quantizer<12, 0, 1, true>(rng, 16, overflows);
  check_quantizer<12, 0, 1, false>(rng, 16, overflows);
  check_quantizer<63, 1, 1, true>(rng, 64, overflows);
  check_quantizer<64, 30, 2, false>(rng, 64, overflows);
  EXPECT_GT(overflows, 10000u);  // the saturate and wrap branches were exercised
}

// The bandpass stage with the other rounding and overflow rules of the configuration, and with
// one integer bit less (DATA_FRAC 15: the worst case overflows), against BandpassFixed.
template <std::int64_t Frac, std::int64_t Rnd, std::int64_t Sat>
struct SosVariant : ranging_hls::ReceiverConfig {
  static constexpr std::int64_t SOS_DATA_FRAC = Frac;
  static constexpr std::int64_t SOS_ROUNDING = Rnd;
  static constexpr std::int64_t SOS_SATURATE = Sat;
  static constexpr std::int64_t SOS_ACC_W = 48;
};

template <class V>
void check_bandpass(const std::vector<std::int64_t>& x, std::uint64_t& overflows) {
  const ReceiverDesign& d = default_design();
  BandpassFixedConfig bc = d.config.bandpass;
  bc.data_frac = static_cast<int>(V::SOS_DATA_FRAC);
  bc.acc_bits = static_cast<int>(V::SOS_ACC_W);
  bc.rounding = V::SOS_ROUNDING == 0 ? Rounding::Truncate : V::SOS_ROUNDING == 1 ? Rounding::RoundHalfUp : Rounding::Convergent;
  bc.overflow = V::SOS_SATURATE ? Overflow::Saturate : Overflow::Wrap;
  BandpassFixed model(d.filter, bc);
  auto hls = std::make_unique<ranging_hls::BandpassSos<V>>();
  hls->reset();
  for (std::size_t n = 0; n < x.size(); ++n) {
    const std::int64_t m = model.execute_raw(x[n]);
    const std::int64_t h = hls->step(x[n]);
    ASSERT_EQ(h, m) << "sample " << n << " frac " << V::SOS_DATA_FRAC << " rounding " << V::SOS_ROUNDING
                    << " saturate " << V::SOS_SATURATE;
    for (int k = 0; k < static_cast<int>(V::SOS_SECTIONS); ++k) {
      ASSERT_EQ(hls->section_output(k), model.section_outputs()[static_cast<std::size_t>(k)]) << "sample " << n;
    }
  }
  overflows += model.overflow_events().total();
  totals().samples += x.size();
  ++totals().signals;
}

TEST(HlsCsim, BandpassVariantsBitExact) {
  const Totals before = totals();
  const ReceiverDesign& d = default_design();
  const std::int64_t lo = -(std::int64_t{1} << (d.config.bandpass.input_bits - 1)), hi = -lo - 1;
  // Worst case of the default filter, then random full-range codes.
  BandpassFixed probe(d.filter, d.config.bandpass);
  std::vector<double> h;
  for (int n = 0; n < 600; ++n) h.push_back(static_cast<double>(probe.execute_raw(n == 0 ? hi : 0)));
  std::vector<std::int64_t> x;
  for (int rep = 0; rep < 10; ++rep) {
    for (int n = 599; n >= 0; --n) x.push_back(h[static_cast<std::size_t>(n)] >= 0 ? hi : lo);
  }
  std::mt19937_64 rng(4);
  std::uniform_int_distribution<std::int64_t> uniform(lo, hi);
  for (int n = 0; n < 20000; ++n) x.push_back(uniform(rng));
  std::uint64_t nominal = 0, tight = 0;
  check_bandpass<SosVariant<14, 0, 1>>(x, nominal);
  check_bandpass<SosVariant<14, 2, 1>>(x, nominal);
  check_bandpass<SosVariant<14, 1, 0>>(x, nominal);
  check_bandpass<SosVariant<15, 1, 1>>(x, tight);
  check_bandpass<SosVariant<15, 0, 0>>(x, tight);
  check_bandpass<SosVariant<15, 2, 0>>(x, tight);
  EXPECT_GT(tight, 0u);  // one integer bit less: the worst case saturates / wraps
  report("bandpass variants", before);
}
