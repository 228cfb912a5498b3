#pragma once
// The receiver: bandpass filter -> parallel correlator bank -> peak detector, in two
// precisions with one life cycle (create / execute / reset / flush):
//   ReceiverFloat  double-precision reference of the same structure
//   ReceiverFixed  the bit-accurate model the generated HLS C++ and Verilog implement
// Both are built from one ReceiverConfig (configs/*.yaml), the single source of truth.
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "model/dsp/bandpass_filter.hpp"
#include "model/dsp/codes.hpp"
#include "model/dsp/correlator_bank.hpp"
#include "model/dsp/excitation.hpp"
#include "model/dsp/filter_design.hpp"
#include "model/dsp/peak_detector.hpp"
#include "model/dsp/quantize.hpp"  // quantize_input, the ADC model
#include "model/dsp/transducer.hpp"

namespace ranging {

// The `system:` section (docs/configuration.md): the ranging system around the receiver
// (rtl/ranging_system.v, model/hw/hw_system.hpp). The model of the receiver does not read it;
// generate and the bitstream do (PERIOD_T, C_INIT, BAUD_DIV, OFFSETS, TIME_W of the RTL).
struct SystemConfig {
  double speed_of_sound = 340.0;        // m/s, loaded into the speed register at reset
  double max_range_m = 1.0;             // L of eq. 3/4 (the paper: 100-1000 mm)
  double baud = 1.5e6;                  // UART; hardware.clock_hz / baud is an integer >= 2
  double calibration_distance_m = 0.1;  // latency calibration (a known distance, as the paper)
  // Widths of the RTL (unsigned sample counters wrap after 2^time_w samples, the model's
  // int64 indices do not: at 5 MS/s 40 bits is 2.5 days, 32 bits 14 minutes).
  int time_w = 40;  // sample index of the bank, the detector and the scheduler
  int off_w = 32;   // signed latency offset per code (frac_bits fraction bits)
  int c_frac = 16;  // fraction bits of the speed register (um per sample); frac_bits + c_frac < 32
};

// The highest system clock a configuration may name (hardware.clock_hz), and so the highest
// sample rate the receiver takes (one sample per clock at most).
inline constexpr double kMaxClockHz = 500e6;

struct ReceiverConfig {
  std::string name = "default";
  std::string family = "Gold4";          // code family (ranging codes --list)
  std::string architecture = "baseband"; // matched-filter architecture (docs/architecture.md)
  double carrier_hz = 200e3;             // f
  int cycles_per_chip = 4;               // q
  double fs = 5e6;                       // ADC sample rate
  BandpassSpec filter;                   // the paper's 150-250 kHz spec by default
  FilterType filter_type = FilterType::Butterworth;
  int filter_order = 0;                  // 0: the minimum order for the spec
  // "sos" (the cascade the receiver and the hardware implement) or "direct" (one high-order
  // recursion of the same design: a study structure, ranging stability; refused here).
  std::string filter_structure = "sos";
  // Matched-filter reference (docs/architecture.md): "received" matches the response of the
  // transducers and the bandpass filter to one chip, as the paper's received templates do;
  // "ideal" matches the bare BPSK excitation.
  std::string reference = "received";
  TransducerParams reference_transducer;  // TX and RX of the template (received mode)
  int decimation = 20;                   // D: the bank runs at fs / D
  double template_floor = 0.1;           // template tail trimmed below this fraction of its
                                         // peak (the paper's T_d threshold, b/10)
  BandpassFixedConfig bandpass;          // fixed-point word lengths of the filter
  CorrelatorFixedConfig correlator;      // ... of the correlator bank
  DetectorConfig detector;
  // hardware.clock_hz: the system clock the generated RTL is scheduled for (the iCEBreaker's
  // PLL makes it from 12 MHz); clock_hz / fs clocks per input sample, an integer.
  double clock_hz = 30e6;
  SystemConfig system;
  // Study option, never read from or written to YAML: design_receiver refuses a design whose
  // quantized filter is unstable or out of spec (model/dsp/stability.hpp) unless it is set
  // (the tools' --allow-out-of-spec).
  bool allow_out_of_spec = false;

  int period() const;        // fs / f, samples per carrier cycle (validated integer)
  int chip_samples() const;  // q fs / f
  int sample_cycles() const; // clock_hz / fs (validated integer)
};

// Throws InputError naming the field and valid range.
void validate(const ReceiverConfig& cfg);

// Lowers cfg.decimation to the largest divisor of the samples per chip that does not exceed it
// (scenes whose families use another q than the configuration's, e.g. M3/M4 at q = 2 with the
// default D = 20 -> 10). No-op when it already divides or fs is unset.
void fit_decimation_to_chip(ReceiverConfig& cfg);

// Everything derived from a configuration: codes, filter, layouts.
struct ReceiverDesign {
  ReceiverConfig config;
  CodeFamily family;
  SosFilter filter;
  CorrelatorReference reference;          // chip template, energy window, code gains
  std::vector<std::vector<double>> templates;  // full-rate template of every code (what
                                               // the bank is matched to), for reports
  CorrelatorFixedLayout layout;
};
ReceiverDesign design_receiver(const ReceiverConfig& cfg);

// The excitation the receiver is designed for (carrier_hz, cycles_per_chip and fs of the
// configuration) at amplitude U: every stimulus built from a configuration starts here.
ExcitationParams receiver_excitation(const ReceiverConfig& config, double amplitude = 1.0);

class ReceiverFloat {
 public:
  explicit ReceiverFloat(const ReceiverDesign& design);
  void reset();
  std::optional<Event> execute(double x);
  // Block form: execute() on every x[i] in order, bit for bit (events, state, filtered()); the
  // bandpass runs a chunk at a time (BandpassFloat::execute_block), then the bank over the
  // chunk, handing its outputs to the detector (CorrelatorBankFloat::feed_outputs). Events are
  // appended (returns how many); filtered, when not empty
  // (its size must be x's, else InputError), receives every bandpass output.
  std::size_t execute_block(std::span<const double> x, std::vector<Event>& events, std::span<double> filtered = {});
  std::optional<Event> flush() { return detector_.flush(); }
  double filtered() const { return filtered_; }  // last bandpass output
  const CorrelatorBankFloat& bank() const { return bank_; }
  const BandpassFloat& filter() const { return filter_; }

 private:
  BandpassFloat filter_;
  std::vector<double> long_chunk_;  // execute_block's filtered long chunk
  CorrelatorBankFloat bank_;
  PeakDetectorFloat detector_;
  double filtered_ = 0;
};

class ReceiverFixed {
 public:
  explicit ReceiverFixed(const ReceiverDesign& design);
  void reset();
  // x: signed input_bits ADC code.
  std::optional<EventFixed> execute_raw(std::int64_t x);
  // Block form: the same as execute_raw on every x[i] in order, bit for bit (events, state,
  // overflow counts); events are appended to `events` (returns how many). The filter runs a
  // chunk at a time (range checked once per chunk: an out-of-range code throws InputError
  // before its chunk changes any state), then the bank and the detector. A long block goes in
  // long chunks that the filter and the bank each run time-split on the SIMD lanes
  // (BandpassSplitStats, CorrelatorBankFixed::feed_split); a short one in cache-sized chunks.
  std::size_t execute_block(std::span<const std::int64_t> x, std::vector<EventFixed>& events);
  // x in full-scale units: quantized by quantize_input first; the event in float form.
  std::optional<Event> execute(double x);
  std::optional<EventFixed> flush_raw() { return detector_.flush(); }
  std::optional<Event> flush();

  std::int64_t filtered() const { return filtered_; }  // last bandpass output (data format)
  const BandpassFixed& filter() const { return filter_; }
  const CorrelatorBankFixed& bank() const { return bank_; }
  const PeakDetectorFixed& detector() const { return detector_; }
  OverflowCounter overflow_events() const;  // input + filter + correlator
  Event to_float(const EventFixed& e) const;

 private:
  int input_bits_, frac_bits_, score_bits_;
  BandpassFixed filter_;
  CorrelatorBankFixed bank_;
  PeakDetectorFixed detector_;
  std::int64_t filtered_ = 0;
  OverflowCounter input_counter_;
  std::vector<std::int64_t> chunk_;  // execute_block's filtered chunk
};

}  // namespace ranging
