#pragma once
// The Verilated receiver of any configuration, built at run time (`ranging verify`, and the
// RTL precision of `ranging simulate`): the IP folder is generated into a work folder (never
// the source tree), tb/verify_driver.cpp is compiled against it with `verilator --build`
// (cached: the same sources are not rebuilt), and sample streams are run through it. With
// simulator "postsynth" the same driver runs the iCE40 gate-level netlist of the IP folder. The
// driver writes raw port values; this module decodes them with the configuration's widths.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "model/dsp/peak_detector.hpp"
#include "model/dsp/receiver.hpp"

namespace ranging::tool {

struct RtlBuildOptions {
  std::string rtl_dir;       // RTL sources (default: the project's rtl/)
  std::string rtl_option = "--rtl";  // option named in errors about rtl_dir
  std::filesystem::path work_dir;    // ip/, obj/, runs/ go here
  std::string origin;        // configuration name for the generated banners
  bool trace = false;        // compile FST tracing in (RANGING_TRACE=1 switches it on)
  // What is Verilated: "verilator" the RTL; "postsynth" the gate-level netlist of yosys
  // synth_ice40 -dsp (as the bitstream flow synthesizes it; SB_* cells from yosys' cells_sim.v);
  // "icarus" the RTL in Icarus Verilog (iverilog -g2012, a generated testbench); "hls" the HLS
  // C++ (C simulation: events only, tb/hls_driver.cpp); "systemc" the RTL Verilated with --sc,
  // driven under the SystemC kernel (tb/verify_driver_sc.cpp).
  std::string simulator = "verilator";
  bool quiet = false;        // no progress on stderr
};

// Default work folder: $TMPDIR (or /tmp)/ranging-<what>-<uid>-<config name>.
std::filesystem::path default_work_dir(const std::string& what, const std::string& config_name);

// One stream through the DUT.
struct RtlStimulus {
  std::string name;                 // letters, digits, '_', '-', '.'
  double valid_prob = 1.0, ready_prob = 1.0;
  std::uint64_t seed = 1;
  long long reset_at = -1;          // rst pulsed before sample reset_at (-1: never)
  // 0: samples offered with valid_prob each cycle; K > 0: sample i due at cycle i K (an ADC at
  // clk / K), and RtlResult::late counts those taken after their due cycle.
  long long cadence = 0;
  std::vector<std::int64_t> x;      // signed ADC samples (input_bits)
};

struct RtlFilterBeat {
  std::int64_t data = 0;
  std::vector<std::int64_t> sections;
};
struct RtlBankBeat {
  int code = 0;  // 0-based beat within the group
  bool last = false;
  std::uint64_t weighted = 0, energy = 0;
  std::int64_t index = 0, chip_re = 0, chip_im = 0, corr_re = 0, corr_im = 0;
};
// Outputs between two resets.
struct RtlSegment {
  std::vector<RtlFilterBeat> filter;
  std::vector<RtlBankBeat> bank;
  std::vector<EventFixed> events;
};
struct RtlResult {
  std::string name;
  std::vector<RtlSegment> segments;  // one more than the resets applied
  bool stalled = false;
  std::uint64_t samples_taken = 0, cycles = 0, late = 0;
};

class RtlReceiver {
 public:
  // Generates and builds (progress on stderr unless quiet). Throws InputError when the
  // sources do not build (the message names the log).
  // The work folder is locked (flock on WORK/.lock) from here to destruction: two processes
  // on the same folder (two simulates of one configuration, parallel tests) take turns.
  RtlReceiver(const ReceiverDesign& design, const RtlBuildOptions& options);
  RtlReceiver(const RtlReceiver&) = delete;
  RtlReceiver& operator=(const RtlReceiver&) = delete;
  std::vector<RtlResult> run(const std::vector<RtlStimulus>& stimuli) const;
  const std::filesystem::path& work_dir() const { return opt_.work_dir; }
  double build_seconds() const { return build_seconds_; }
  bool rebuilt() const { return rebuilt_; }

 private:
  void build_icarus(const std::filesystem::path& work);
  void build_hls(const std::filesystem::path& work);
  const ReceiverDesign& design_;
  RtlBuildOptions opt_;
  std::filesystem::path driver_;
  double build_seconds_ = 0;
  bool rebuilt_ = false;
  struct Lock {  // the flock's descriptor, closed (and so released) even if the constructor throws
    int fd = -1;
    Lock() = default;
    Lock(const Lock&) = delete;
    Lock& operator=(const Lock&) = delete;
    ~Lock();
  } lock_;
  int data_w_, sections_, chip_w_, corr_w_, time_w_, code_w_, frac_w_, score_w_, in_w_;
};

}  // namespace ranging::tool
