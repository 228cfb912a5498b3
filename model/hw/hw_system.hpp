#pragma once
// The ranging system around the generated receiver (rtl/ranging_system.v, docs/bitstream.md):
// the configuration-derived parameters of the transmit scheduler, ADC clock, time of flight and
// UART, the bit-exact model of rtl/tof_distance.v, and the generated system top
// (rtl/ranging_system_top.v with literal parameters, and its Verilator -G file).
#include "model/config/ice40_pll.hpp"
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "model/dsp/receiver.hpp"

namespace ranging {

// The configuration's `system:` section (SystemConfig, model/dsp/receiver.hpp) and the system
// clock; system_options(config) is what generate and the bitstream use.
struct SystemOptions : SystemConfig {
  double clk_hz = 0;  // system clock; 0: the configuration's hardware.clock_hz
};
SystemOptions system_options(const ReceiverConfig& config);

struct SystemDesign {
  int clk_div = 0;        // clocks per full-rate sample (f_clk / fs, exact integer)
  int codes = 0, chips = 0, spc = 0, cycles_per_chip = 0;
  int period_t = 0;       // samples between bursts: max(1.5 T_d, L / (eta c)) (eq. 3, 4)
  std::vector<std::int64_t> code_bits;  // code j chip m at element j*chips + m (0/1)
  int code_w = 0, time_w = 0, frac_w = 0, score_w = 0;
  int off_w = 32;
  std::vector<std::int64_t> offsets;    // receiver latency per code, frac_w fraction bits
  int c_frac = 16;
  std::uint32_t c_init = 0;             // speed of sound, um per sample, c_frac fraction bits
  int baud_div = 0;
  std::int64_t led_hold = 0;            // clocks: 50 ms
  double fs = 0, clk_hz = 0, speed_of_sound = 0, max_range_m = 0, baud = 0;
  double measurement_rate_hz() const { return fs / period_t; }
};

// Throws InputError naming the key (system.*) when the clock is not an integer multiple of fs,
// the baud rate is not an integer divider, the period cannot hold a burst, a latency offset
// does not fit system.off_w bits or the calibration burst is not decoded.
SystemDesign system_design(const ReceiverDesign& design);  // system_options(design.config)
SystemDesign system_design(const ReceiverDesign& design, const SystemOptions& opt);

// Speed of sound (m/s) -> the tof_distance C register (um per sample, c_frac fraction bits).
std::uint32_t speed_register(double speed_of_sound, double fs, int c_frac);

// rtl/tof_distance.v, bit for bit (its header is the specification).
struct Measurement32 {
  int code = 0;
  unsigned flags = 0;          // bit 0 no burst of the code before the arrival; bit 1 saturated
  std::uint32_t tof = 0;       // full-rate samples, frac_w fraction bits
  std::uint32_t distance = 0;  // micrometres
  std::uint64_t score = 0, margin = 0;
};
class TofDistanceModel {
 public:
  explicit TofDistanceModel(const SystemDesign& s);
  void reset();
  void burst(int code, std::int64_t start_sample);  // tx_scheduler's burst strobe
  void set_speed(std::uint32_t c) { c_ = c; }
  Measurement32 execute(int code, std::int64_t arrival, std::uint64_t score, std::uint64_t margin) const;

 private:
  SystemDesign s_;
  bool have_ = false;
  int last_code_ = 0;
  std::int64_t last_time_ = 0;
  std::uint32_t c_;
};

// The transmitted H-bridge drive of the schedule, one value per full-rate sample from 0:
// +1/-1 inside bursts (hbridge_drive of the code), 0 between them.
std::vector<std::int8_t> system_drive(const ReceiverDesign& design, const SystemDesign& s,
                                      std::size_t samples);

// ice40_pll (the board's PLL settings): model/config/ice40_pll.hpp.

// Generated files (relative to the generator's output folder): rtl/ranging_system_top.v,
// rtl/ranging_system.vc, rtl/ice40_pll.vh (the iCEBreaker PLL: 12 MHz -> clk_hz), system.json.
std::map<std::string, std::string> generate_system_files(const ReceiverDesign& design,
                                                         const std::string& origin);

}  // namespace ranging
