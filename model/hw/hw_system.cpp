#include "model/hw/hw_system.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "model/sim/channel.hpp"
#include "model/base/error.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/latency.hpp"
#include "model/hw/hw_emit.hpp"
#include "model/hw/hw_params.hpp"

namespace ranging {
namespace {

int exact_divider(const std::string& what, double num, double den) {
  const double r = num / den;
  const double n = std::round(r);
  if (n < 2 || std::abs(r - n) > 1e-9 * n) {
    std::ostringstream os;
    os << what << ": " << num << " / " << den << " = " << r << " must be an integer >= 2";
    throw InputError(os.str());
  }
  return static_cast<int>(n);
}

std::int64_t module_value(const std::vector<HwModuleParams>& mods, const std::string& m,
                          const std::string& p) {
  for (const auto& x : mods) {
    if (x.module == m) return x.value(p);
  }
  throw std::logic_error("hw_system: no module " + m);
}

}  // namespace

std::uint32_t speed_register(double c, double fs, int c_frac) {
  require_in_range("system.speed_of_sound", c, 100.0, 10000.0);
  const double v = std::round(c / fs * 1e6 * std::ldexp(1.0, c_frac));
  if (!(v >= 1 && v < 4294967296.0)) {
    throw InputError("system.c_frac: the speed register c / fs * 1e6 * 2^c_frac does not fit 32 bits");
  }
  return static_cast<std::uint32_t>(v);
}

SystemOptions system_options(const ReceiverConfig& c) {
  SystemOptions o;
  static_cast<SystemConfig&>(o) = c.system;
  return o;
}

SystemDesign system_design(const ReceiverDesign& d) { return system_design(d, system_options(d.config)); }

SystemDesign system_design(const ReceiverDesign& d, const SystemOptions& options) {
  SystemOptions opt = options;
  if (opt.clk_hz == 0) opt.clk_hz = d.config.clock_hz;
  require_in_range("clk_hz", opt.clk_hz, 1e6, kMaxClockHz);
  require_in_range("system.max_range_m", opt.max_range_m, 0.01, 100.0);
  require_in_range("system.baud", opt.baud, 1200.0, 12e6);
  require_in_range("system.calibration_distance_m", opt.calibration_distance_m, 0.01, 10.0);
  require_in_range("system.off_w", opt.off_w, 16, 48);
  require_in_range("system.c_frac", opt.c_frac, 1, 31 - d.config.detector.frac_bits);
  const ReceiverConfig& c = d.config;
  const auto mods = hardware_parameters(d);
  SystemDesign s;
  s.fs = c.fs;
  s.clk_hz = opt.clk_hz;
  s.speed_of_sound = opt.speed_of_sound;
  s.max_range_m = opt.max_range_m;
  s.baud = opt.baud;
  s.clk_div = exact_divider("clk_hz / fs", opt.clk_hz, c.fs);
  s.baud_div = exact_divider("system.baud: clk_hz / baud", opt.clk_hz, opt.baud);
  s.codes = static_cast<int>(d.family.codes.size());
  s.chips = d.family.length;
  s.spc = c.chip_samples();
  s.cycles_per_chip = c.cycles_per_chip;
  for (const auto& code : d.family.codes) {
    for (auto chip : code) s.code_bits.push_back(chip);
  }
  // Eq. 3/4: T >= 1.5 T_d (T_d: the template span, what the receiver integrates) and
  // eta T c >= L (the code repeats only after the longest flight).
  const double t_td = std::ceil(1.5 * d.layout.window);
  const double t_l = std::ceil(c.fs * opt.max_range_m / (s.codes * opt.speed_of_sound) - 1e-9);
  s.period_t = static_cast<int>(std::max(t_td, t_l));
  const int burst = s.chips * s.spc;
  const PeakDetectorFixed det(c.detector, d.layout, c.correlator);
  if (s.period_t < burst || s.period_t < det.holdoff()) {
    throw InputError("system.max_range_m: the burst period " + std::to_string(s.period_t) +
                     " samples is shorter than a burst (" + std::to_string(burst) + ") or the detector holdoff (" +
                     std::to_string(det.holdoff()) + ")");
  }
  s.code_w = static_cast<int>(module_value(mods, "peak_detector", "CODE_W"));
  s.time_w = static_cast<int>(module_value(mods, "peak_detector", "TIME_W"));
  s.frac_w = static_cast<int>(module_value(mods, "peak_detector", "FRAC_W"));
  s.score_w = static_cast<int>(module_value(mods, "peak_detector", "SCORE_W"));
  s.off_w = opt.off_w;
  s.c_frac = opt.c_frac;
  s.c_init = speed_register(opt.speed_of_sound, c.fs, s.c_frac);
  s.led_hold = static_cast<std::int64_t>(opt.clk_hz / 20);

  // Latency calibration on the golden model (model/dsp/latency.hpp): the arrival of the
  // strongest event the fixed receiver reports for a burst sent at sample 0 through the
  // reference transducers, minus the true flight, in frac_w fraction bits.
  const ExcitationParams ex = receiver_excitation(c);
  ChannelParams ch;
  ch.speed_of_sound = opt.speed_of_sound;
  ch.distance_m = opt.calibration_distance_m;
  ch.gain = 0.5;
  ch.tx = c.reference_transducer;
  ch.rx = c.reference_transducer;
  const double flight = calibration_flight(opt.calibration_distance_m, opt.speed_of_sound, c.fs);
  const std::int64_t flight_q = std::llround(std::ldexp(flight, s.frac_w));
  const std::size_t n_out = static_cast<std::size_t>(flight) + burst + 3 * d.layout.window + 2000;
  s.offsets = calibrate_receiver_latency<EventFixed>(
      static_cast<std::size_t>(s.codes), flight_q,
      [&](int code) {
        const auto drive = hbridge_drive(d.family.codes[static_cast<std::size_t>(code - 1)], ex);
        const std::vector<double> x(drive.begin(), drive.end());
        const auto y = propagate(x, ch, c.fs, n_out);
        ReceiverFixed rx(d);
        std::vector<EventFixed> events;
        for (double v : y) {
          if (auto e = rx.execute_raw(quantize_input(v, c.bandpass.input_bits, nullptr))) events.push_back(*e);
        }
        if (auto e = rx.flush_raw()) events.push_back(*e);
        return events;
      },
      [](int code) {
        return "system.calibration_distance_m: code " + std::to_string(code) +
               " is not decoded at the calibration distance; check detector.threshold";
      });
  const std::int64_t lim = std::int64_t{1} << (s.off_w - 1);
  for (std::size_t j = 0; j < s.offsets.size(); ++j) {
    const std::int64_t off = s.offsets[j];
    if (off < -lim || off >= lim) {
      throw InputError("system.off_w: the latency offset " + std::to_string(off) + " of code " + std::to_string(j + 1) +
                       " does not fit " + std::to_string(s.off_w) + " signed bits; valid range is [16, 48]");
    }
  }
  return s;
}

TofDistanceModel::TofDistanceModel(const SystemDesign& s) : s_(s), c_(s.c_init) {}

void TofDistanceModel::reset() {
  have_ = false;
  last_code_ = 0;
  last_time_ = 0;
  c_ = s_.c_init;
}

void TofDistanceModel::burst(int code, std::int64_t start) {
  have_ = true;
  last_code_ = code;
  last_time_ = start;
}

Measurement32 TofDistanceModel::execute(int code, std::int64_t arrival, std::uint64_t score,
                                        std::uint64_t margin) const {
  Measurement32 m;
  m.code = code;
  m.score = score;
  m.margin = margin;
  const std::int64_t off = code >= 1 && code <= s_.codes ? s_.offsets[static_cast<std::size_t>(code - 1)] : 0;
  const std::int64_t a = arrival - off;
  bool no_tx = !have_;
  int k = last_code_ - code;
  if (k < 0) k += s_.codes;
  std::int64_t t = last_time_ - static_cast<std::int64_t>(k) * s_.period_t;
  const std::int64_t cycle = static_cast<std::int64_t>(s_.codes) * s_.period_t;
  std::int64_t tof = 0;
  if (t < 0) no_tx = true;  // the code's burst would precede the first one: never sent
  // The sample counters wrap after 2^time_w samples: an arrival more than half that range
  // behind the burst was counted after the wrap, so it is 2^time_w samples later (rtl/tof_distance.v).
  const std::int64_t range = std::int64_t{1} << (s_.time_w + s_.frac_w);
  std::int64_t a_w = a;
  while (!no_tx && a_w - t * (std::int64_t{1} << s_.frac_w) < -(range >> 1)) a_w += range;
  while (!no_tx) {
    tof = a_w - t * (std::int64_t{1} << s_.frac_w);
    if (tof >= 0) break;
    if (t < cycle) no_tx = true;
    else t -= cycle;
  }
  bool sat = false;
  std::uint64_t tq = 0;
  if (!no_tx) {
    if (tof > 0xffffffffLL) {
      tq = 0xffffffffULL;
      sat = true;
    } else {
      tq = static_cast<std::uint64_t>(tof);
    }
  }
  const int sh = s_.frac_w + s_.c_frac;
  const unsigned __int128 acc = static_cast<unsigned __int128>(tq) * c_;
  const unsigned __int128 dist = (acc + (static_cast<unsigned __int128>(1) << (sh - 1))) >> sh;
  if (dist > 0xffffffffULL) {
    m.distance = 0xffffffffU;
    sat = true;
  } else {
    m.distance = static_cast<std::uint32_t>(dist);
  }
  m.tof = static_cast<std::uint32_t>(tq);
  m.flags = (no_tx ? 1u : 0u) | (sat ? 2u : 0u);
  return m;
}

std::vector<std::int8_t> system_drive(const ReceiverDesign& d, const SystemDesign& s, std::size_t n) {
  ExcitationParams ex;
  ex.carrier_hz = d.config.carrier_hz;
  ex.cycles_per_chip = d.config.cycles_per_chip;
  ex.fs = d.config.fs;
  std::vector<std::int8_t> out(n, 0);
  for (std::size_t b = 0; b * static_cast<std::size_t>(s.period_t) < n; ++b) {
    const auto drive = hbridge_drive(d.family.codes[b % static_cast<std::size_t>(s.codes)], ex);
    const std::size_t start = b * static_cast<std::size_t>(s.period_t);
    for (std::size_t i = 0; i < drive.size() && start + i < n; ++i) out[start + i] = drive[i];
  }
  return out;
}

std::map<std::string, std::string> generate_system_files(const ReceiverDesign& design,
                                                         const std::string& origin) {
  const SystemDesign s = system_design(design);
  const auto d32 = [](std::int64_t v) { return emit::sized32(v); };
  const emit::VerilogParams params = {
      {"CLK_DIV", d32(s.clk_div)},
      {"ADC_W", d32(design.config.bandpass.input_bits)},
      {"ADC_OFFSET_BINARY", d32(1)},
      {"CODES", d32(s.codes)},
      {"CHIPS", d32(s.chips)},
      {"SPC", d32(s.spc)},
      {"CYC", d32(s.cycles_per_chip)},
      {"PERIOD_T", d32(s.period_t)},
      {"CODE_BITS", verilog_packed(s.code_bits, 1)},
      {"CODE_W", d32(s.code_w)},
      {"TIME_W", d32(s.time_w)},
      {"FRAC_W", d32(s.frac_w)},
      {"SCORE_W", d32(s.score_w)},
      {"OFF_W", d32(s.off_w)},
      {"OFFSETS", verilog_packed(s.offsets, s.off_w)},
      {"C_FRAC", d32(s.c_frac)},
      {"C_INIT", d32(s.c_init)},
      {"BAUD_DIV", d32(s.baud_div)},
      {"LED_HOLD", d32(s.led_hold)}};
  const std::string head = emit::banner("//", origin, "docs/bitstream.md", "model/hw/hw_system.cpp");
  std::ostringstream v;
  v << head
    << "//\n// ranging_system_top: rtl/ranging_system.v with the parameters of this configuration.\n"
    << "// fs = " << s.fs << " S/s = clk " << s.clk_hz << " Hz / " << s.clk_div << "; burst period T = "
    << s.period_t << " samples (" << s.measurement_rate_hz() << " measurements/s); speed of sound "
    << s.speed_of_sound << " m/s; UART " << s.baud << " baud.\n"
    << "`default_nettype none\n\nmodule ranging_system_top (\n"
    << "  input  wire clk, rst,\n"
    << "  output wire adc_clk,\n"
    << "  input  wire [" << design.config.bandpass.input_bits - 1 << ":0] adc_data,\n"
    << "  output wire hb_p, hb_n, tx_active,\n"
    << "  input  wire c_wr,\n  input  wire [31:0] c_value,\n"
    << "  output wire uart_tx, led_meas, led_error,\n"
    << "  output wire sample_tick, meas_valid\n);\n"
    << "  ranging_system #(\n";
  v << emit::instance_params(params);
  v << "  ) u_system (\n"
    << "    .clk(clk), .rst(rst), .adc_clk(adc_clk), .adc_data(adc_data),\n"
    << "    .hb_p(hb_p), .hb_n(hb_n), .tx_active(tx_active), .c_wr(c_wr), .c_value(c_value),\n"
    << "    .uart_tx(uart_tx), .led_meas(led_meas), .led_error(led_error),\n"
    << "    .sample_tick(sample_tick), .meas_valid(meas_valid)\n  );\nendmodule\n\n`default_nettype wire\n";
  nlohmann::json j;
  j["generated_from"] = origin;
  j["clk_hz"] = s.clk_hz;
  j["fs"] = s.fs;
  j["clk_div"] = s.clk_div;
  j["period_t_samples"] = s.period_t;
  j["measurement_rate_hz"] = s.measurement_rate_hz();
  j["max_range_m"] = s.max_range_m;
  j["speed_of_sound"] = s.speed_of_sound;
  j["c_register"] = s.c_init;
  j["c_frac"] = s.c_frac;
  j["baud"] = s.baud;
  j["baud_div"] = s.baud_div;
  j["frac_bits"] = s.frac_w;
  j["offsets"] = s.offsets;
  // The board's PLL (boards/icebreaker/ice40_top.v includes this file).
  const Ice40Pll pll = ice40_pll(kBoardOscillatorHz, s.clk_hz);
  std::ostringstream vh;
  vh << head << "// iCEBreaker SB_PLL40_PAD settings: 12 MHz -> " << pll.f_out / 1e6 << " MHz (F_PFD "
     << pll.f_pfd / 1e6 << " MHz, F_VCO " << pll.f_vco / 1e6 << " MHz), as `icepll -i 12 -o " << s.clk_hz / 1e6
     << "`.\n"
     << "`define RANGING_PLL_DIVR " << pll.divr << "\n`define RANGING_PLL_DIVF " << pll.divf
     << "\n`define RANGING_PLL_DIVQ " << pll.divq << "\n`define RANGING_PLL_FILTER_RANGE " << pll.filter_range
     << "\n`define RANGING_CLK_HZ " << static_cast<std::int64_t>(std::llround(s.clk_hz)) << "\n";
  j["pll"] = {{"divr", pll.divr}, {"divf", pll.divf}, {"divq", pll.divq}, {"filter_range", pll.filter_range}};
  std::map<std::string, std::string> files;
  files["rtl/ice40_pll.vh"] = vh.str();
  files["rtl/ranging_system_top.v"] = v.str();
  files["rtl/ranging_system.vc"] = emit::vc_file(params);
  files["system.json"] = emit::json_file(j);
  return files;
}

}  // namespace ranging
