#pragma once
// HLS stage 3: the streaming peak detector (model: PeakDetectorFixed,
// model/dsp/peak_detector.hpp; RTL: rtl/peak_detector.v): best two codes per output, gate,
// candidate tracking and hold-off, then at an event the score, margin and parabolic fraction
// by integer division. Widths DET_*_W from the generated configuration.
#include "hls/hls_common.hpp"

// Loop labels exist for the HLS reports; g++ would call them unused.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"

namespace ranging_hls {

// ---- stage 3: peak detector -----------------------------------------------------------------
template <class Cfg>
class PeakDetector {
 public:
  static constexpr int kCodes = RANGING_HLS_I(DET_CODES);
  static constexpr int kScoreW = RANGING_HLS_I(DET_SCORE_W);
  static constexpr int kFracW = RANGING_HLS_I(DET_FRAC_W);
  static constexpr int kTimeW = RANGING_HLS_I(DET_TIME_W);
  static constexpr int kWeightedW = RANGING_HLS_I(DET_WEIGHTED_W);
  static constexpr int kNormW = RANGING_HLS_I(DET_ENERGY_W) - RANGING_HLS_I(DET_ENERGY_SHIFT);
  static constexpr uword_t kThreshold = static_cast<uword_t>(Cfg::DET_THRESHOLD[0]);
  static constexpr uword_t kMinNorm = static_cast<uword_t>(Cfg::DET_MIN_NORM[0]);
  static constexpr uword_t kHoldoff = static_cast<uword_t>(Cfg::DET_HOLDOFF);
  static constexpr uword_t kScoreCap = fx::mask<kScoreW>();
  // The gate product THRESHOLD * norm and the fraction's numerator stay inside 64 bits.
  static_assert(kScoreW + kNormW <= 64, "detector: SCORE_W + norm width above 64 bits");
  static_assert(kWeightedW + kFracW + 2 <= 63, "detector: fraction numerator above 63 bits");
  static_assert(RANGING_HLS_I(DET_CODES) == RANGING_HLS_I(BANK_CODES), "codes");

  void reset() {
    cand_valid_ = cand_has_next_ = false;
    cand_n_ = 0;
    cand_code_ = 0;
    cand_q_prev_ = cand_q_ = cand_q_next_ = cand_q_second_ = cand_norm_ = 0;
  det_reset:
    for (int j = 0; j < kCodes; ++j) prev_[j] = 0;
  }

  // One decimated output of the bank. Returns true when an event is emitted.
  bool step(const BankOutput<Cfg>& in, EventBeat& ev) {
    RANGING_HLS_PRAGMA(HLS INLINE)
    RANGING_HLS_PRAGMA(HLS ARRAY_PARTITION variable=prev_ complete)
    // best = argmax (lowest index on ties), second = max of the others, in one pass.
    int best = 0;
    uword_t best_q = in.weighted[0], second = 0;
  best_two:
    for (int j = 1; j < kCodes; ++j) {
      RANGING_HLS_PRAGMA(hls_unroll yes)
      RANGING_HLS_PRAGMA(HLS UNROLL)
      const uword_t q = in.weighted[j];
      if (q > best_q) {
        second = best_q;
        best_q = q;
        best = j;
      } else if (q > second) {
        second = q;
      }
    }
    if (cand_valid_ && !cand_has_next_) {
      cand_q_next_ = in.weighted[cand_code_];
      cand_has_next_ = true;
    }
    const uword_t norm = in.energy >> RANGING_HLS_I(DET_ENERGY_SHIFT);
    const uword_t norm1 = norm == 0 ? 1 : norm;
    const bool gate = best_q >= kThreshold * norm1 && norm >= kMinNorm;
    bool emit = false;
    // The candidate is the best normalized match: Q / norm > Q_c / norm_c, cross-multiplied
    // exactly (79 bits; ap_uint<128> under Vitis).
    const unsigned __int128 lhs = static_cast<unsigned __int128>(best_q) * (cand_norm_ == 0 ? 1 : cand_norm_);
    const unsigned __int128 rhs = static_cast<unsigned __int128>(cand_q_) * norm1;
    if (gate && (!cand_valid_ || lhs > rhs)) {
      cand_valid_ = true;
      cand_has_next_ = false;
      cand_n_ = in.index;
      cand_code_ = best;
      cand_q_prev_ = prev_[best];
      cand_q_ = best_q;
      cand_q_next_ = 0;
      cand_q_second_ = second;
      cand_norm_ = norm;
    } else if (cand_valid_ && cand_has_next_ && fx::zext<kTimeW>(in.index - cand_n_) >= kHoldoff) {
      ev = make_event();
      cand_valid_ = false;
      emit = true;
    }
  det_prev:
    for (int j = 0; j < kCodes; ++j) {
      RANGING_HLS_PRAGMA(hls_unroll yes)
      RANGING_HLS_PRAGMA(HLS UNROLL)
      prev_[j] = in.weighted[j];
    }
    return emit;
  }

  // End of a record: emit a pending candidate (no right neighbour: symmetric parabola).
  bool flush(EventBeat& ev) {
    if (!cand_valid_) return false;
    if (!cand_has_next_) cand_q_next_ = cand_q_prev_;
    ev = make_event();
    cand_valid_ = false;
    return true;
  }

 private:
  static uword_t score(uword_t q, uword_t norm) {
    const uword_t s = q / (norm == 0 ? 1 : norm);  // only at an event: one divider
    return s > kScoreCap ? kScoreCap : s;
  }

  // Parabolic vertex (Q_next - Q_prev) 2^FRAC_W / (2 (2 Q - Q_prev - Q_next)), truncated
  // toward zero, clamped to +-1/2 (model: parabolic_fraction).
  static word_t fraction(uword_t qp, uword_t q, uword_t qn) {
    const word_t den = 2 * (2 * static_cast<word_t>(q) - static_cast<word_t>(qp) -
                                  static_cast<word_t>(qn));
    if (den <= 0) return 0;
    const word_t num = (static_cast<word_t>(qn) - static_cast<word_t>(qp)) *
                             (word_t{1} << kFracW);
    constexpr word_t half = (word_t{1} << kFracW) >> 1;  // 0 when FRAC_W = 0
    const word_t r = num / den;  // C++ division truncates toward zero
    return r < -half ? -half : (r > half ? half : r);
  }

  EventBeat make_event() const {
    EventBeat e;
    e.code = cand_code_ + 1;
    e.arrival = static_cast<word_t>(cand_n_) * (word_t{1} << kFracW) +
                RANGING_HLS_I(DET_DECIM) * fraction(cand_q_prev_, cand_q_, cand_q_next_);
    e.score = score(cand_q_, cand_norm_);
    e.margin = e.score - score(cand_q_second_, cand_norm_);
    return e;
  }

  bool cand_valid_ = false, cand_has_next_ = false;
  uword_t cand_n_ = 0;
  int cand_code_ = 0;
  uword_t cand_q_prev_ = 0, cand_q_ = 0, cand_q_next_ = 0, cand_q_second_ = 0, cand_norm_ = 0;
  uword_t prev_[kCodes] = {};  // Q_j of the previous decimated output
};

}  // namespace ranging_hls

#pragma GCC diagnostic pop
