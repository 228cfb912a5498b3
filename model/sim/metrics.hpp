#pragma once
// The paper's figures of merit and system equations, as free functions:
// correlation (eq. 9) and the matched filter over lags (section 3.3.2), distinguishability
// (eqs. 10 and 12), received energy (Table 4), received duration T_d (section 2.2), required
// number of codes (eq. 3), maximum measurement rate (eq. 4) and the vertical blade-tip
// distance from two slant measurements (eq. 1).
#include <cstddef>
#include <map>
#include <memory>
#include <algorithm>
#include <span>
#include <vector>

#include "model/base/aligned.hpp"

namespace ranging {

// Eq. 9 (and 8): Pearson correlation coefficient of two equal-length signals.
// InputError if the lengths differ or are 0; returns 0 if either has zero variance.
double pearson(std::span<const double> a, std::span<const double> b);

// The paper's decoder is a matched filter (section 3.3.2): the filtered received signal is
// cross-correlated with each reference, so each reference takes its best Pearson coefficient
// over time shifts. For a reference t of N samples and a signal x:
//   rho(k) = pearson(x[k .. k+N), t)              (eq. 9 at lag k)
//   rho    = max over k in [lo, hi] of rho(k)     (lags whose segment leaves x are not searched)
// The search window [lo, hi] is the caller's: the scene simulator and `decode` search +-L chips
// (L = code length) around the detected arrival (docs/signal-model.md).
struct LagRho {
  double rho = 0;  // the largest rho(k) over the window
  long lag = 0;    // its k (first one on ties): x index of the best segment's first sample
};
// Direct O(N (hi - lo)) form, the definition itself. InputError if t has < 2 samples or no lag
// of [lo, hi] keeps the segment inside x.
LagRho pearson_over_lags(std::span<const double> x, std::span<const double> t, long lo, long hi);

// The same search for a bank of references of one length at once, by FFT cross-correlation
// (FFTW, double precision, on correlation_fft_size(window) points, model/sim/fft.hpp; agrees with
// pearson_over_lags to ~1e-12, tested). Segment sums of x
// come from prefix sums of x minus the window's mean. A segment whose variance is below 1e-24
// of the window's largest gives rho 0 there (as pearson() does for zero variance).
// Not thread-safe per object (it owns FFTW buffers); plans are made once per transform size.
// max_lags > 0: every search of at most max_lags lags uses the transform size of max_lags lags
// (a window cut short at the signal's edge is zero-padded to it), so a stream's bursts need one
// FFTW plan, not one more per edge window (planning an estimate costs 2-6 ms per new size);
// rho is the same to a few ulps as on the window's own size. The plans: plan_correlation
// (model/sim/fft.hpp), measured ones from the project's wisdom where it applies.
class PearsonBank {
 public:
  // InputError if templates is empty, their lengths differ, or are < 2.
  explicit PearsonBank(std::vector<std::vector<double>> templates, std::size_t max_lags = 0);
  ~PearsonBank();
  PearsonBank(const PearsonBank&) = delete;
  PearsonBank& operator=(const PearsonBank&) = delete;
  std::size_t length() const { return n_; }
  std::size_t size() const { return t_.size(); }
  // One LagRho per template. InputError as pearson_over_lags.
  std::vector<LagRho> search(std::span<const double> x, long lo, long hi);
  // The lags are screened by a multiply before rho is divided out (the same result bit for bit);
  // off: every lag's rho is computed (the reference the tests compare the screening with).
  void set_screening(bool on) { screen_ = on; }
  // Makes the transform plans of a max_lags search now (else the first search makes them).
  void prepare();

 private:
  struct Plan;
  Plan& plan(std::size_t nfft);
  static std::size_t transform_size(std::size_t window);  // of a window of `window` samples
  std::size_t n_ = 0;
  std::size_t max_lags_ = 0;
  bool screen_ = true;
  std::vector<std::vector<double>> t_;  // centred templates
  std::vector<double> tnorm_;           // sqrt(sum tc^2)
  std::map<std::size_t, std::unique_ptr<Plan>> plans_;
  AlignedVector<double> s1_, s2_, var_, inv_den_, bm_;  // search()'s per-window scratch
  std::vector<std::size_t> idx_;
};

// Eq. 10 for one received signal: u = rho(code sent) - max over the other codes j of rho_j,
// rho_j the matched-filter coefficients (1-based sent). u < 0 exactly when the Pearson decoder
// (argmax) picks another code; u = 0 when another code ties. InputError unless rhos has >= 2
// finite values and 1 <= sent <= rhos.size().
double u_for_sent(std::span<const double> rhos, int sent);

// Eq. 12 as the decoder sees it (no knowledge of the code sent): rho_max - rho_submax over the
// correlations of one received signal with every reference of a family; best_code (1-based) is
// the argmax = the decoded code, and u >= 0 is the decoder's margin (equal to eq. 10's u when
// the decode is right). Ties go to the lowest index. InputError unless rhos has >= 2 finite values.
struct Distinguishability {
  int best_code;
  double rho_max;
  double rho_submax;
  double u;
};
Distinguishability distinguishability(std::span<const double> rhos);

// Table 4 "Energy": sum of squares of the received signal.
double energy(std::span<const double> x);

// Section 2.2 (Figure 7): b = max |x|, a = b/10; T_d runs from the first sample with
// |x| > a to the last sample with |x| > a; seconds = (last - first)/fs.
// InputError if x is empty or all zero (no signal, no duration), or fs <= 0.
struct Duration {
  std::size_t first, last;
  double seconds;
};
Duration duration_td(std::span<const double> x, double fs);

// Section 2.2 on a stream, until the signal really ends. b = max |x| over the burst window
// [p0, p1) (at sample pk); the threshold is a = max(b/10, 4.5 sigma), sigma the noise floor
// (the stream's robust rms, median|x|/0.6745, over up to 2000 samples before lo; 0 when fewer
// than 100 are there), so Gaussian noise alone crosses it with probability ~7e-6 per sample.
// From pk outwards, the signal ends at the first run of `guard` consecutive samples with
// |x| <= a: last = the last sample above a before that run after pk, first = the first one
// before the run before pk (the paper's "subsequent sampling points all below the threshold",
// where a noise spike far after the end is not the signal; dips inside a burst, at phase
// flips, are shorter than the guard of one or two chips).
//   clipped       no such run fits between pk and lo or hi (the end of the stream or the
//                 next burst): the search range may have cut T_d;
//   noise_limited the noise floor, not b/10, set a (T_d is then shorter than at high SNR;
//                 T_d = 0 if even the peak is below it).
// InputError if fs <= 0, the ranges are empty or outside x, or x is all zero over [p0, p1).
struct StreamDuration {
  std::size_t first = 0, last = 0;
  double seconds = 0;
  double threshold = 0, noise_rms = 0;
  bool clipped = false, noise_limited = false;
  bool ended_forward = false;  // the forward scan found `guard` quiet samples before hi (hi did not cut it):
                               // then any larger hi gives the same result (streaming decode relies on it)
};
// The k-th smallest of m[0, n) (k < n; values not NaN; m is reordered): the value
// std::nth_element leaves at m[k] (duration_td_stream's noise median). For n >= 512 two ranks
// of a sample of 128 (selected, not sorted) bracket it, one branchless pass counts the values
// below the bracket and keeps those inside (about a fifth) in buf (n entries), and nth_element
// runs on those only; a bracket that misses the rank falls back to nth_element on all of m.
double kth_smallest(double* m, std::size_t n, std::size_t k, double* buf);

StreamDuration duration_td_stream(std::span<const double> x, std::size_t lo, std::size_t hi, std::size_t p0,
                                  std::size_t p1, std::size_t guard, double fs);

// Spearman's rank correlation of two equal-length samples: the Pearson coefficient of their
// ranks, tied values taking the mean of their ranks. InputError if the lengths differ or are
// < 2; NaN if either sample is constant (no ranking).
double spearman(std::span<const double> a, std::span<const double> b);

// Clipping seen in a recorded stream (decode: a capture carries no ADC flags): the samples that
// lie in runs of at least min_run consecutive samples equal to the stream's maximum or to its
// minimum (flat tops). An unclipped 200 kHz burst sampled at >= 1 MS/s repeats its extreme
// value on consecutive samples only if its amplitude is a few LSB; a clipped one holds it.
// 0 for an all-zero stream.
struct FlatTops {
  std::size_t samples = 0;   // samples in such runs
  std::size_t runs = 0;
  double high = 0, low = 0;  // the stream's maximum and minimum
};
FlatTops flat_top_clipping(std::span<const double> x, std::size_t min_run = 3);

// The same count over a stream read in blocks (decode streams its capture): pass 1 feeds every
// block to levels(), pass 2 feeds them again to runs(); result() then equals
// flat_top_clipping() of the whole stream.
class FlatTopScan {
 public:
  explicit FlatTopScan(std::size_t min_run = 3) : min_run_(std::max<std::size_t>(min_run, 1)) {}
  void levels(std::span<const double> x);
  // levels() of a stream scanned in consecutive parts, each on a scan of its own: this scan's
  // levels followed by `later`'s part, as if its blocks had come after this scan's (the same
  // values, signed zeros included: each level is the first of its value in block order).
  void merge_levels(const FlatTopScan& later);
  void runs(std::span<const double> x);
  FlatTops result() const;

 private:
  std::size_t min_run_;
  bool any_ = false;
  FlatTops t_;
  std::size_t run_high_ = 0, run_low_ = 0;
};

// Eq. 3: eta * c * T > L, the smallest integer number of codes for which a burst from distance
// L arrives before the next send of its own code (at equality d = L aliases to 0). Ratios
// L/(T*c) within 1e-9 (relative) of an integer n count as n, and demand n + 1.
int eta_required(double max_distance_m, double period_s, double c);

// Eq. 4: v_max = min(1/(1.5*T_d), eta*c/L) in Hz.
double vmax(double td_max_s, int eta, double c, double max_distance_m);

// Eq. 1 with the erratum (NOTES.md): the altitude onto side s of the triangle with sides
// h_m, h_n, s: h = 2*sqrt(p(p-h_m)(p-h_n)(p-s))/s, p = (h_m + h_n + s)/2 (Heron's formula,
// evaluated in Kahan's cancellation-free form). InputError if the sides do not form a
// triangle (a degenerate one gives 0) or are not positive.
double heron_vertical_distance(double h_m, double h_n, double s);

}  // namespace ranging
