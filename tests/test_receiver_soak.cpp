// The fixed-point golden model over 10^9 samples (label soak: about a minute; RANGING_SOAK=1
// scripts/run-tests.sh, or ctest -L soak): the default configuration's receiver fed a periodic
// scene (every code once per cycle, at 0.5 m, with noise) for 1e9 / cycle cycles, block by block.
//   - no drift: from the third cycle on, every cycle's events (code, arrival relative to the
//     cycle's start, score, margin) equal the second cycle's, to the bit;
//   - the energy accumulator E (a running sum of y^2 over the window, updated per sample) equals
//     the direct sum over the last window of the filter's output at every checkpoint;
//   - no overflow of the input, the filter or the correlator nodes;
//   - the sample index and the arrival time base are exact at 10^9 samples (int64; the arrival
//     has 8 fraction bits, so it wraps only after 2^55 samples: 228 years at 5 MS/s).
// RANGING_SOAK_SAMPLES overrides the length (at least 10 cycles).
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <vector>

#include "model/config/receiver_config.hpp"
#include "model/dsp/bandpass_filter.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/receiver.hpp"
#include "model/sim/channel.hpp"

using namespace ranging;

namespace {

// One cycle of the periodic scene as ADC codes: code j's burst starts at j * period, and the
// tails of the previous cycle's bursts are folded in (cycle -1 and 0 generated, cycle 0 kept).
std::vector<std::int64_t> periodic_cycle(const ReceiverDesign& d, int period) {
  const int eta = d.family.eta();
  const std::size_t cycle = static_cast<std::size_t>(eta * period);
  std::vector<double> two(2 * cycle, 0.0);
  const ExcitationParams ex = receiver_excitation(d.config);
  for (int rep = 0; rep < 2; ++rep) {
    for (int j = 0; j < eta; ++j) {
      ChannelParams ch;
      ch.distance_m = 0.5;
      ch.gain = 0.5;
      ch.noise_rms = 0.0;
      const std::size_t start = static_cast<std::size_t>(rep) * cycle + static_cast<std::size_t>(j * period);
      const auto rx = propagate(bpsk_excitation(d.family.codes[static_cast<std::size_t>(j)], ex), ch, d.config.fs,
                                two.size() - start);
      for (std::size_t k = 0; k < rx.size(); ++k) two[start + k] += rx[k];
    }
  }
  // Noise: one cycle of it, repeated (the whole input is periodic).
  ChannelParams noise;
  noise.distance_m = 0.5;
  noise.gain = 0.0;
  noise.noise_rms = 0.002;
  noise.seed = 11;
  const auto nz = propagate(std::vector<double>(1, 0.0), noise, d.config.fs, cycle);
  std::vector<std::int64_t> x(cycle);
  OverflowCounter clip;
  for (std::size_t k = 0; k < cycle; ++k) x[k] = quantize_input(two[cycle + k] + nz[k], d.config.bandpass.input_bits, &clip);
  EXPECT_EQ(clip.total(), 0u) << "the scene must not clip the ADC";
  return x;
}

std::uint64_t soak_samples() {
  const char* s = std::getenv("RANGING_SOAK_SAMPLES");
  return s ? std::strtoull(s, nullptr, 10) : 1000000000ULL;
}

}  // namespace

TEST(ReceiverSoak, BillionSamplesWithoutDriftOrOverflow) {
  const ReceiverDesign d = design_receiver(load_receiver_config(RANGING_SOURCE_DIR "/configs/default.yaml"));
  const int period = 1400;
  const auto x = periodic_cycle(d, period);
  const std::int64_t cycle = static_cast<std::int64_t>(x.size());
  const std::uint64_t cycles = soak_samples() / static_cast<std::uint64_t>(cycle);
  ASSERT_GE(cycles, 10u) << "RANGING_SOAK_SAMPLES below 10 cycles";
  const int frac = d.config.detector.frac_bits;

  ReceiverFixed rx(d);
  BandpassFixed filter(d.filter, d.config.bandpass);  // the receiver's filter, for E
  const std::size_t window = static_cast<std::size_t>(rx.bank().layout().window);
  ASSERT_LE(window, x.size());
  std::vector<std::int64_t> y(x.size());
  std::vector<EventFixed> events, reference;
  std::uint64_t total_events = 0, energy_checks = 0, first_cycle_events = 0;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::uint64_t c = 0; c < cycles; ++c) {
    events.clear();
    rx.execute_block(x, events);
    total_events += events.size();
    // Arrivals relative to the start of this cycle (exact: int64, 8 fraction bits).
    const std::int64_t base = static_cast<std::int64_t>(c) * cycle * (std::int64_t{1} << frac);
    for (auto& e : events) e.arrival -= base;
    if (c == 0) {
      first_cycle_events = events.size();  // from a reset state: its own count
    } else if (c == 1) {
      reference = events;
      ASSERT_EQ(reference.size(), static_cast<std::size_t>(d.family.eta())) << "one event per burst";
    } else if (c > 1) {
      ASSERT_EQ(events, reference) << "cycle " << c << " (sample " << c * static_cast<std::uint64_t>(cycle)
                                   << ") differs from cycle 1";
    }
    // E against the direct sum of y^2 over the last window, every 1000 cycles and at the end.
    filter.execute_block(x, y);
    if (c % 1000 == 999 || c + 1 == cycles) {
      std::uint64_t e = 0;
      for (std::size_t k = y.size() - window; k < y.size(); ++k) e += static_cast<std::uint64_t>(y[k] * y[k]);
      ASSERT_EQ(rx.bank().energy(), e) << "energy accumulator drifted by cycle " << c;
      ++energy_checks;
    }
  }
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::uint64_t n = cycles * static_cast<std::uint64_t>(cycle);
  EXPECT_EQ(rx.bank().sample_index(), static_cast<std::int64_t>(n) - 1);
  EXPECT_EQ(rx.overflow_events().total(), 0u);
  EXPECT_EQ(total_events, first_cycle_events + (cycles - 1) * reference.size());
  std::cout << n << " samples (" << cycles << " cycles of " << cycle << "), " << total_events << " events, "
            << energy_checks << " energy checks, in " << s << " s (" << n / s / 1e6 << " MS/s)\n";
}
