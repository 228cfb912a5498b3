#pragma once
// Synthesizable HLS C++ of the fixed-point receiver: bandpass (SOS cascade) -> correlator bank
// (mixer, one-cycle moving sum, decimation, chip FIR, code combiner, weighted power, energy
// window) -> peak detector (gate, candidate tracking, parabolic fraction, score). It computes
// exactly what the golden model ReceiverFixed (model/dsp/receiver.hpp) computes, bit for bit
// (tests/test_hls_csim.cpp), and is a template on ONE configuration struct carrying every
// width, size and table: the generated ranging_hls::ReceiverConfig
// (`ranging generate` -> <out>/hls/receiver_config.hpp).
//
// Synthesizable subset: fixed-size arrays, constant loop bounds, no dynamic memory, no
// recursion, no floating point. Integers are plain 64-bit words whose configured width is
// enforced by explicit masking / sign extension (fx:: helpers below), so g++ and the HLS tools
// see the same arithmetic. Rounding is round half up = add half an LSB then arithmetic shift
// right (computed as floor + (dropped bits >= half), the same value without the overflow of
// the addition), then saturation, exactly as model/dsp/fixed_point.cpp fx_quantize.
//
// Pragmas: Vitis HLS (`#pragma HLS ...`) and Catapult (`#pragma hls_...`) are written through
// RANGING_HLS_PRAGMA(...), which becomes `_Pragma("...")` under __SYNTHESIS__ (both tools
// define it) and nothing for g++: g++ 12 cannot silence -Wunknown-pragmas with
// `#pragma GCC diagnostic` in C++ (GCC bug 53431, fixed in GCC 13). See hls/README.md.
//
// One header per stage (hls4ml style), each a template on the generated configuration struct:
//   hls/hls_common.hpp      stream type, fx:: width helpers, stream words
//   hls/bandpass_sos.hpp    BandpassSos<Cfg>
//   hls/correlator_bank.hpp CorrelatorBank<Cfg>
//   hls/peak_detector.hpp   PeakDetector<Cfg>
//   hls/receiver.hpp        Receiver<Cfg>
//   hls/receiver_top.hpp    receiver_top<Cfg>
// This header includes them all.
#include "hls/receiver_top.hpp"
