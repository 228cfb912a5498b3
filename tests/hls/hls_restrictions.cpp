// Compiled by tests/hls/hls_restrictions.cmake with the restrictions HLS tools impose (no
// exceptions, no RTTI) for one generated configuration (RANGING_HLS_CONFIG). The checks on the
// object: no undefined symbol (no dynamic memory, no library call, no throw), no call left in
// the flattened entry points (no recursion: flatten inlines every non-recursive call), and a
// static stack frame in each (no variable-length arrays / alloca, i.e. static sizes).
#include RANGING_HLS_CONFIG
#include "hls/receiver.hpp"
using Rx = ranging_hls::Receiver<ranging_hls::ReceiverConfig>;
extern "C" __attribute__((flatten)) bool hls_step(Rx* rx, long long x, ranging_hls::EventBeat* ev) {
  return rx->step(x, *ev);
}
extern "C" __attribute__((flatten)) bool hls_flush(Rx* rx, ranging_hls::EventBeat* ev) { return rx->flush(*ev); }
extern "C" __attribute__((flatten)) void hls_reset(Rx* rx) { rx->reset(); }
