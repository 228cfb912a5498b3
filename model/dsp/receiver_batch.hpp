#pragma once
// ReceiverFixedBatch / ReceiverFloatBatch: the fixed and float receivers (receiver.hpp:
// bandpass, correlator bank, detector) on up to kLanes independent streams at once, one stream
// per SIMD lane ("SIMD across streams"). What follows is said of the fixed one; the float one
// is built the same way (below).
//
// Each stream's events and overflow counts are bit for bit what a fresh ReceiverFixed gives for
// that stream through execute_block and flush_raw (tests/test_receiver_batch.cpp). Streams may
// differ in length: the lanes run in lockstep to the longest; a lane that has ended is fed
// zeros whose results are discarded (its detector is flushed and its counters are read at its
// own last sample), so a batch of streams of similar length wastes little.
// A batch's common leading silence (codes of 0: an ideal link before the echo) is not run when
// the design's silence leaves the receiver at reset, which is checked once per design; the
// kernels start after it with the same results (receiver_batch.cpp, "Silence").
//
// Where the work is: the bandpass cascade and the bank's full-rate front end and decimated
// outputs run in receiver_batch_kernels_v4.cpp (AVX-512, 8 lanes of int64), and so does the
// interleaving of the lanes' inputs (8 x 8 transposes); the detector, a few operations per
// decimated output, runs per lane (the float batch calls a lane's detector only when the
// lanes' gate kernel finds its gate open or the detector holds a candidate). On a CPU without AVX-512, or a configuration
// the kernels do not cover (more than 8 bandpass sections), every stream runs the scalar
// ReceiverFixed instead: the same results, slower. vectorized() says which.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "model/dsp/receiver.hpp"

namespace ranging {

class ReceiverFixedBatch {
 public:
  static constexpr std::size_t kLanes = 8;

  explicit ReceiverFixedBatch(const ReceiverDesign& design);
  ~ReceiverFixedBatch();
  ReceiverFixedBatch(const ReceiverFixedBatch&) = delete;
  ReceiverFixedBatch& operator=(const ReceiverFixedBatch&) = delete;

  // Runs every stream from reset (ADC codes, signed input_bits; any count: kLanes at a time).
  // events[s] receives stream s's events (what ReceiverFixed::execute_block then flush_raw
  // give), overflows[s] its filter + bank saturations and wraps (input quantization excluded:
  // the codes are given). An out-of-range code throws InputError, as ReceiverFixed does.
  void run(std::span<const std::span<const std::int64_t>> streams, std::vector<std::vector<EventFixed>>& events,
           std::vector<OverflowCounter>& overflows);

  bool vectorized() const { return vectorized_; }
  Event to_float(const EventFixed& e) const { return e.to_float(frac_bits_, score_bits_); }
  // Leading silence (receiver_batch.cpp): the step P in which a batch's common leading codes of
  // 0 are skipped (0: not for this design, or not vectorized), and the samples per lane the
  // last run() skipped, summed over its batches.
  std::size_t silence_step() const;
  std::size_t silence_skipped() const { return skipped_; }

 private:
  struct Kernels;  // the SIMD state (receiver_batch.cpp)
  ReceiverDesign design_;
  int frac_bits_, score_bits_;
  bool vectorized_ = false;
  std::size_t skipped_ = 0;
  std::unique_ptr<Kernels> k_;
  void run_lanes(std::span<const std::span<const std::int64_t>> streams, std::vector<EventFixed>* events,
                 OverflowCounter* overflows);
};

// ReceiverFloatBatch: ReceiverFloat on up to kLanes streams at once, the same way (IEEE double
// per lane in ReceiverFloat's order of operations, so each stream's events and filtered
// samples are ReceiverFloat's bit for bit; the scalar receiver per stream where the kernels
// cannot run). A batch's common leading silence (inputs of +0.0, an ideal link's samples before
// the echo) is not run when the design's silence has a checked fixed point: the kernels start
// from that state instead, with the same results (receiver_batch.cpp, "Silence").
class ReceiverFloatBatch {
 public:
  static constexpr std::size_t kLanes = 8;

  explicit ReceiverFloatBatch(const ReceiverDesign& design);
  ~ReceiverFloatBatch();
  ReceiverFloatBatch(const ReceiverFloatBatch&) = delete;
  ReceiverFloatBatch& operator=(const ReceiverFloatBatch&) = delete;

  // Runs every stream from reset on x = stream[i] * gain (full-scale units; the product is
  // formed here, as a caller scaling a copy would). events[s] receives what
  // ReceiverFloat::execute_block then flush give; filtered, when not null, every bandpass
  // output of every stream (execute_block's `filtered`).
  void run(std::span<const std::span<const double>> streams, double gain, std::vector<std::vector<Event>>& events,
           std::vector<std::vector<double>>* filtered = nullptr);

  bool vectorized() const { return vectorized_; }
  // Leading silence (receiver_batch.cpp): the step P in which a batch's common leading +0.0
  // inputs are skipped (0: this design's silence has no fixed point, or not vectorized), and
  // the samples per lane the last run() skipped, summed over its batches.
  std::size_t silence_step() const;
  std::size_t silence_skipped() const { return skipped_; }

 private:
  struct Kernels;
  ReceiverDesign design_;
  bool vectorized_ = false;
  std::size_t skipped_ = 0;
  std::unique_ptr<Kernels> k_;
  void run_lanes(std::span<const std::span<const double>> streams, double gain, std::vector<Event>* events,
                 std::vector<double>* filtered);
};

// BandpassFloat (a fresh one per stream) on any number of streams, kLanes at a time on the
// SIMD lanes (the float batch's bandpass kernel): out[s] = what BandpassFloat(filter)
// .execute_block gives for streams[s], bit for bit (tests/test_receiver_batch.cpp); the
// scalar filter per stream where the kernels cannot run. out is resized to the streams.
void bandpass_float_streams(const SosFilter& filter, std::span<const std::span<const double>> streams,
                            std::vector<std::vector<double>>& out);

}  // namespace ranging
