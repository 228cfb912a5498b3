#pragma once
// HLS stage 2: the parallel correlator bank (model: CorrelatorBankFixed,
// model/dsp/correlator_bank.hpp; RTL: rtl/correlator_bank.v): mixer to baseband, one-cycle
// moving sum, decimation by BANK_DECIM, chip FIR, code combiner, |C|^2 power, weighting, and
// the energy window every sample. Widths BANK_*_W from the generated configuration.
#include "hls/hls_common.hpp"

// Loop labels exist for the HLS reports; g++ would call them unused.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-label"

namespace ranging_hls {

// ---- stage 2: correlator bank ---------------------------------------------------------------
template <class Cfg>
struct BankOutput {  // one decimated output
  static constexpr int kCodes = RANGING_HLS_I(BANK_CODES);
  uword_t weighted[kCodes] = {};  // Q_j, unsigned WEIGHTED_W
  uword_t energy = 0;             // E, unsigned ENERGY_W
  uword_t index = 0;              // full-rate index of the last input, TIME_W
};

template <class Cfg>
struct BankTaps {  // debug taps of the bank's internal nodes (last sample / last output)
  static constexpr int kCodes = RANGING_HLS_I(BANK_CODES);
  word_t mix_re = 0, mix_im = 0;     // B, every sample
  word_t dec_re = 0, dec_im = 0;     // Bd, decimated
  word_t chip_re = 0, chip_im = 0;   // F_q
  word_t corr_re[kCodes] = {}, corr_im[kCodes] = {};  // C_q
  uword_t power[kCodes] = {};        // P_j
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
  bool step(word_t y_in, BankOutput<Cfg>& out) {
    RANGING_HLS_PRAGMA(HLS INLINE)
    const word_t y = fx::sext<kDataW>(y_in);
    // 1. mixer: exact product with the LO table, round half up into MIX_W, saturate.
    const word_t mre =
        fx::quantize<kMixW, kMixShift, fx::kRoundHalfUp, true>(y * Cfg::BANK_LO_COS[phase_]);
    const word_t mim =
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
    const uword_t y2 = static_cast<uword_t>(y * y);
    energy_ = fx::zext<kEnergyW>(energy_ + y2 - y2_[y_idx_]);
    y2_[y_idx_] = y2;
    y_idx_ = (y_idx_ == kWindow - 1) ? 0 : y_idx_ + 1;
    const uword_t n = n_;
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
    word_t fre = 0, fim = 0;
    int k = bd_idx_;
  chip_fir:
    for (int i = 0; i < kTaps; ++i) {
      RANGING_HLS_PRAGMA(hls_pipeline_init_interval 1)
      RANGING_HLS_PRAGMA(HLS PIPELINE II=1)
      fre += Cfg::BANK_TAP_VALUES[i] * bd_re_[k];
      fim += Cfg::BANK_TAP_VALUES[i] * bd_im_[k];
      k = (k == 0) ? kTaps - 1 : k - 1;
    }
    const word_t chre = fx::quantize<kChipW, kChipShift, fx::kRoundHalfUp, true>(fx::sext<kFirW>(fre));
    const word_t chim = fx::quantize<kChipW, kChipShift, fx::kRoundHalfUp, true>(fx::sext<kFirW>(fim));
    f_idx_ = (f_idx_ == kHistory - 1) ? 0 : f_idx_ + 1;
    f_re_[f_idx_] = chre;
    f_im_[f_idx_] = chim;
    taps_.chip_re = chre;
    taps_.chip_im = chim;

    // 4. combiner taps: F[k - (L-1-m) STEP], m = 0..L-1, shared by every code.
    word_t tre[kChips], tim[kChips];
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
      word_t cre = 0, cim = 0;
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
      const word_t qre = fx::quantize<kCorrW, kCorrShift, fx::kRoundHalfUp, true>(fx::sext<kCombW>(cre));
      const word_t qim = fx::quantize<kCorrW, kCorrShift, fx::kRoundHalfUp, true>(fx::sext<kCombW>(cim));
      const uword_t p = fx::zext<kPowerW>(static_cast<uword_t>(qre * qre + qim * qim));
      out.weighted[c] = fx::zext<kWeightedW>(p * static_cast<uword_t>(Cfg::BANK_WEIGHTS[c]));
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
  uword_t n_ = 0;  // full-rate index of the next input (TIME_W bits)
  word_t acc_re_ = 0, acc_im_ = 0;
  uword_t energy_ = 0;
  int b_idx_ = 0, bd_idx_ = 0, f_idx_ = 0, y_idx_ = 0;
  word_t b_re_[kPeriod] = {}, b_im_[kPeriod] = {};      // B history (moving sum)
  word_t bd_re_[kTaps] = {}, bd_im_[kTaps] = {};        // Bd delay line (chip filter)
  word_t f_re_[kHistory] = {}, f_im_[kHistory] = {};    // F_q history (combiner)
  uword_t y2_[kWindow] = {};                            // y^2 history (energy window)
  BankTaps<Cfg> taps_;
};

}  // namespace ranging_hls

#pragma GCC diagnostic pop
