#pragma once
// HLS stage 1: the bandpass filter, SOS_SECTIONS Direct Form I second-order sections in
// cascade (model: BandpassFixed, model/dsp/bandpass_filter.hpp; RTL: rtl/bandpass_sos.v).
// y = sum(b_k x[n-k]) - sum(a_k y[n-k]) per section on an SOS_ACC_W accumulator, quantized to
// SOS_DATA_W bits (rounding SOS_ROUNDING, saturate or wrap SOS_SATURATE). One sample per call.
#include "hls/hls_common.hpp"

// Loop labels exist for the HLS reports; g++ would call them unused.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"

namespace ranging_hls {

// ---- stage 1: bandpass, Direct Form I second-order sections ---------------------------------
template <class Cfg>
class BandpassSos {
 public:
  static constexpr int kSections = RANGING_HLS_I(SOS_SECTIONS);
  static constexpr int kInW = RANGING_HLS_I(SOS_IN_W);
  static constexpr int kDataW = RANGING_HLS_I(SOS_DATA_W);
  static constexpr int kAccW = RANGING_HLS_I(SOS_ACC_W);
  static constexpr int kShift = RANGING_HLS_I(SOS_COEF_FRAC);      // acc frac - data frac
  static constexpr int kAlign = RANGING_HLS_I(SOS_DATA_FRAC) - (kInW - 1);  // input -> data frac
  static_assert(kAlign >= 0 && kAccW <= 64 && kDataW <= 64, "bandpass widths");

  void reset() {
  sos_reset:
    for (int k = 0; k < kSections; ++k) {
      RANGING_HLS_PRAGMA(hls_unroll yes)
      RANGING_HLS_PRAGMA(HLS UNROLL)
      x1_[k] = x2_[k] = y1_[k] = y2_[k] = 0;
      out_[k] = 0;
    }
  }

  // x: signed IN_W ADC code; returns the cascade output (signed DATA_W, DATA_FRAC fraction bits).
  word_t step(word_t x_in) {
    RANGING_HLS_PRAGMA(HLS INLINE)
    RANGING_HLS_PRAGMA(HLS ARRAY_PARTITION variable=x1_ complete)
    RANGING_HLS_PRAGMA(HLS ARRAY_PARTITION variable=x2_ complete)
    RANGING_HLS_PRAGMA(HLS ARRAY_PARTITION variable=y1_ complete)
    RANGING_HLS_PRAGMA(HLS ARRAY_PARTITION variable=y2_ complete)
    // Aligning the input to DATA_FRAC is wiring.
    word_t x = fx::sext<kInW>(x_in) * (word_t{1} << kAlign);
  sos_sections:
    for (int k = 0; k < kSections; ++k) {
      // The sections form a chain (each feeds the next): unrolled, the scheduler shares
      // the multipliers across the sample period.
      RANGING_HLS_PRAGMA(hls_unroll yes)
      RANGING_HLS_PRAGMA(HLS UNROLL)
      const word_t b0 = Cfg::SOS_COEFS[5 * k + 0], b1 = Cfg::SOS_COEFS[5 * k + 1];
      const word_t b2 = Cfg::SOS_COEFS[5 * k + 2], a1 = Cfg::SOS_COEFS[5 * k + 3];
      const word_t a2 = Cfg::SOS_COEFS[5 * k + 4];
      // Exact: the model validated that ACC_W holds the worst-case sum of products.
      word_t acc = b0 * x + b2 * x2_[k] - a1 * y1_[k] - a2 * y2_[k];
      if (b1 != 0) acc += b1 * x1_[k];  // b1 = 0 for the Butterworth bandpass: no multiplier
      acc = fx::sext<kAccW>(acc);
      const word_t y = fx::quantize<kDataW, kShift, RANGING_HLS_I(SOS_ROUNDING),
                                          Cfg::SOS_SATURATE != 0>(acc);
      x2_[k] = x1_[k];
      x1_[k] = x;
      y2_[k] = y1_[k];
      y1_[k] = y;
      out_[k] = y;
      x = y;
    }
    return x;
  }

  word_t section_output(int k) const { return out_[k]; }  // debug tap (last sample)

 private:
  word_t x1_[kSections] = {}, x2_[kSections] = {}, y1_[kSections] = {}, y2_[kSections] = {};
  word_t out_[kSections] = {};
};

}  // namespace ranging_hls

#pragma GCC diagnostic pop
