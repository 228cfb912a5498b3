#include "model/sim/channel.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include "model/base/error.hpp"
#include "model/dsp/filter_design.hpp"
#include "model/sim/fft.hpp"
#include "model/sim/front_end.hpp"

namespace ranging {

void validate(const ChannelParams& p) {
  require_in_range("speed_of_sound", p.speed_of_sound, 100.0, 10000.0);
  require_in_range("distance_m", p.distance_m, 0.001, 1000.0);
  require_in_range("gain", p.gain, 0.0, 1e9);
  require_in_range("noise_rms", p.noise_rms, 0.0, 1e9);
}

// Taps h[i] = sinc(m - mu) * kaiser(m - mu), m = i - (N/2 - 1), so that
// y[k] = sum_i h[i] z[k - I - m] interpolates z at time k - (I + mu).
std::vector<double> fractional_delay_taps(double mu) {
  constexpr double beta = 10.0;  // ~-100 dB sidelobes; passband flat far beyond 0.1*fs
  constexpr double half = kDelayTaps / 2.0;
  std::vector<double> h(kDelayTaps);
  for (int i = 0; i < kDelayTaps; ++i) {
    const double x = static_cast<double>(i - (kDelayTaps / 2 - 1)) - mu;  // in (-N/2, N/2]
    const double r = x / half;
    const double w = kaiser_window(r, beta);
    const double s = x == 0.0 ? 1.0 : std::sin(std::numbers::pi * x) / (std::numbers::pi * x);
    h[static_cast<std::size_t>(i)] = s * w;
  }
  return h;
}

std::vector<double> propagate(std::span<const double> excitation, const ChannelParams& p, double fs,
                              std::size_t n_out) {
  validate(p);
  require_in_range("fs", fs, 1.0, 1e10);
  require_in_range("n_out", static_cast<double>(n_out), 0.0, 1e8);
  for (std::size_t i = 0; i < excitation.size(); ++i) {
    require_finite("excitation[" + std::to_string(i) + "]", excitation[i]);
  }
  // Name which transducer is wrong: the shared validator does not know.
  for (const auto& [name, tp] : {std::pair{"tx", &p.tx}, std::pair{"rx", &p.rx}}) {
    try {
      validate(*tp, fs);
    } catch (const InputError& e) {
      throw InputError(std::string(name) + ": " + e.what());
    }
  }
  Transducer tx(p.tx, fs), rx(p.rx, fs);

  const double delay = p.distance_m / p.speed_of_sound * fs;  // samples, <= 1e7 * 1e10 bounded by checks
  const double whole = std::floor(delay);
  const double mu = delay - whole;
  const auto taps = fractional_delay_taps(mu);
  constexpr std::ptrdiff_t m_lo = -(kDelayTaps / 2 - 1);

  // Transducer output z: only the part that can reach an output sample is needed.
  std::vector<double> y(n_out, 0.0);
  if (whole < static_cast<double>(n_out) + kDelayTaps) {
    const auto I = static_cast<std::ptrdiff_t>(whole);
    const auto z_len = static_cast<std::ptrdiff_t>(n_out) - I - m_lo;  // z[j], j < z_len
    std::vector<double> z(static_cast<std::size_t>(std::max<std::ptrdiff_t>(z_len, 0)));
    for (std::size_t j = 0; j < z.size(); ++j) {
      const double x = j < excitation.size() ? excitation[j] : 0.0;
      z[j] = rx.execute(tx.execute(x));
    }
    const double g = p.gain * kReferenceDistance / p.distance_m;
    // y[k] = g sum_i taps[i] z[k - I - m_lo - i] = g (z * taps)[k - I - m_lo]: the linear
    // convolution (model/sim/fft.hpp, the direct sum at 64 taps), z[j] = 0 outside [0, z_len).
    const std::vector<double> c = convolve(z, taps);
    for (std::size_t k = 0; k < n_out; ++k) {
      const std::ptrdiff_t m = static_cast<std::ptrdiff_t>(k) - I - m_lo;
      if (m >= 0 && m < static_cast<std::ptrdiff_t>(c.size())) y[k] = g * c[static_cast<std::size_t>(m)];
    }
  }
  add_white_noise(y, p.noise_rms, p.seed);
  return y;
}

}  // namespace ranging
