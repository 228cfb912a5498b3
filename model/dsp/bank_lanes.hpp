#pragma once
// The correlator bank on the SIMD lanes (batch::BankBatch / FloatBankBatch of
// receiver_batch_kernels.hpp): the arrays a batch bank points into, and the fixed bank's
// constants taken from a CorrelatorBankFixed, in one place for both users:
//   ReceiverFixedBatch / ReceiverFloatBatch   one stream per lane (receiver_batch.cpp)
//   CorrelatorBankFixed::feed_split           one long block's segments, one per lane (the
//                                             bank's time split, correlator_bank.cpp)
// Internal to model/dsp (not included by the kernels' translation unit, which sees plain data only).
#include <cstdint>
#include <span>
#include <vector>

#include "model/dsp/correlator_bank.hpp"
#include "model/dsp/receiver_batch_kernels.hpp"

namespace ranging {

// The bank's arrays of a batch (Lanes or LanesF), zeroed, and the kernel state pointed at them
// in the scalar bank's reset positions (the rings' newest slot is the last one).
template <class L, class Bank>
struct BankArrays {
  std::vector<L> b_re, b_im, y2h, bd_re, bd_im, f_re, f_im, q;
  void reset(Bank& b) {
    b_re.assign(static_cast<std::size_t>(b.period), L{});
    b_im.assign(b_re.size(), L{});
    y2h.assign(b.window, L{});
    bd_re.assign(2 * b.bd_n, L{});
    bd_im.assign(2 * b.bd_n, L{});
    f_re.assign(2 * b.f_n, L{});
    f_im.assign(2 * b.f_n, L{});
    q.assign(static_cast<std::size_t>(b.codes), L{});
    b.b_re = b_re.data();
    b.b_im = b_im.data();
    b.y2h = y2h.data();
    b.bd_re = bd_re.data();
    b.bd_im = bd_im.data();
    b.f_re = f_re.data();
    b.f_im = f_im.data();
    b.q = q.data();
    b.dec_phase = 0;
    b.y_idx = b.window - 1;
    b.bd_idx = b.bd_n - 1;
    b.f_idx = b.f_n - 1;
    b.acc_re = b.acc_im = b.energy = L{};
  }
};

// CorrelatorBankFixed's constants (its layout, quantized taps, sign masks, weights) and
// kBatchLanes lanes of its state, every lane at reset (reset()). Not copyable: b points into
// the members.
struct FixedBankLanes {
  batch::BankBatch b;
  std::vector<std::int64_t> lo_cos, lo_nsin, taps_rev, sign_mask, weights;
  BankArrays<batch::Lanes, batch::BankBatch> arrays;
  OverflowCounter mix_events[batch::kBatchLanes], chip_events[batch::kBatchLanes], corr_events[batch::kBatchLanes];

  explicit FixedBankLanes(const CorrelatorBankFixed& bank);
  FixedBankLanes(const FixedBankLanes&) = delete;
  FixedBankLanes& operator=(const FixedBankLanes&) = delete;
  void reset();  // every lane at CorrelatorBankFixed::reset's state, counters cleared
};

}  // namespace ranging
