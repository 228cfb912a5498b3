#include "model/dsp/receiver_batch.hpp"

#include <algorithm>

#include "model/base/error.hpp"
#include "model/dsp/bank_lanes.hpp"
#include "model/dsp/receiver_batch_kernels.hpp"

namespace ranging {

using batch::kBatchLanes;
using batch::Lanes;
using batch::LanesF;

static_assert(ReceiverFixedBatch::kLanes == static_cast<std::size_t>(kBatchLanes));

namespace {
constexpr std::size_t kChunk = 1024;  // samples per lane per pass of the kernels

// The chunk loop of both batch receivers. The lanes run to the longest stream in chunks of at
// most kChunk samples, and a chunk ends at every lane's end: a lane has all n samples of a
// chunk or none, and finish(l) runs right after lane l's last sample (before the first chunk
// for an empty stream), so a lane's counters and its detector's flush are read at its own end.
// chunk(n0, n, src, open) processes samples [n0, n0 + n): src[l] points at lane l's sample n0,
// or at `zeros` (>= kChunk of them) for an ended or unused lane, whose results are discarded;
// open[l] says whether lane l is still running.
template <class T, class Chunk, class Finish>
void run_chunks(std::span<const std::span<const T>> streams, const T* zeros, Chunk&& chunk, Finish&& finish) {
  const std::size_t lanes = streams.size();
  std::size_t longest = 0;
  bool open[kBatchLanes] = {};
  const auto close = [&](std::size_t l) {
    finish(l);
    open[l] = false;
  };
  for (std::size_t l = 0; l < lanes; ++l) {
    longest = std::max(longest, streams[l].size());
    open[l] = true;
  }
  for (std::size_t l = 0; l < lanes; ++l) {
    if (streams[l].empty()) close(l);
  }
  for (std::size_t n0 = 0, n = 0; n0 < longest; n0 += n) {
    n = std::min(kChunk, longest - n0);
    for (std::size_t l = 0; l < lanes; ++l) {
      if (streams[l].size() > n0) n = std::min(n, streams[l].size() - n0);
    }
    const T* src[kBatchLanes];
    for (std::size_t l = 0; l < static_cast<std::size_t>(kBatchLanes); ++l) {
      src[l] = l < lanes && streams[l].size() > n0 ? streams[l].data() + n0 : zeros;
    }
    chunk(n0, n, src, static_cast<const bool*>(open));
    for (std::size_t l = 0; l < lanes; ++l) {
      if (open[l] && streams[l].size() == n0 + n) close(l);
    }
  }
}
}  // namespace

// The kernels' state: the bandpass lanes and the bank's (bank_lanes.hpp).
struct ReceiverFixedBatch::Kernels {
  batch::BandpassBatch bp;
  BandpassFixed filter;  // the scalar filter the constants come from (and the input range check)
  FixedBankLanes lanes;  // the bank's constants and arrays; lanes.b is the kernel's state
  batch::BankBatch& bank = lanes.b;
  OverflowCounter bp_events[kBatchLanes];
  std::vector<Lanes> in, out;  // a chunk, lane-interleaved
  std::vector<std::int64_t> zeros = std::vector<std::int64_t>(kChunk);  // an ended lane's input

  explicit Kernels(const ReceiverDesign& d)
      : filter(d.filter, d.config.bandpass), lanes(CorrelatorBankFixed(d.reference, d.config.correlator)) {
    bp = bandpass_batch_constants(filter);
    bp.events = bp_events;
    reset();
  }

  void reset() {
    std::fill(std::begin(bp.y1), std::end(bp.y1), Lanes{});
    std::fill(std::begin(bp.y2), std::end(bp.y2), Lanes{});
    bp.x1 = bp.x2 = Lanes{};
    lanes.reset();
    for (int l = 0; l < kBatchLanes; ++l) bp_events[l] = {};
  }
};

ReceiverFixedBatch::ReceiverFixedBatch(const ReceiverDesign& design)
    : design_(design), frac_bits_(design.config.detector.frac_bits), score_bits_(design.config.correlator.score_bits) {
  vectorized_ = batch::batch_kernels_available() &&
                static_cast<int>(design.filter.sections.size()) <= batch::kBatchMaxSections;
  if (vectorized_) k_ = std::make_unique<Kernels>(design_);
}

ReceiverFixedBatch::~ReceiverFixedBatch() = default;

void ReceiverFixedBatch::run(std::span<const std::span<const std::int64_t>> streams,
                             std::vector<std::vector<EventFixed>>& events, std::vector<OverflowCounter>& overflows) {
  events.assign(streams.size(), {});
  overflows.assign(streams.size(), {});
  for (std::size_t s0 = 0; s0 < streams.size(); s0 += kLanes) {
    const std::size_t n = std::min(kLanes, streams.size() - s0);
    if (!vectorized_) {
      for (std::size_t s = s0; s < s0 + n; ++s) {
        ReceiverFixed rx(design_);
        rx.execute_block(streams[s], events[s]);
        if (auto e = rx.flush_raw()) events[s].push_back(*e);
        overflows[s] = rx.overflow_events();
      }
      continue;
    }
    run_lanes(streams.subspan(s0, n), events.data() + s0, overflows.data() + s0);
  }
}

void ReceiverFixedBatch::run_lanes(std::span<const std::span<const std::int64_t>> streams, std::vector<EventFixed>* events,
                                   OverflowCounter* overflows) {
  Kernels& k = *k_;
  k.reset();
  const std::size_t lanes = streams.size();
  std::vector<PeakDetectorFixed> det(lanes, PeakDetectorFixed(design_.config.detector, design_.layout,
                                                              design_.config.correlator));
  const int energy_shift = design_.layout.energy_shift;
  const std::size_t codes = static_cast<std::size_t>(k.bank.codes);
  std::vector<std::uint64_t> qv(codes);
  const std::int64_t in_lo = fx_min_raw(k.filter.input_format()), in_hi = fx_max_raw(k.filter.input_format());
  k.in.resize(kChunk);
  k.out.resize(kChunk);
  const auto chunk = [&](std::size_t n0, std::size_t n, const std::int64_t* const* src, const bool* open) {
    // Interleave: lane l's sample n0 + i at in[i].v[l].
    std::int64_t mn = 0, mx = 0;
    batch::interleave_batch(src, k.in.data(), n, &mn, &mx);
    if (mn < in_lo || mx > in_hi) {  // the input range, once per chunk; the scalar check names the sample
      for (std::size_t l = 0; l < lanes; ++l) {
        if (open[l]) k.filter.check_input(streams[l].subspan(n0, n));
      }
    }
    batch::bandpass_batch(k.bp, k.in.data(), k.out.data(), n);
    for (std::size_t i = 0; i < n;) {
      bool ready = false;
      i += batch::bank_feed_batch(k.bank, k.out.data() + i, n - i, &ready);
      if (!ready) continue;
      const auto last = static_cast<std::int64_t>(n0 + i - 1);  // index of the last sample fed
      for (std::size_t l = 0; l < lanes; ++l) {
        if (!open[l]) continue;
        for (std::size_t j = 0; j < codes; ++j) qv[j] = static_cast<std::uint64_t>(k.bank.q[j].v[l]);
        const std::uint64_t norm = static_cast<std::uint64_t>(k.bank.energy.v[l]) >> energy_shift;
        if (auto e = det[l].execute(qv, last, norm)) events[l].push_back(*e);
      }
    }
  };
  const auto finish = [&](std::size_t l) {  // lane l's last sample is in: flush, read its counters
    if (auto e = det[l].flush()) events[l].push_back(*e);
    overflows[l] = k.bp_events[l] + k.lanes.mix_events[l] + k.lanes.chip_events[l] + k.lanes.corr_events[l];
  };
  run_chunks(streams, k.zeros.data(), chunk, finish);
}

// ---- float -----------------------------------------------------------------------------


struct ReceiverFloatBatch::Kernels {
  batch::FloatBandpassBatch bp;
  batch::FloatBankBatch bank;
  CorrelatorBankFloat scalar;  // the LO tables come from it
  std::vector<double> taps, signs, gain;
  BankArrays<LanesF, batch::FloatBankBatch> arrays;
  std::vector<LanesF> in, out;
  std::vector<double> zeros = std::vector<double>(kChunk);  // an ended lane's input

  explicit Kernels(const ReceiverDesign& d) : bp(bandpass_batch_constants(d.filter.sections)), scalar(d.reference) {
    const CorrelatorReference& r = d.reference;
    auto& b = bank;
    b.period = r.period;
    b.decimation = r.decimation;
    b.chips = static_cast<int>(r.codes.front().size());
    b.codes = static_cast<int>(r.codes.size());
    b.step = r.chip_samples / r.decimation;
    b.window = static_cast<std::size_t>(r.window);
    b.bd_n = r.chip_taps.size();
    b.f_n = static_cast<std::size_t>(b.chips - 1) * static_cast<std::size_t>(b.step) + 1;
    taps = r.chip_taps;
    for (const auto& code : r.codes) {
      for (std::uint8_t chip : code) signs.push_back(chip ? 1.0 : -1.0);
    }
    gain = r.code_gain;
    b.lo_cos = scalar.lo_cos().data();
    b.lo_sin = scalar.lo_sin().data();
    b.taps = taps.data();
    b.signs = signs.data();
    b.gain = gain.data();
  }

  void reset() {
    auto& b = bank;
    for (int k = 0; k < batch::kBatchMaxSections; ++k) bp.x1[k] = bp.x2[k] = bp.y1[k] = bp.y2[k] = LanesF{};
    arrays.reset(b);  // CorrelatorBankFloat::reset's positions
    b.b_idx = 0;
  }
};

ReceiverFloatBatch::ReceiverFloatBatch(const ReceiverDesign& design) : design_(design) {
  vectorized_ = batch::batch_kernels_available() && !design.reference.codes.empty() &&
                static_cast<int>(design.filter.sections.size()) <= batch::kBatchMaxSections;
  if (vectorized_) k_ = std::make_unique<Kernels>(design_);
}

ReceiverFloatBatch::~ReceiverFloatBatch() = default;

void ReceiverFloatBatch::run(std::span<const std::span<const double>> streams, double gain,
                             std::vector<std::vector<Event>>& events, std::vector<std::vector<double>>* filtered) {
  events.assign(streams.size(), {});
  if (filtered) {
    filtered->resize(streams.size());
    for (std::size_t s = 0; s < streams.size(); ++s) (*filtered)[s].assign(streams[s].size(), 0.0);
  }
  for (std::size_t s0 = 0; s0 < streams.size(); s0 += kLanes) {
    const std::size_t n = std::min(kLanes, streams.size() - s0);
    if (!vectorized_) {
      for (std::size_t s = s0; s < s0 + n; ++s) {
        ReceiverFloat rx(design_);
        std::vector<double> x(streams[s].size());
        for (std::size_t i = 0; i < x.size(); ++i) x[i] = streams[s][i] * gain;
        rx.execute_block(x, events[s], filtered ? std::span<double>((*filtered)[s]) : std::span<double>());
        if (auto e = rx.flush()) events[s].push_back(*e);
      }
      continue;
    }
    run_lanes(streams.subspan(s0, n), gain, events.data() + s0, filtered ? filtered->data() + s0 : nullptr);
  }
}

void ReceiverFloatBatch::run_lanes(std::span<const std::span<const double>> streams, double gain,
                                   std::vector<Event>* events, std::vector<double>* filtered) {
  Kernels& k = *k_;
  k.reset();
  const std::size_t lanes = streams.size();
  std::vector<PeakDetectorFloat> det(lanes, PeakDetectorFloat(design_.config.detector, design_.reference));
  const std::size_t codes = static_cast<std::size_t>(k.bank.codes);
  std::vector<double> qv(codes), pv(codes);
  std::vector<LanesF> qprev(codes);  // the previous output's Q_j (zeros before the first)
  const double thr = design_.config.detector.threshold, min_e = design_.config.detector.min_energy;
  k.in.resize(kChunk);
  k.out.resize(kChunk);
  const auto chunk = [&](std::size_t n0, std::size_t n, const double* const* src, const bool* open) {
    batch::interleave_batch_float(src, gain, k.in.data(), n);  // in[i].v[l] = src[l][i] * gain
    batch::bandpass_batch_float(k.bp, k.in.data(), k.out.data(), n);
    if (filtered) {
      for (std::size_t l = 0; l < lanes; ++l) {
        if (!open[l]) continue;
        double* dst = filtered[l].data() + n0;
        for (std::size_t i = 0; i < n; ++i) dst[i] = k.out[i].v[l];
      }
    }
    for (std::size_t i = 0; i < n;) {
      bool ready = false;
      i += batch::bank_feed_batch_float(k.bank, k.out.data() + i, n - i, &ready);
      if (!ready) continue;
      const auto last = static_cast<std::int64_t>(n0 + i - 1);
      // A lane's detector is called when its gate is open or it holds a candidate; otherwise
      // the output changes nothing (PeakDetectorFloat::execute's own early return).
      const unsigned gates = batch::gate_batch_float(k.bank, thr, min_e);
      for (std::size_t l = 0; l < lanes; ++l) {
        if (!open[l] || (det[l].idle() && !((gates >> l) & 1u))) continue;
        for (std::size_t j = 0; j < codes; ++j) {
          qv[j] = k.bank.q[j].v[l];
          pv[j] = qprev[j].v[l];
        }
        if (auto e = det[l].execute(qv, pv, last, k.bank.energy.v[l])) events[l].push_back(*e);
      }
      std::copy(k.bank.q, k.bank.q + codes, qprev.begin());
    }
  };
  const auto finish = [&](std::size_t l) {
    if (auto e = det[l].flush()) events[l].push_back(*e);
  };
  run_chunks(streams, k.zeros.data(), chunk, finish);
}

}  // namespace ranging
