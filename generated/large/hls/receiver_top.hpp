#pragma once
// The HLS synthesis top: receiver_top<Cfg>(s_axis, m_axis, rst), AXI-Stream in and out.
#include "hls/receiver.hpp"
#include "hls/hls_common.hpp"

// Loop labels exist for the HLS reports; g++ would call them unused.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"

namespace ranging_hls {

// ---- synthesis top --------------------------------------------------------------------------
// Free-running streaming top: one ADC beat in per call, at most one event out. `rst` (a plain
// wire) clears every state and consumes no beat. HLS needs a non-template top: wrap it with the
// configuration (hls/README.md).
template <class Cfg>
void receiver_top(hls_stream<AdcBeat>& s_axis, hls_stream<EventBeat>& m_axis, bool rst) {
  RANGING_HLS_PRAGMA(hls_design top)
  RANGING_HLS_PRAGMA(HLS INTERFACE axis port=s_axis)
  RANGING_HLS_PRAGMA(HLS INTERFACE axis port=m_axis)
  RANGING_HLS_PRAGMA(HLS INTERFACE ap_none port=rst)
  RANGING_HLS_PRAGMA(HLS INTERFACE ap_ctrl_none port=return)
  static Receiver<Cfg> rx;  // state across calls: zero at power-up, cleared by rst
  if (rst) {
    rx.reset();
    return;
  }
  const AdcBeat in = s_axis.read();
  EventBeat ev;
  // At most one of the two fires: an emitted event clears the candidate that flush would emit.
  if (rx.step(in.data, ev)) m_axis.write(ev);
  if (in.last && rx.flush(ev)) m_axis.write(ev);
}

}  // namespace ranging_hls

#pragma GCC diagnostic pop
