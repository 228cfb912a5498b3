// The whole ranging system (rtl/ranging_system.v around the generated receiver) in a closed
// loop against the model: the channel model (model/sim/channel.hpp: TX and RX transducers,
// propagation delay, noise) turns the transmit schedule into the ADC pins; the H-bridge drive
// is checked sample by sample against hbridge_drive; the UART line is decoded into frames and
// every frame is checked field by field against ReceiverFixed + TofDistanceModel fed with the
// same ADC codes, and against the true distance.
// The system clock divider is the configuration's (RANGING_TB_CLK_DIV = hardware.clock_hz / fs,
// 6 at 30 MHz): the receiver must take every ADC sample at the board's real rate, or the ADC
// interface flags an overrun (led_error), which the test asserts never happens.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <optional>
#include <vector>

#include "tb/system_tb.hpp"  // Vranging_system, the harness, design(), sys(), UartDecoder
#include "model/hw/frames.hpp"
#include "model/sim/channel.hpp"

using namespace ranging;
using namespace ranging::tb;

namespace {

TEST(RangingSystem, ClosedLoopSceneFramesMatchModel) {
  const auto& d = design();
  const auto& s = sys();
  const double distance = 0.35;
  const int clk_div = RANGING_TB_CLK_DIV;
  const int eta = s.codes;
  const std::size_t n = static_cast<std::size_t>((eta - 1) * s.period_t + s.chips * s.spc +
                                                 distance / s.speed_of_sound * s.fs + 2 * d.layout.window + 600);
  // The scene: the schedule's drive through the channel model, quantized by a 12-bit ADC.
  const auto drive = system_drive(d, s, n);
  std::vector<double> x(drive.begin(), drive.end());
  ChannelParams ch;
  ch.speed_of_sound = s.speed_of_sound;
  ch.distance_m = distance;
  ch.gain = 0.5 * 0.1 / 0.1;
  ch.tx = d.config.reference_transducer;
  ch.rx = d.config.reference_transducer;
  ch.noise_rms = 0.005;
  ch.seed = 7;
  const auto y = propagate(x, ch, s.fs, n);
  const int bits = d.config.bandpass.input_bits;
  std::vector<std::int64_t> adc(n);
  for (std::size_t k = 0; k < n; ++k) adc[k] = quantize_input(y[k], bits, nullptr);

  tb::Harness<Vranging_system> h("tb_ranging_system");
  auto& top = h.top();
  reset_idle(h);
  UartDecoder uart(s.baud_div);
  std::size_t k_adc = 0;  // ADC conversions started (rising edges of adc_clk)
  std::size_t k_tick = 0;
  bool prev_adc_clk = false;
  std::size_t drive_errors = 0, first_drive_error = 0;
  const std::uint64_t extra = 40000;  // clocks after the last sample: pipeline + UART
  const std::uint64_t total = static_cast<std::uint64_t>(n) * clk_div + extra;
  while (h.cycles() < total) {
    h.settle();
    if (top.sample_tick) {
      // hb_p/hb_n hold the drive of sample k_tick - 1 (registered at the previous tick).
      if (k_tick >= 1 && k_tick - 1 < n) {
        const int got = top.hb_p && !top.hb_n ? 1 : (!top.hb_p && top.hb_n ? -1 : (top.hb_p ? 9 : 0));
        if (got != drive[k_tick - 1]) {
          if (drive_errors++ == 0) first_drive_error = k_tick - 1;
        }
      }
      ++k_tick;
    }
    uart.sample(top.uart_tx != 0, h.cycles());
    h.tick();
    // An ideal ADC: converts on the rising edge of adc_clk, data out right after it.
    const bool ac = top.adc_clk != 0;
    if (ac && !prev_adc_clk) {
      const std::int64_t code = k_adc < n ? adc[k_adc] : 0;
      top.adc_data = static_cast<std::uint16_t>((code + (1 << (bits - 1))) & ((1 << bits) - 1));
      ++k_adc;
    }
    prev_adc_clk = ac;
  }
  // Expected measurements: the golden receiver on the same codes (zeros after the scene, as
  // the ADC pins were), then ToF/distance with the bursts sent up to each event.
  const std::size_t samples = k_tick;
  ReceiverFixed rx(d);
  TofDistanceModel tof(s);
  std::vector<Measurement32> expected;
  std::vector<std::size_t> emitted_at;
  std::size_t next_burst = 0;
  for (std::size_t k = 0; k < samples; ++k) {
    while (next_burst * static_cast<std::size_t>(s.period_t) <= k) {
      tof.burst(static_cast<int>(next_burst % static_cast<std::size_t>(eta)) + 1,
                static_cast<std::int64_t>(next_burst * static_cast<std::size_t>(s.period_t)));
      ++next_burst;
    }
    if (auto e = rx.execute_raw(k < n ? adc[k] : 0)) {
      expected.push_back(tof.execute(e->code, e->arrival, e->score, e->margin));
      emitted_at.push_back(k);
    }
  }
  ASSERT_GE(expected.size(), static_cast<std::size_t>(eta)) << "the model must decode every burst";
  // Events in the last samples may still be in the pipeline or the UART.
  const std::size_t settled = static_cast<std::size_t>(
      std::count_if(emitted_at.begin(), emitted_at.end(), [&](std::size_t k) { return k + 400 < samples; }));
  EXPECT_EQ(drive_errors, 0u) << "H-bridge drive differs from hbridge_drive, first at sample " << first_drive_error;
  EXPECT_EQ(top.led_error, 0) << "ADC overrun: the receiver did not keep up at CLK_DIV " << clk_div;
  EXPECT_EQ(uart.framing_errors, 0);
  FrameStats stats;
  const auto frames = decode_uart_frames(uart.bytes, stats);
  EXPECT_EQ(stats.bad_frames, 0u) << "bad sync or checksum";
  EXPECT_EQ(stats.skipped_bytes, 0u) << "bytes outside frames";
  std::cout << frames.size() << " UART frames, " << expected.size() << " model measurements, "
            << k_tick << " samples at " << clk_div << " clocks per sample\n";
  for (const auto& f : frames) {
    std::cout << "  code " << f.code << " tof " << f.tof_q8 / 256.0 << " samples distance " << f.distance_um
              << " um score " << f.score << " margin " << f.margin << "\n";
  }
  ASSERT_GE(frames.size(), settled);
  ASSERT_LE(frames.size(), expected.size());
  const double um_per_sample = s.speed_of_sound / s.fs * 1e6;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    SCOPED_TRACE("frame " + std::to_string(i));
    const auto& f = frames[i];
    const auto& e = expected[i];
    EXPECT_EQ(f.code, e.code);
    EXPECT_EQ(f.flags, e.flags);
    EXPECT_EQ(f.tof_q8, e.tof);
    EXPECT_EQ(f.distance_um, e.distance);
    EXPECT_EQ(f.score, e.score);
    EXPECT_EQ(f.margin, e.margin);
    // The scene: burst i carried code i+1 and flew `distance`.
    EXPECT_EQ(f.code, static_cast<int>(i % static_cast<std::size_t>(eta)) + 1);
    EXPECT_EQ(f.flags, 0u);
    EXPECT_NEAR(f.distance_um * 1e-6, distance, 0.002);
    EXPECT_NEAR(f.tof_q8 / 256.0 * um_per_sample * 1e-6, f.distance_um * 1e-6, 1e-5);
  }
}

// A measured speed of sound written at run time scales the distance (compensation module).
TEST(RangingSystem, SpeedRegisterModel) {
  const auto& s = sys();
  TofDistanceModel m(s);
  m.burst(1, 0);
  const std::int64_t flight = 5000;  // samples
  const auto a = m.execute(1, (flight << s.frac_w) + s.offsets[0], 60000, 1000);
  EXPECT_EQ(a.tof, static_cast<std::uint32_t>(flight << s.frac_w));
  EXPECT_NEAR(a.distance, flight * 68.0, 1.0);  // 340 m/s at 5 MS/s: 68 um per sample
  m.set_speed(speed_register(343.0, s.fs, s.c_frac));
  EXPECT_NEAR(m.execute(1, (flight << s.frac_w) + s.offsets[0], 0, 0).distance, flight * 68.6, 1.0);
  // before any burst of the code: flagged, no distance
  TofDistanceModel fresh(s);
  EXPECT_EQ(fresh.execute(2, 1000, 0, 0).flags & 1u, 1u);
}

}  // namespace
