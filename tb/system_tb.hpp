#pragma once
// What the two testbenches of the ranging system (tb_ranging_system.cpp, tb_system_loop.cpp)
// share: the Verilated system with the harness, the default configuration's receiver and
// system designs, and the host's UART receiver on the sampled tx line.
#include <cstdint>
#include <vector>

// Verilator's headers are not -Wunused-parameter clean.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include "Vranging_system.h"
#include "tb/verilator_harness.hpp"
#pragma GCC diagnostic pop
#include "model/config/receiver_config.hpp"
#include "model/dsp/receiver.hpp"
#include "model/hw/hw_system.hpp"

namespace ranging::tb {

inline const ReceiverDesign& design() {
  static const ReceiverDesign d = design_receiver(load_receiver_config(RANGING_CONFIG));
  return d;
}
inline const SystemDesign& sys() {
  static const SystemDesign s = system_design(design());
  return s;
}

// The system's inputs idle (ADC pins 0, no speed-of-sound write), then 4 clocks of reset.
inline void reset_idle(Harness<Vranging_system>& h) {
  auto& top = h.top();
  top.adc_data = 0;
  top.c_wr = 0;
  top.c_value = 0;
  h.reset(4);
}

// 8N1 receiver on the line sampled once per clock, div clocks per bit (the line idles high; a
// falling edge starts a byte, each bit is sampled in its middle). Records every byte and the
// clock of its stop bit; a stop bit that reads 0 is a framing error.
class UartDecoder {
 public:
  explicit UartDecoder(int div) : div_(div) {}
  void sample(bool line, std::uint64_t cycle) {
    if (state_ < 0) {
      if (prev_ && !line) {
        state_ = 0;
        count_ = div_ + div_ / 2;  // middle of data bit 0
        byte_ = 0;
      }
    } else if (--count_ == 0) {
      if (state_ < 8) {
        byte_ |= static_cast<std::uint8_t>((line ? 1 : 0) << state_);
        ++state_;
        count_ = div_;
      } else {
        if (!line) ++framing_errors;
        bytes.push_back(byte_);
        cycles.push_back(cycle);
        state_ = -1;
      }
    }
    prev_ = line;
  }
  bool idle() const { return state_ < 0; }
  std::vector<std::uint8_t> bytes;
  std::vector<std::uint64_t> cycles;
  int framing_errors = 0;

 private:
  int div_, state_ = -1, count_ = 0;
  bool prev_ = true;
  std::uint8_t byte_ = 0;
};

}  // namespace ranging::tb
