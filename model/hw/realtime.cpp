#include "model/hw/realtime.hpp"

#include <algorithm>
#include <cstdio>

#include "model/base/error.hpp"
#include "model/hw/hw_params.hpp"

namespace ranging {

namespace {

long long digits16(long long bits) { return (bits + 15) / 16; }

const HwModuleParams& module(const std::vector<HwModuleParams>& mods, const std::string& name) {
  for (const auto& m : mods) {
    if (m.module == name) return m;
  }
  throw InputError("no " + name + " parameters");
}

}  // namespace

double RealTimeBudget::needed_clocks_per_sample() const {
  const double d = static_cast<double>(std::max(1LL, decimation));
  return std::max({static_cast<double>(bandpass_clocks_per_sample), static_cast<double>(bank_back_end_clocks) / d,
                   static_cast<double>(combiner_clocks) / d, static_cast<double>(detector_clocks) / d});
}

std::string RealTimeBudget::summary() const {
  char buf[320];
  std::snprintf(buf, sizeof buf,
                "%d clocks per sample available, %.2f needed (bandpass %lld, bank back end %lld, combiner %lld and "
                "detector %lld clocks per group of %lld = %lld x %lld)",
                static_cast<int>(clocks_per_sample), needed_clocks_per_sample(), bandpass_clocks_per_sample,
                bank_back_end_clocks, combiner_clocks, detector_clocks, group_clocks, decimation, clocks_per_sample);
  std::string s = std::string(real_time ? "real time: " : "NOT REAL TIME: ") + buf;
  for (const auto& l : limits) s += "; " + l;
  return s;
}

RealTimeBudget realtime_budget(const ReceiverDesign& d) {
  const auto mods = hardware_parameters(d);
  const auto& bank = module(mods, "correlator_bank");
  const auto& det = module(mods, "peak_detector");
  RealTimeBudget r;
  r.clocks_per_sample = d.config.sample_cycles();
  r.decimation = bank.value("DECIM");
  r.group_clocks = r.decimation * r.clocks_per_sample;
  const long long taps = bank.value("TAPS"), codes = bank.value("CODES");
  const long long corr = digits16(bank.value("CORR_W"));
  r.bank_back_end_clocks = 2 * taps * digits16(bank.value("DEC_W")) * digits16(bank.value("TAP_W")) + 1 +
                           codes * (2 * corr * corr + digits16(2 * bank.value("CORR_W")) * digits16(bank.value("WEIGHT_W")));
  const long long chips = bank.value("CHIPS");
  r.combiner_clocks = (chips + 2) * codes;
  const long long na = digits16(det.value("WEIGHTED_W"));
  const long long nw = std::max(1LL, static_cast<long long>(det.value("ENERGY_W") - det.value("ENERGY_SHIFT")));
  const long long nb = digits16(nw);
  const long long event = 6 + 2 * det.value("FRAC_W") + 1 + 2 * (det.value("SCORE_W") + 2) + 1;
  r.detector_clocks = codes + 1 + 2 * (2 * na * nb + 3) + 1 + std::max(codes + 5, event);
  if (r.clocks_per_sample < r.bandpass_clocks_per_sample) {
    r.limits.push_back("bandpass and bank front end need 6 clocks per sample, hardware.clock_hz / signal.fs gives " +
                       std::to_string(r.clocks_per_sample));
  }
  if (r.bank_back_end_clocks > r.group_clocks) {
    r.limits.push_back("correlator back end needs " + std::to_string(r.bank_back_end_clocks) + " > " +
                       std::to_string(r.group_clocks) + " clocks per group (TAPS " + std::to_string(taps) +
                       ", DECIM " + std::to_string(r.decimation) + ")");
  }
  if (r.combiner_clocks > r.group_clocks) {
    r.limits.push_back("correlator combiner needs " + std::to_string(r.combiner_clocks) + " > " +
                       std::to_string(r.group_clocks) + " clocks per group ((CHIPS " + std::to_string(chips) +
                       " + 2) x CODES " + std::to_string(codes) + ", DECIM " + std::to_string(r.decimation) + ")");
  }
  if (r.detector_clocks > r.group_clocks) {
    r.limits.push_back("peak detector needs up to " + std::to_string(r.detector_clocks) + " > " +
                       std::to_string(r.group_clocks) + " clocks per group");
  }
  r.real_time = r.limits.empty();
  return r;
}

}  // namespace ranging
