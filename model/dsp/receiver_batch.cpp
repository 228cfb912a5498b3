#include "model/dsp/receiver_batch.hpp"

#include <algorithm>
#include <bit>
#include <cstring>
#include <cstdint>
#include <limits>
#include <numeric>

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
// open[l] says whether lane l is still running. The chunks start at sample `start` (<= every
// lane's length: the samples before it are the caller's, see "Silence" below).
template <class T, class Chunk, class Finish>
void run_chunks(std::span<const std::span<const T>> streams, const T* zeros, Chunk&& chunk, Finish&& finish,
                std::size_t start = 0) {
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
    if (streams[l].size() <= start) close(l);
  }
  for (std::size_t n0 = start, n = 0; n0 < longest; n0 += n) {
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
// Whether `bytes` bytes at p are all zero (a state of +0.0 / 0 words).
bool zero_bits(const void* p, std::size_t bytes) {
  const auto* c = static_cast<const unsigned char*>(p);
  return std::all_of(c, c + bytes, [](unsigned char v) { return v == 0; });
}
template <class Row>
bool zero_rows(const std::vector<Row>& v) {
  return zero_bits(v.data(), v.size() * sizeof(Row));
}

// The lanes' common leading silence (silent(x) on each lane's samples from its first), rounded
// down to a multiple of step (step 0: none).
template <class T, class Silent>
std::size_t common_silence(std::span<const std::span<const T>> streams, std::size_t step, Silent&& silent) {
  if (step == 0 || streams.empty()) return 0;
  std::size_t quiet = std::numeric_limits<std::size_t>::max();
  for (const auto& x : streams) {
    std::size_t i = 0;
    const std::size_t lim = std::min(quiet, x.size());
    while (i < lim && silent(x[i])) ++i;
    quiet = i;
  }
  return quiet / step * step;
}

// A bank's rings (energy window, Bd, F) moved on by s samples (a multiple of the decimation) as
// the samples would have moved them; the LO and decimation phases are the caller's.
template <class Bank>
void advance_rings(Bank& b, std::size_t s) {
  const std::size_t outputs = s / static_cast<std::size_t>(b.decimation);
  b.y_idx = (b.y_idx + s) % b.window;
  b.bd_idx = (b.bd_idx + outputs) % b.bd_n;
  b.f_idx = (b.f_idx + outputs) % b.f_n;
}

// p samples of silence (rows of zero bits) through a batch's kernels from its current state:
// filter(in, out, n) is the bandpass, feed(in, n, &ready) the bank's full-rate front end, and
// at_output() judges each decimated output. False when a bandpass output is not all zero bits
// or at_output() says no.
template <class Row, class Filter, class Feed, class AtOutput>
bool run_silence(std::size_t p, Filter&& filter, Feed&& feed, AtOutput&& at_output) {
  std::vector<Row> zin(std::min(p, kChunk)), zout(zin.size());
  for (std::size_t done = 0; done < p;) {
    const std::size_t n = std::min(zin.size(), p - done);
    filter(zin.data(), zout.data(), n);
    if (!zero_bits(zout.data(), n * sizeof(Row))) return false;
    for (std::size_t i = 0; i < n;) {
      bool ready = false;
      i += feed(zout.data() + i, n - i, &ready);
      if (ready && !at_output()) return false;
    }
    done += n;
  }
  return true;
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

  // Silence (as ReceiverFloatBatch's, below, with integers: no signed zeros, so the fixed point
  // is the reset state itself): P = lcm(period, decimation) codes of 0 from reset must give
  // outputs of 0, no overflow, Q_j = 0 and E = 0 at every decimated output with the detector's
  // gate closed there (threshold_q > 0 or min_norm_q > 0: the fixed batch calls every lane's
  // detector, which then changes nothing), and end with every state word 0 and the phases back
  // at reset. silence_step = P then, else 0.
  std::size_t silence_step = 0;
  void probe_silence(const PeakDetectorFixed& det) {
    silence_step = 0;
    reset();
    const std::size_t p = static_cast<std::size_t>(std::lcm(bank.period, bank.decimation));
    const auto codes = static_cast<std::size_t>(bank.codes);
    bool ok = p > 0 && (det.threshold_q() > 0 || det.min_norm_q() > 0) &&
              run_silence<Lanes>(
                  p, [&](const Lanes* in, Lanes* out, std::size_t n) { batch::bandpass_batch(bp, in, out, n); },
                  [&](const Lanes* in, std::size_t n, bool* ready) { return batch::bank_feed_batch(bank, in, n, ready); },
                  [&] { return zero_bits(bank.q, codes * sizeof(Lanes)) && zero_bits(&bank.energy, sizeof(Lanes)); });
    for (int l = 0; ok && l < kBatchLanes; ++l) {
      ok = bp_events[l].total() == 0 && lanes.mix_events[l].total() == 0 && lanes.chip_events[l].total() == 0 &&
           lanes.corr_events[l].total() == 0;
    }
    const auto& a = lanes.arrays;
    if (ok && bank.phase == 0 && bank.dec_phase == 0 && zero_bits(&bp.x1, sizeof bp.x1) &&
        zero_bits(&bp.x2, sizeof bp.x2) && zero_bits(bp.y1, sizeof bp.y1) && zero_bits(bp.y2, sizeof bp.y2) &&
        zero_bits(&bank.acc_re, sizeof(Lanes)) && zero_bits(&bank.acc_im, sizeof(Lanes)) &&
        zero_bits(&bank.energy, sizeof(Lanes)) && zero_rows(a.b_re) && zero_rows(a.b_im) && zero_rows(a.y2h) &&
        zero_rows(a.bd_re) && zero_rows(a.bd_im) && zero_rows(a.f_re) && zero_rows(a.f_im) && zero_rows(a.q)) {
      silence_step = p;
    }
    reset();
  }
};

ReceiverFixedBatch::ReceiverFixedBatch(const ReceiverDesign& design)
    : design_(design), frac_bits_(design.config.detector.frac_bits), score_bits_(design.config.correlator.score_bits) {
  vectorized_ = batch::batch_kernels_available() &&
                static_cast<int>(design.filter.sections.size()) <= batch::kBatchMaxSections;
  if (vectorized_) {
    k_ = std::make_unique<Kernels>(design_);
    k_->probe_silence(PeakDetectorFixed(design_.config.detector, design_.layout, design_.config.correlator));
  }
}

ReceiverFixedBatch::~ReceiverFixedBatch() = default;

std::size_t ReceiverFixedBatch::silence_step() const { return k_ ? k_->silence_step : 0; }

void ReceiverFixedBatch::run(std::span<const std::span<const std::int64_t>> streams,
                             std::vector<std::vector<EventFixed>>& events, std::vector<OverflowCounter>& overflows) {
  events.assign(streams.size(), {});
  skipped_ = 0;
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
  // The lanes' common leading codes of 0, skipped in multiples of silence_step (Kernels).
  const std::size_t start = common_silence(streams, k.silence_step, [](std::int64_t c) { return c == 0; });
  advance_rings(k.bank, start);
  skipped_ += start;
  run_chunks(streams, k.zeros.data(), chunk, finish, start);
}

// ---- float -----------------------------------------------------------------------------


// Silence: the samples of a batch before its first echo, when every lane's x = stream * gain is
// +0.0 there (its bits: an ideal link's silence), need not run. From reset, silence brings the
// kernels to a fixed point within P = lcm(period, decimation) samples: every bandpass output
// +0.0, no detector gate open (the float batch calls an idle lane's detector only at an open
// gate), every state word +0.0 but the mixer's history, which holds +-0.0 by the LO's signs, in
// phase with the LO. That is checked once per design, never assumed (Kernels::probe_silence:
// P samples from reset, then P more must end in the same state bit for bit, with the LO and
// decimation phases back at reset). Then any m >= 1 runs of P give that state (a ring of +0.0
// reads the same at any position), so run_lanes skips the largest multiple of P within the
// lanes' common leading silence: it sets the fixed point, advances the rings' positions as the
// samples would have, and starts the kernels there. Events, filtered samples (+0.0 in the
// silence) and the state are those of running every sample, bit for bit
// (tests/test_receiver_batch.cpp). A design whose silence has no such fixed point, a -0.0 input
// or a noisy stream skips nothing.
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

  std::size_t silence_step = 0;                   // P when silence reaches its fixed point (above), else 0
  std::vector<LanesF> silent_b_re, silent_b_im;  // the mixer's history there (-0.0 where lo < 0)

  // Whether every word of the state but the mixer's history (b_re, b_im) is +0.0 (all bits 0).
  bool state_zero() const {
    return zero_bits(bp.x1, sizeof bp.x1) && zero_bits(bp.x2, sizeof bp.x2) && zero_bits(bp.y1, sizeof bp.y1) &&
           zero_bits(bp.y2, sizeof bp.y2) && zero_bits(&bank.acc_re, sizeof(LanesF)) &&
           zero_bits(&bank.acc_im, sizeof(LanesF)) && zero_bits(&bank.energy, sizeof(LanesF)) &&
           zero_rows(arrays.y2h) && zero_rows(arrays.bd_re) && zero_rows(arrays.bd_im) && zero_rows(arrays.f_re) &&
           zero_rows(arrays.f_im) && zero_rows(arrays.q);
  }

  // p samples of +0.0 through the very kernels run_lanes uses; false when a bandpass output is
  // not +0.0 or a gate opens.
  bool run_zeros(std::size_t p, double threshold, double min_energy) {
    return run_silence<LanesF>(
        p, [&](const LanesF* in, LanesF* out, std::size_t n) { batch::bandpass_batch_float(bp, in, out, n); },
        [&](const LanesF* in, std::size_t n, bool* ready) { return batch::bank_feed_batch_float(bank, in, n, ready); },
        [&] { return batch::gate_batch_float(bank, threshold, min_energy) == 0; });
  }

  // Sets silence_step (see above): from reset, P zero samples, then P more must give the same
  // state (the mixer's history bit for bit, the rest +0.0) with quiet outputs and closed gates;
  // then back to reset.
  void probe_silence(double threshold, double min_energy) {
    silence_step = 0;
    reset();
    const std::size_t p = static_cast<std::size_t>(std::lcm(bank.period, bank.decimation));
    const auto same = [](const std::vector<LanesF>& a, const std::vector<LanesF>& b) {
      return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(LanesF)) == 0;
    };
    if (p > 0 && run_zeros(p, threshold, min_energy) && state_zero()) {
      silent_b_re = arrays.b_re;
      silent_b_im = arrays.b_im;
      if (run_zeros(p, threshold, min_energy) && state_zero() && bank.b_idx == 0 && bank.dec_phase == 0 &&
          same(arrays.b_re, silent_b_re) && same(arrays.b_im, silent_b_im)) {
        silence_step = p;
      }
    }
    reset();
  }

  // From reset, the state after s zero samples (a multiple of silence_step, or 0): the mixer's
  // history at its fixed point, the rings' positions advanced; every other word stays +0.0.
  void skip_silence(std::size_t s) {
    if (s == 0) return;
    std::copy(silent_b_re.begin(), silent_b_re.end(), arrays.b_re.begin());
    std::copy(silent_b_im.begin(), silent_b_im.end(), arrays.b_im.begin());
    advance_rings(bank, s);
  }
};

ReceiverFloatBatch::ReceiverFloatBatch(const ReceiverDesign& design) : design_(design) {
  vectorized_ = batch::batch_kernels_available() && !design.reference.codes.empty() &&
                static_cast<int>(design.filter.sections.size()) <= batch::kBatchMaxSections;
  if (vectorized_) {
    k_ = std::make_unique<Kernels>(design_);
    k_->probe_silence(design_.config.detector.threshold, design_.config.detector.min_energy);
  }
}

ReceiverFloatBatch::~ReceiverFloatBatch() = default;

std::size_t ReceiverFloatBatch::silence_step() const { return k_ ? k_->silence_step : 0; }

void ReceiverFloatBatch::run(std::span<const std::span<const double>> streams, double gain,
                             std::vector<std::vector<Event>>& events, std::vector<std::vector<double>>* filtered) {
  events.assign(streams.size(), {});
  skipped_ = 0;
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
  // The lanes' common leading silence (x = +0.0 exactly), skipped in multiples of silence_step.
  const std::size_t start = common_silence(
      streams, k.silence_step, [gain](double x) { return std::bit_cast<std::uint64_t>(x * gain) == 0; });
  k.skip_silence(start);
  skipped_ += start;
  run_chunks(streams, k.zeros.data(), chunk, finish, start);
}

void bandpass_float_streams(const SosFilter& filter, std::span<const std::span<const double>> streams,
                            std::vector<std::vector<double>>& out) {
  out.resize(streams.size());
  for (std::size_t s = 0; s < streams.size(); ++s) out[s].resize(streams[s].size());
  if (!batch::batch_kernels_available() || filter.sections.empty() ||
      static_cast<int>(filter.sections.size()) > batch::kBatchMaxSections) {
    for (std::size_t s = 0; s < streams.size(); ++s) BandpassFloat(filter).execute_block(streams[s], out[s]);
    return;
  }
  std::vector<LanesF> in(kChunk), res(kChunk);
  std::vector<double> zeros(kChunk), discard(kChunk);
  for (std::size_t s0 = 0; s0 < streams.size(); s0 += kBatchLanes) {
    const auto group = streams.subspan(s0, std::min<std::size_t>(kBatchLanes, streams.size() - s0));
    batch::FloatBandpassBatch bp = bandpass_batch_constants(filter.sections);  // every lane at reset
    const auto chunk = [&](std::size_t n0, std::size_t n, const double* const* src, const bool* open) {
      batch::interleave_batch_float(src, 1.0, in.data(), n);  // x * 1.0 == x, bit for bit
      batch::bandpass_batch_float(bp, in.data(), res.data(), n);
      double* dst[kBatchLanes];
      for (std::size_t l = 0; l < static_cast<std::size_t>(kBatchLanes); ++l) {
        dst[l] = l < group.size() && open[l] ? out[s0 + l].data() + n0 : discard.data();
      }
      batch::deinterleave_batch_float(res.data(), dst, n);
    };
    run_chunks(group, static_cast<const double*>(zeros.data()), chunk, [](std::size_t) {});
  }
}

}  // namespace ranging
