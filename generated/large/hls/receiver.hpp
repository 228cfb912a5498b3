#pragma once
// The HLS receiver chain (model: ReceiverFixed, model/dsp/receiver.hpp): BandpassSos ->
// CorrelatorBank -> PeakDetector, with reset(), step(x, ev), flush(ev) and the debug taps used
// by the C simulation (tests/test_hls_csim.cpp).
#include "hls/bandpass_sos.hpp"
#include "hls/correlator_bank.hpp"
#include "hls/peak_detector.hpp"
#include "hls/hls_common.hpp"

// Loop labels exist for the HLS reports; g++ would call them unused.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"

namespace ranging_hls {

// ---- the receiver ---------------------------------------------------------------------------
template <class Cfg>
class Receiver {
 public:
  void reset() {
    bandpass_.reset();
    bank_.reset();
    detector_.reset();
    filtered_ = 0;
    decimated_ = false;
    bank_out_ = BankOutput<Cfg>{};
  }

  // One ADC sample (signed SOS_IN_W). Returns true when an event is emitted into ev.
  bool step(word_t x, EventBeat& ev) {
    RANGING_HLS_PRAGMA(HLS INLINE)
    filtered_ = bandpass_.step(x);
    decimated_ = bank_.step(filtered_, bank_out_);
    if (!decimated_) return false;
    return detector_.step(bank_out_, ev);
  }
  bool flush(EventBeat& ev) { return detector_.flush(ev); }

  // Debug taps of the last sample (C simulation; unused, they are optimized away in hardware).
  word_t filtered() const { return filtered_; }
  word_t section_output(int k) const { return bandpass_.section_output(k); }
  bool decimated() const { return decimated_; }              // the last sample made an output
  const BankOutput<Cfg>& bank_output() const { return bank_out_; }  // the last decimated output
  const BankTaps<Cfg>& bank_taps() const { return bank_.taps(); }

 private:
  BandpassSos<Cfg> bandpass_;
  CorrelatorBank<Cfg> bank_;
  PeakDetector<Cfg> detector_;
  word_t filtered_ = 0;
  bool decimated_ = false;
  BankOutput<Cfg> bank_out_;
};

}  // namespace ranging_hls

#pragma GCC diagnostic pop
