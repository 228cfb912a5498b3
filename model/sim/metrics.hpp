#pragma once
// The paper's figures of merit and system equations, as free functions:
// correlation (eq. 9), distinguishability (eq. 12), received energy (Table 4), received
// duration T_d (section 2.2), required number of codes (eq. 3), maximum measurement rate
// (eq. 4) and the vertical blade-tip distance from two slant measurements (eq. 1).
#include <cstddef>
#include <span>

namespace ranging {

// Eq. 9 (and 8): Pearson correlation coefficient of two equal-length signals.
// InputError if the lengths differ or are 0; returns 0 if either has zero variance.
double pearson(std::span<const double> a, std::span<const double> b);

// Eq. 12: u = rho_max - rho_submax over the correlations of one received signal with
// every reference of a family; best_code (1-based) is the argmax = the decoded code.
// Ties go to the lowest index. InputError unless rhos has >= 2 finite values.
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

// Eq. 3: eta >= L/(T*c), the smallest integer number of codes. Ratios within 1e-9
// (relative) of an integer count as that integer, so rounding never demands an extra code.
int eta_required(double max_distance_m, double period_s, double c);

// Eq. 4: v_max = min(1/(1.5*T_d), eta*c/L) in Hz.
double vmax(double td_max_s, int eta, double c, double max_distance_m);

// Eq. 1 with the erratum (NOTES.md): the altitude onto side s of the triangle with sides
// h_m, h_n, s: h = 2*sqrt(p(p-h_m)(p-h_n)(p-s))/s, p = (h_m + h_n + s)/2 (Heron's formula,
// evaluated in Kahan's cancellation-free form). InputError if the sides do not form a
// triangle (a degenerate one gives 0) or are not positive.
double heron_vertical_distance(double h_m, double h_n, double s);

}  // namespace ranging
