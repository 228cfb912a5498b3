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
#include <cstdint>

#ifdef __SYNTHESIS__
#define RANGING_HLS_PRAGMA(x) _Pragma(#x)
#else
#define RANGING_HLS_PRAGMA(x)
#endif

// Loop labels exist for the HLS reports; g++ would call them unused.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"

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
  std::int64_t step(std::int64_t x_in) {
    RANGING_HLS_PRAGMA(HLS INLINE)
    RANGING_HLS_PRAGMA(HLS ARRAY_PARTITION variable=x1_ complete)
    RANGING_HLS_PRAGMA(HLS ARRAY_PARTITION variable=x2_ complete)
    RANGING_HLS_PRAGMA(HLS ARRAY_PARTITION variable=y1_ complete)
    RANGING_HLS_PRAGMA(HLS ARRAY_PARTITION variable=y2_ complete)
    // Aligning the input to DATA_FRAC is wiring.
    std::int64_t x = fx::sext<kInW>(x_in) * (std::int64_t{1} << kAlign);
  sos_sections:
    for (int k = 0; k < kSections; ++k) {
      // The sections form a chain (each feeds the next): unrolled, the scheduler shares
      // the multipliers across the sample period.
      RANGING_HLS_PRAGMA(hls_unroll yes)
      RANGING_HLS_PRAGMA(HLS UNROLL)
      const std::int64_t b0 = Cfg::SOS_COEFS[5 * k + 0], b1 = Cfg::SOS_COEFS[5 * k + 1];
      const std::int64_t b2 = Cfg::SOS_COEFS[5 * k + 2], a1 = Cfg::SOS_COEFS[5 * k + 3];
      const std::int64_t a2 = Cfg::SOS_COEFS[5 * k + 4];
      // Exact: the model validated that ACC_W holds the worst-case sum of products.
      std::int64_t acc = b0 * x + b2 * x2_[k] - a1 * y1_[k] - a2 * y2_[k];
      if (b1 != 0) acc += b1 * x1_[k];  // b1 = 0 for the Butterworth bandpass: no multiplier
      acc = fx::sext<kAccW>(acc);
      const std::int64_t y = fx::quantize<kDataW, kShift, RANGING_HLS_I(SOS_ROUNDING),
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

  std::int64_t section_output(int k) const { return out_[k]; }  // debug tap (last sample)

 private:
  std::int64_t x1_[kSections] = {}, x2_[kSections] = {}, y1_[kSections] = {}, y2_[kSections] = {};
  std::int64_t out_[kSections] = {};
};

// ---- stage 2: correlator bank ---------------------------------------------------------------
template <class Cfg>
struct BankOutput {  // one decimated output
  static constexpr int kCodes = RANGING_HLS_I(BANK_CODES);
  std::uint64_t weighted[kCodes] = {};  // Q_j, unsigned WEIGHTED_W
  std::uint64_t energy = 0;             // E, unsigned ENERGY_W
  std::uint64_t index = 0;              // full-rate index of the last input, TIME_W
};

template <class Cfg>
struct BankTaps {  // debug taps of the bank's internal nodes (last sample / last output)
  static constexpr int kCodes = RANGING_HLS_I(BANK_CODES);
  std::int64_t mix_re = 0, mix_im = 0;     // B, every sample
  std::int64_t dec_re = 0, dec_im = 0;     // Bd, decimated
  std::int64_t chip_re = 0, chip_im = 0;   // F_q
  std::int64_t corr_re[kCodes] = {}, corr_im[kCodes] = {};  // C_q
  std::uint64_t power[kCodes] = {};        // P_j
};

template <class Cfg>
class CorrelatorBank {
 public:
  static constexpr int kDataW = RANGING_HLS_I(BANK_DATA_W);
  static constexpr int kPeriod = RANGING_HLS_I(BANK_PERIOD);
  static constexpr int kMixW = RANGING_HLS_I(BANK_MIX_W);
  static constexpr int kMixShift = RANGING_HLS_I(BANK_MIX_SHIFT);
  static constexpr int kDecim = RANGING_HLS_I(BANK_DECIM);
  static constexpr int kDecW = RANGING_HLS_I(BANK_DEC_W);
  static constexpr int kTaps = RANGING_HLS_I(BANK_TAPS);
  static constexpr int kFirW = RANGING_HLS_I(BANK_FIR_W);
  static constexpr int kChipW = RANGING_HLS_I(BANK_CHIP_W);
  static constexpr int kChipShift = RANGING_HLS_I(BANK_CHIP_SHIFT);
  static constexpr int kChips = RANGING_HLS_I(BANK_CHIPS);
  static constexpr int kCodes = RANGING_HLS_I(BANK_CODES);
  static constexpr int kStep = RANGING_HLS_I(BANK_CHIP_STEP);
  static constexpr int kCombW = RANGING_HLS_I(BANK_COMB_W);
  static constexpr int kCorrW = RANGING_HLS_I(BANK_CORR_W);
  static constexpr int kCorrShift = RANGING_HLS_I(BANK_CORR_SHIFT);
  // P = re^2 + im^2 of two CORR_W words needs 2 CORR_W bits (re = im = -2^(CORR_W-1) gives
  // 2^(2 CORR_W - 1)); a configuration with a narrower POWER_W still gets them.
  static constexpr int kPowerW = RANGING_HLS_I(BANK_POWER_W) > 2 * RANGING_HLS_I(BANK_CORR_W)
                                     ? RANGING_HLS_I(BANK_POWER_W)
                                     : 2 * RANGING_HLS_I(BANK_CORR_W);
  static constexpr int kWeightedW = RANGING_HLS_I(BANK_WEIGHTED_W);
  static constexpr int kWindow = RANGING_HLS_I(BANK_WINDOW);
  static constexpr int kEnergyW = RANGING_HLS_I(BANK_ENERGY_W);
  static constexpr int kTimeW = RANGING_HLS_I(BANK_TIME_W);
  static constexpr int kHistory = (kChips - 1) * kStep + 1;  // F history for the combiner
  static_assert(kFirW <= 63 && kEnergyW <= 63 && kWeightedW <= 63 && kTimeW <= 56, "bank widths");
  static_assert(kDataW <= 32 && kMixW + RANGING_HLS_I(BANK_LO_W) <= 62, "bank widths");

  void reset() {
    phase_ = 0;
    dec_count_ = 0;
    n_ = 0;
    acc_re_ = acc_im_ = 0;
    energy_ = 0;
    b_idx_ = bd_idx_ = f_idx_ = y_idx_ = 0;
    taps_ = BankTaps<Cfg>{};
  bank_reset_b:
    for (int i = 0; i < kPeriod; ++i) b_re_[i] = b_im_[i] = 0;
  bank_reset_bd:
    for (int i = 0; i < kTaps; ++i) bd_re_[i] = bd_im_[i] = 0;
  bank_reset_f:
    for (int i = 0; i < kHistory; ++i) f_re_[i] = f_im_[i] = 0;
  bank_reset_y2:
    for (int i = 0; i < kWindow; ++i) y2_[i] = 0;
  }

  // One filtered sample y (signed DATA_W). Returns true on a decimated output (every DECIM-th
  // sample), written to out.
  bool step(std::int64_t y_in, BankOutput<Cfg>& out) {
    RANGING_HLS_PRAGMA(HLS INLINE)
    const std::int64_t y = fx::sext<kDataW>(y_in);
    // 1. mixer: exact product with the LO table, round half up into MIX_W, saturate.
    const std::int64_t mre =
        fx::quantize<kMixW, kMixShift, fx::kRoundHalfUp, true>(y * Cfg::BANK_LO_COS[phase_]);
    const std::int64_t mim =
        fx::quantize<kMixW, kMixShift, fx::kRoundHalfUp, true>(-(y * Cfg::BANK_LO_SIN[phase_]));
    phase_ = (phase_ == kPeriod - 1) ? 0 : phase_ + 1;
    taps_.mix_re = mre;
    taps_.mix_im = mim;
    // 2. moving sum over one carrier cycle (exact in DEC_W).
    acc_re_ = fx::sext<kDecW>(acc_re_ + mre - b_re_[b_idx_]);
    acc_im_ = fx::sext<kDecW>(acc_im_ + mim - b_im_[b_idx_]);
    b_re_[b_idx_] = mre;
    b_im_[b_idx_] = mim;
    b_idx_ = (b_idx_ == kPeriod - 1) ? 0 : b_idx_ + 1;
    // 7. energy: running sum of y^2 over WINDOW samples, modulo 2^ENERGY_W (the true sum fits).
    const std::uint64_t y2 = static_cast<std::uint64_t>(y * y);
    energy_ = fx::zext<kEnergyW>(energy_ + y2 - y2_[y_idx_]);
    y2_[y_idx_] = y2;
    y_idx_ = (y_idx_ == kWindow - 1) ? 0 : y_idx_ + 1;
    const std::uint64_t n = n_;
    n_ = fx::zext<kTimeW>(n_ + 1);
    if (dec_count_ != kDecim - 1) {
      ++dec_count_;
      return false;
    }
    dec_count_ = 0;

    // Decimator: every DECIM-th moving sum into the chip filter's delay line.
    bd_idx_ = (bd_idx_ == kTaps - 1) ? 0 : bd_idx_ + 1;
    bd_re_[bd_idx_] = acc_re_;
    bd_im_[bd_idx_] = acc_im_;
    taps_.dec_re = acc_re_;
    taps_.dec_im = acc_im_;
    // 3. chip filter F = sum_i g[i] Bd[k - i]: exact (FIR_W), then round half up by CHIP_SHIFT.
    std::int64_t fre = 0, fim = 0;
    int k = bd_idx_;
  chip_fir:
    for (int i = 0; i < kTaps; ++i) {
      RANGING_HLS_PRAGMA(hls_pipeline_init_interval 1)
      RANGING_HLS_PRAGMA(HLS PIPELINE II=1)
      fre += Cfg::BANK_TAP_VALUES[i] * bd_re_[k];
      fim += Cfg::BANK_TAP_VALUES[i] * bd_im_[k];
      k = (k == 0) ? kTaps - 1 : k - 1;
    }
    const std::int64_t chre = fx::quantize<kChipW, kChipShift, fx::kRoundHalfUp, true>(fx::sext<kFirW>(fre));
    const std::int64_t chim = fx::quantize<kChipW, kChipShift, fx::kRoundHalfUp, true>(fx::sext<kFirW>(fim));
    f_idx_ = (f_idx_ == kHistory - 1) ? 0 : f_idx_ + 1;
    f_re_[f_idx_] = chre;
    f_im_[f_idx_] = chim;
    taps_.chip_re = chre;
    taps_.chip_im = chim;

    // 4. combiner taps: F[k - (L-1-m) STEP], m = 0..L-1, shared by every code.
    std::int64_t tre[kChips], tim[kChips];
    RANGING_HLS_PRAGMA(HLS ARRAY_PARTITION variable=tre complete)
    RANGING_HLS_PRAGMA(HLS ARRAY_PARTITION variable=tim complete)
  combiner_taps:
    for (int m = 0; m < kChips; ++m) {
      RANGING_HLS_PRAGMA(hls_pipeline_init_interval 1)
      RANGING_HLS_PRAGMA(HLS PIPELINE II=1)
      int j = f_idx_ - (kChips - 1 - m) * kStep;
      if (j < 0) j += kHistory;
      tre[m] = f_re_[j];
      tim[m] = f_im_[j];
    }
    // 4-6. per code: signed sum of the taps (exact, COMB_W), quantize, power, weight.
  codes:
    for (int c = 0; c < kCodes; ++c) {
      RANGING_HLS_PRAGMA(hls_pipeline_init_interval 1)
      RANGING_HLS_PRAGMA(HLS PIPELINE II=1)
      std::int64_t cre = 0, cim = 0;
    code_chips:
      for (int m = 0; m < kChips; ++m) {
        RANGING_HLS_PRAGMA(hls_unroll yes)
        RANGING_HLS_PRAGMA(HLS UNROLL)
        if (Cfg::BANK_CODE_BITS[c * kChips + m]) {
          cre += tre[m];
          cim += tim[m];
        } else {
          cre -= tre[m];
          cim -= tim[m];
        }
      }
      const std::int64_t qre = fx::quantize<kCorrW, kCorrShift, fx::kRoundHalfUp, true>(fx::sext<kCombW>(cre));
      const std::int64_t qim = fx::quantize<kCorrW, kCorrShift, fx::kRoundHalfUp, true>(fx::sext<kCombW>(cim));
      const std::uint64_t p = fx::zext<kPowerW>(static_cast<std::uint64_t>(qre * qre + qim * qim));
      out.weighted[c] = fx::zext<kWeightedW>(p * static_cast<std::uint64_t>(Cfg::BANK_WEIGHTS[c]));
      taps_.corr_re[c] = qre;
      taps_.corr_im[c] = qim;
      taps_.power[c] = p;
    }
    out.energy = energy_;
    out.index = n;
    return true;
  }

  const BankTaps<Cfg>& taps() const { return taps_; }

 private:
  int phase_ = 0, dec_count_ = 0;
  std::uint64_t n_ = 0;  // full-rate index of the next input (TIME_W bits)
  std::int64_t acc_re_ = 0, acc_im_ = 0;
  std::uint64_t energy_ = 0;
  int b_idx_ = 0, bd_idx_ = 0, f_idx_ = 0, y_idx_ = 0;
  std::int64_t b_re_[kPeriod] = {}, b_im_[kPeriod] = {};      // B history (moving sum)
  std::int64_t bd_re_[kTaps] = {}, bd_im_[kTaps] = {};        // Bd delay line (chip filter)
  std::int64_t f_re_[kHistory] = {}, f_im_[kHistory] = {};    // F_q history (combiner)
  std::uint64_t y2_[kWindow] = {};                            // y^2 history (energy window)
  BankTaps<Cfg> taps_;
};

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
  static constexpr std::uint64_t kThreshold = static_cast<std::uint64_t>(Cfg::DET_THRESHOLD[0]);
  static constexpr std::uint64_t kMinNorm = static_cast<std::uint64_t>(Cfg::DET_MIN_NORM[0]);
  static constexpr std::uint64_t kHoldoff = static_cast<std::uint64_t>(Cfg::DET_HOLDOFF);
  static constexpr std::uint64_t kScoreCap = fx::mask<kScoreW>();
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
    std::uint64_t best_q = in.weighted[0], second = 0;
  best_two:
    for (int j = 1; j < kCodes; ++j) {
      RANGING_HLS_PRAGMA(hls_unroll yes)
      RANGING_HLS_PRAGMA(HLS UNROLL)
      const std::uint64_t q = in.weighted[j];
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
    const std::uint64_t norm = in.energy >> RANGING_HLS_I(DET_ENERGY_SHIFT);
    const std::uint64_t norm1 = norm == 0 ? 1 : norm;
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
  static std::uint64_t score(std::uint64_t q, std::uint64_t norm) {
    const std::uint64_t s = q / (norm == 0 ? 1 : norm);  // only at an event: one divider
    return s > kScoreCap ? kScoreCap : s;
  }

  // Parabolic vertex (Q_next - Q_prev) 2^FRAC_W / (2 (2 Q - Q_prev - Q_next)), truncated
  // toward zero, clamped to +-1/2 (model: parabolic_fraction).
  static std::int64_t fraction(std::uint64_t qp, std::uint64_t q, std::uint64_t qn) {
    const std::int64_t den = 2 * (2 * static_cast<std::int64_t>(q) - static_cast<std::int64_t>(qp) -
                                  static_cast<std::int64_t>(qn));
    if (den <= 0) return 0;
    const std::int64_t num = (static_cast<std::int64_t>(qn) - static_cast<std::int64_t>(qp)) *
                             (std::int64_t{1} << kFracW);
    constexpr std::int64_t half = (std::int64_t{1} << kFracW) >> 1;  // 0 when FRAC_W = 0
    const std::int64_t r = num / den;  // C++ division truncates toward zero
    return r < -half ? -half : (r > half ? half : r);
  }

  EventBeat make_event() const {
    EventBeat e;
    e.code = cand_code_ + 1;
    e.arrival = static_cast<std::int64_t>(cand_n_) * (std::int64_t{1} << kFracW) +
                RANGING_HLS_I(DET_DECIM) * fraction(cand_q_prev_, cand_q_, cand_q_next_);
    e.score = score(cand_q_, cand_norm_);
    e.margin = e.score - score(cand_q_second_, cand_norm_);
    return e;
  }

  bool cand_valid_ = false, cand_has_next_ = false;
  std::uint64_t cand_n_ = 0;
  int cand_code_ = 0;
  std::uint64_t cand_q_prev_ = 0, cand_q_ = 0, cand_q_next_ = 0, cand_q_second_ = 0, cand_norm_ = 0;
  std::uint64_t prev_[kCodes] = {};  // Q_j of the previous decimated output
};

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
  bool step(std::int64_t x, EventBeat& ev) {
    RANGING_HLS_PRAGMA(HLS INLINE)
    filtered_ = bandpass_.step(x);
    decimated_ = bank_.step(filtered_, bank_out_);
    if (!decimated_) return false;
    return detector_.step(bank_out_, ev);
  }
  bool flush(EventBeat& ev) { return detector_.flush(ev); }

  // Debug taps of the last sample (C simulation; unused, they are optimized away in hardware).
  std::int64_t filtered() const { return filtered_; }
  std::int64_t section_output(int k) const { return bandpass_.section_output(k); }
  bool decimated() const { return decimated_; }              // the last sample made an output
  const BankOutput<Cfg>& bank_output() const { return bank_out_; }  // the last decimated output
  const BankTaps<Cfg>& bank_taps() const { return bank_.taps(); }

 private:
  BandpassSos<Cfg> bandpass_;
  CorrelatorBank<Cfg> bank_;
  PeakDetector<Cfg> detector_;
  std::int64_t filtered_ = 0;
  bool decimated_ = false;
  BankOutput<Cfg> bank_out_;
};

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

#undef RANGING_HLS_I

}  // namespace ranging_hls

#pragma GCC diagnostic pop
