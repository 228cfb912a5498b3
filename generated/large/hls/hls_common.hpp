#pragma once
// Shared by every HLS stage (one header per stage, as hls4ml does: bandpass_sos.hpp,
// correlator_bank.hpp, peak_detector.hpp, receiver.hpp, receiver_top.hpp; receiver_hls.hpp
// includes them all):
//   - RANGING_HLS_PRAGMA(...): Vitis HLS / Catapult pragmas, nothing for g++ (hls/README.md);
//   - hls_stream<T>: the AXI-Stream channel (ac_channel under Catapult, hls::stream under Vitis,
//     an unbounded FIFO for C simulation);
//   - fx::: fixed-width integer helpers on the native word types below. Every register of a
//     stage is a `word_t` / `uword_t` whose configured width is enforced by fx::sext / fx::zext;
//     fx::quantize<W, K, Mode, Sat> rounds (truncate, round half up as floor + (dropped bits >=
//     half), convergent) then saturates or wraps, exactly as model/dsp/fixed_point.cpp;
//   - the stream words AdcBeat / EventBeat and RANGING_HLS_I (a configuration constant as int).
#include <cstdint>

#ifdef __SYNTHESIS__
#define RANGING_HLS_PRAGMA(x) _Pragma(#x)
#else
#define RANGING_HLS_PRAGMA(x)
#endif


// ---- stream type ----------------------------------------------------------------------------
#if defined(__SYNTHESIS__) && defined(RANGING_HLS_CATAPULT)
#include <ac_channel.h>
namespace ranging_hls {
template <class T>
using hls_stream = ac_channel<T>;
}
#elif defined(__SYNTHESIS__)
#include <hls_stream.h>
namespace ranging_hls {
template <class T>
using hls_stream = hls::stream<T>;
}
#else
#include <deque>
#include <stdexcept>
namespace ranging_hls {
// C-simulation stand-in for Vitis's hls::stream (Catapult: ac_channel), which replace it under
// __SYNTHESIS__: an unbounded FIFO with the same read / write / empty calls.
template <class T>
class hls_stream {
 public:
  void write(const T& v) { q_.push_back(v); }
  T read() {
    if (q_.empty()) throw std::runtime_error("hls_stream: read from an empty stream");
    T v = q_.front();
    q_.pop_front();
    return v;
  }
  bool empty() const { return q_.empty(); }
  std::size_t size() const { return q_.size(); }

 private:
  std::deque<T> q_;
};
}  // namespace ranging_hls
#endif

namespace ranging_hls {

// ---- word types -----------------------------------------------------------------------------
// Every register is held in a native 64-bit word; its configured width (<= 64) is enforced by
// fx::sext / fx::zext. A build for an HLS tool that wants arbitrary-precision types may
// redefine these two (e.g. ac_int<64, true> / ap_int<64>); only the native words are tested.
using word_t = std::int64_t;
using uword_t = std::uint64_t;

// ---- fixed-width integer helpers ------------------------------------------------------------
namespace fx {

enum Rounding { kTruncate = 0, kRoundHalfUp = 1, kConvergent = 2 };  // = generated SOS_ROUNDING

template <int W>
constexpr std::uint64_t mask() {
  static_assert(W >= 1 && W <= 64, "width out of range");
  if constexpr (W == 64) {
    return ~std::uint64_t{0};
  } else {
    return (std::uint64_t{1} << W) - 1;
  }
}

// The low W bits of v read as a signed W-bit two's complement number.
template <int W>
constexpr std::int64_t sext(std::int64_t v) {
  const std::uint64_t m = mask<W>();
  std::uint64_t u = static_cast<std::uint64_t>(v) & m;
  if constexpr (W < 64) {
    if ((u >> (W - 1)) & 1u) u |= ~m;
  }
  return static_cast<std::int64_t>(u);  // modular conversion (C++20)
}

// The low W bits of v, unsigned.
template <int W>
constexpr std::uint64_t zext(std::uint64_t v) {
  return v & mask<W>();
}

template <int W>
constexpr std::int64_t smin() {
  return W == 64 ? static_cast<std::int64_t>(std::uint64_t{1} << 63) : -(std::int64_t{1} << (W - 1));
}
template <int W>
constexpr std::int64_t smax() {
  return static_cast<std::int64_t>(mask<W>() >> 1);
}

// floor(v / 2^K) adjusted by the rounding rule. RoundHalfUp is (v + 2^(K-1)) >> K, written
// as floor + (dropped bits >= half) so that it cannot overflow.
template <int K, int Mode>
constexpr std::int64_t shift_round(std::int64_t v) {
  static_assert(K >= 0 && K <= 62, "shift out of range");
  if constexpr (K == 0) {
    return v;
  } else {
    const std::int64_t q = v >> K;  // arithmetic shift (C++20): floor
    if constexpr (Mode == kTruncate) return q;
    const std::uint64_t rem = static_cast<std::uint64_t>(v) & mask<K>();
    const std::uint64_t half = std::uint64_t{1} << (K - 1);
    if constexpr (Mode == kRoundHalfUp) {
      return q + (rem >= half ? 1 : 0);
    } else {
      return q + ((rem > half || (rem == half && (q & 1))) ? 1 : 0);
    }
  }
}

// Signed W-bit result of v / 2^K: round by Mode, then saturate (Sat) or wrap.
template <int W, int K, int Mode, bool Sat>
constexpr std::int64_t quantize(std::int64_t v) {
  const std::int64_t q = shift_round<K, Mode>(v);
  if constexpr (Sat) {
    return q < smin<W>() ? smin<W>() : (q > smax<W>() ? smax<W>() : q);
  } else {
    return sext<W>(q);
  }
}

}  // namespace fx

// ---- stream words ---------------------------------------------------------------------------
struct AdcBeat {          // s_axis: one ADC sample
  std::int64_t data = 0;  // signed SOS_IN_W code (the low SOS_IN_W bits are used)
  bool last = false;      // end of a record: emit a pending candidate after this sample (flush)
};

struct EventBeat {           // m_axis: one detection (PeakDetectorFixed's EventFixed)
  std::int64_t code = 0;     // 1-based, DET_CODE_W bits
  std::int64_t arrival = 0;  // signed DET_TIME_W + DET_FRAC_W + 1 bits: sample . fraction
  std::uint64_t score = 0;   // DET_SCORE_W bits: rho^2 as a fraction
  std::uint64_t margin = 0;  // DET_SCORE_W bits: score(best) - score(second)
};

// Integer constants of a configuration, as int (template arguments).
#define RANGING_HLS_I(name) static_cast<int>(Cfg::name)

}  // namespace ranging_hls
