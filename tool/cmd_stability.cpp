// `ranging stability --config FILE`: numerical stability report of a receiver configuration
// (issue 12): the guard's verdict on the quantized filter (model/dsp/stability.hpp) with its
// exact pole radii and edge attenuations, overflow headroom per filter node and per correlator
// bank node (model/dsp/correlator_headroom.hpp) under its worst-case input, zero-input limit cycles per rounding / overflow mode and excitation,
// their amplitude against the data and coefficient word lengths, and the filter-structure
// comparison (SOS vs direct form, per filter type: minimal coefficient bits, pole radius vs
// bits). The report never refuses the design: it is where an out-of-spec one is studied.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "model/base/error.hpp"
#include "model/config/receiver_config.hpp"
#include "model/dsp/bandpass_filter.hpp"
#include "model/dsp/correlator_headroom.hpp"
#include "model/dsp/receiver.hpp"
#include "model/dsp/limit_cycle_search.hpp"
#include "model/dsp/stability.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/guard.hpp"
#include "tool/options.hpp"

namespace ranging::tool {
namespace {

using json = nlohmann::ordered_json;

const Rounding kRoundings[] = {Rounding::Truncate, Rounding::RoundHalfUp, Rounding::Convergent};
const Overflow kOverflows[] = {Overflow::Wrap, Overflow::Saturate};
const Excitation kExcitations[] = {Excitation::Impulse, Excitation::Step, Excitation::WorstCase, Excitation::Random};
constexpr int kExcitationLength = 2000;

std::string rounding_str(Rounding r) {
  return r == Rounding::Truncate ? "truncate" : r == Rounding::RoundHalfUp ? "round-half-up" : "convergent";
}
std::string overflow_str(Overflow o) { return o == Overflow::Wrap ? "wrap" : "saturate"; }

// The configuration's words with another data / coefficient width (same integer bits),
// input and accumulator adjusted so that the configuration stays realizable.
BandpassFixedConfig with_widths(BandpassFixedConfig c, const SosFilter& f, int data_bits, int coef_bits) {
  const int data_int = c.data_bits - c.data_frac, coef_int = c.coef_bits - c.coef_frac;
  c.data_bits = data_bits;
  c.data_frac = data_bits - data_int;
  c.coef_bits = coef_bits;
  c.coef_frac = coef_bits - coef_int;
  c.input_bits = std::min(c.input_bits, c.data_frac + 1);
  c.acc_bits = 64;
  c.acc_bits = std::max(bandpass_min_acc_bits(c, f), 2);
  return c;
}

// Worst over the excitations of the steady-state amplitude (LSB) and its period.
struct Worst {
  double amplitude = 0;
  int period = 0;
  std::string excitation;
};
Worst worst_limit_cycle(const SosFilter& f, const BandpassFixedConfig& c) {
  BandpassFixed probe(f, c);
  const SosFilter q = probe.quantized_filter();
  Worst w;
  for (Excitation e : kExcitations) {
    const LimitCycle lc = measure_limit_cycle(f, c, excitation_codes(e, q, c.input_bits, kExcitationLength));
    if (lc.amplitude_lsb > w.amplitude || w.excitation.empty()) {
      w.amplitude = lc.amplitude_lsb;
      w.period = lc.period;
      w.excitation = excitation_name(e);
    }
  }
  return w;
}

}  // namespace

int cmd_stability(const Args& args) {
  cli::Parser p = command_parser("stability");
  add_config_options(p, {.allow_out_of_spec = false});
  add_output_options(p, {.json = true});
  p.flag("--quick", "skip the width sweeps and the structure comparison");
  if (!p.parse(args)) return 0;
  // The report shows an out-of-spec design rather than refusing it, whether the file or a
  // --set made it so; the overrides apply to --config, else to the built-in default.
  const Overrides overrides = parse_overrides(p.values("--set"));
  ReceiverConfig cfg;  // the built-in default
  if (p.has("--config")) {
    cfg = load_receiver_config(*p.get("--config"), overrides, true);
  } else if (!overrides.empty()) {
    cfg = parse_receiver_config("", "(built-in default configuration)", overrides, true);
  }
  cfg.allow_out_of_spec = true;
  BandpassSpec spec = cfg.filter;
  spec.fs = cfg.fs;
  const SosFilter filter = cfg.filter_order > 0 ? design_bandpass(spec, cfg.filter_type, cfg.filter_order)
                                                : design_bandpass(spec, cfg.filter_type);
  const DesignGuard guard = check_quantized_design(cfg);
  const BandpassFixedConfig& bc = cfg.bandpass;
  json j;
  j["config"] = cfg.name;
  j["guard"] = guard_json(guard, cfg.filter_order);

  // Headroom: bandpass_headroom's bounds, and each node driven by its own worst-case input
  // (the full-scale sign sequence of its impulse response, both polarities) in the model.
  json head = json::array();
  {
    const BandpassHeadroom h = bandpass_headroom(bc, filter);
    BandpassFixed probe(filter, bc);
    const SosFilter q = probe.quantized_filter();
    const double lsb = std::ldexp(1.0, -bc.data_frac);
    for (std::size_t k = 0; k < q.sections.size(); ++k) {
      SosFilter to_k = q;
      to_k.sections.resize(k + 1);
      double peak = 0;
      std::uint64_t overflows = 0;
      for (int pol : {1, -1}) {
        std::vector<std::int64_t> x = excitation_codes(Excitation::WorstCase, to_k, bc.input_bits, 4096);
        if (pol < 0) {
          for (auto& v : x) v = -v - 1;  // the other polarity within the word's range
        }
        BandpassFixed f(filter, bc);
        for (std::int64_t v : x) {
          f.execute_raw(v);
          peak = std::max(peak, std::abs(static_cast<double>(f.section_outputs()[k])) * lsb);
        }
        overflows += f.overflow_events().total();
      }
      head.push_back({{"node", "section " + std::to_string(k + 1) + " output"},
                      {"l1_gain", h.signal_gain[k]},
                      {"peak_bound", h.peak_bound[k]},
                      {"measured_peak", peak},
                      {"limit", h.limit},
                      {"headroom_bits", std::log2(h.limit / h.peak_bound[k])},
                      {"overflows", overflows}});
    }
  }
  j["headroom"] = head;

  // The correlator bank, node by node (model/dsp/correlator_headroom.hpp): each node's bound,
  // and the node driven by its own full-scale worst-case sign sequences in the model.
  json bank_head = json::array();
  {
    const ReceiverDesign d = design_receiver(cfg);
    for (const BankNodeHeadroom& h : correlator_headroom(d.reference, cfg.correlator)) {
      json n{{"node", h.name},       {"bits", h.bits},
             {"claim", h.exact ? "exact" : "saturate (counted)"},
             {"bound", h.bound},     {"measured_peak", h.measured},
             {"limit", h.limit},     {"headroom_bits", h.headroom_bits},
             {"overflows", h.overflows}};
      if (h.worst_code >= 0) n["worst_code"] = h.worst_code + 1;
      bank_head.push_back(n);
    }
  }
  j["bank_headroom"] = bank_head;

  // Limit cycles at the configuration's words, every mode and excitation.
  json lcs = json::array();
  for (Rounding r : kRoundings) {
    for (Overflow o : kOverflows) {
      BandpassFixedConfig c = bc;
      c.rounding = r;
      c.overflow = o;
      BandpassFixed probe(filter, c);
      const SosFilter q = probe.quantized_filter();
      for (Excitation e : kExcitations) {
        const LimitCycle lc = measure_limit_cycle(filter, c, excitation_codes(e, q, c.input_bits, kExcitationLength));
        lcs.push_back({{"rounding", rounding_str(r)}, {"overflow", overflow_str(o)}, {"excitation", excitation_name(e)},
                       {"amplitude_lsb", lc.amplitude_lsb}, {"period", lc.period}, {"overflows", lc.overflows}});
      }
    }
  }
  j["limit_cycles"] = lcs;

  // Overflow oscillations: each section alone as the all-pole recursion 1/A_k (unscaled, so a
  // full-scale input overflows its output word), wrap vs saturate, the configuration's words.
  json osc = json::array();
  for (std::size_t k = 0; k < filter.sections.size(); ++k) {
    SosFilter one = filter;
    one.sections = {Biquad{1, 0, 0, filter.sections[k].a1, filter.sections[k].a2}};
    for (Overflow o : kOverflows) {
      BandpassFixedConfig c = bc;
      c.overflow = o;
      c.acc_bits = std::max(c.acc_bits, bandpass_min_acc_bits(c, one));
      BandpassFixed probe(one, c);
      double amp = 0;
      int period = 0;
      for (Excitation e : kExcitations) {
        const LimitCycle lc = measure_limit_cycle(one, c, excitation_codes(e, probe.quantized_filter(), c.input_bits, kExcitationLength));
        if (lc.amplitude_lsb >= amp) {
          amp = lc.amplitude_lsb;
          period = lc.period;
        }
      }
      osc.push_back({{"section", k + 1}, {"overflow", overflow_str(o)}, {"amplitude_lsb", amp}, {"period", period},
                     {"full_scale_lsb", static_cast<double>(fx_max_raw(probe.data_format()))}});
    }
  }
  j["overflow_oscillations"] = osc;

  // Exhaustive search: every initial state of each quantized section's zero-input recursion, at
  // small data widths (model/dsp/limit_cycle_search.hpp), each rounding and overflow mode.
  json exh = json::array();
  const QuantizedSos qs = quantize_sos(filter, bc.coef_bits, bc.coef_frac, "bandpass_fixed");
  for (std::size_t k = 0; k < qs.sections.size(); ++k) {
    for (int w : {6, 8}) {
      for (Rounding r : kRoundings) {
        for (Overflow o : kOverflows) {
          const LimitCycleSearch ls =
              exhaustive_limit_cycles(qs.sections[k][3], qs.sections[k][4], qs.frac, FixedFormat{w, 0, true, r, o});
          exh.push_back({{"section", k + 1}, {"data_bits", w}, {"rounding", rounding_str(r)}, {"overflow", overflow_str(o)},
                         {"states", ls.states}, {"nonzero_cycles", ls.nonzero_cycles},
                         {"states_into_nonzero", ls.states_into_nonzero}, {"max_amplitude_lsb", ls.max_amplitude_lsb},
                         {"period", ls.period_of_max}, {"full_scale_lsb", (1 << (w - 1))}});
        }
      }
    }
  }
  j["exhaustive_limit_cycles"] = exh;

  if (!p.has("--quick")) {
    // Amplitude (worst over the excitations) against the data width (coefficients as
    // configured) and against the coefficient width (data as configured), saturating.
    json vs_data = json::array(), vs_coef = json::array();
    for (Rounding r : kRoundings) {
      for (int db = 8; db <= 24; ++db) {
        BandpassFixedConfig c = with_widths(bc, filter, db, bc.coef_bits);
        c.rounding = r;
        const Worst w = worst_limit_cycle(filter, c);
        vs_data.push_back({{"rounding", rounding_str(r)}, {"data_bits", db}, {"amplitude_lsb", w.amplitude},
                           {"period", w.period}, {"excitation", w.excitation}});
      }
      for (int cb = 6; cb <= 18; ++cb) {
        BandpassFixedConfig c;
        try {
          c = with_widths(bc, filter, bc.data_bits, cb);
          c.rounding = r;
          const Worst w = worst_limit_cycle(filter, c);
          vs_coef.push_back({{"rounding", rounding_str(r)}, {"coef_bits", cb}, {"amplitude_lsb", w.amplitude},
                             {"period", w.period}, {"excitation", w.excitation},
                             {"guard_ok", check_quantized_design(filter, quantize_sos(filter, c.coef_bits, c.coef_frac, ""),
                                                                 spec, c.coef_bits).ok()}});
        } catch (const InputError&) {
          // a coefficient does not fit this width with the configured integer bits
        }
      }
    }
    j["limit_cycle_vs_data_bits"] = vs_data;
    j["limit_cycle_vs_coef_bits"] = vs_coef;

    json st = json::array();
    for (FilterType t : {FilterType::Butterworth, FilterType::Chebyshev1, FilterType::Elliptic}) {
      const SosFilter f = design_bandpass(spec, t);
      for (FilterStructure s : {FilterStructure::Sos, FilterStructure::Direct}) {
        json pts = json::array();
        for (int b = 6; b <= 44; b += 2) {
          const StructurePoint pt = evaluate_structure(f, spec, s, b);
          pts.push_back({{"bits", b}, {"max_radius", pt.max_radius}, {"stable", pt.stable}, {"within_spec", pt.within_spec}});
        }
        st.push_back({{"type", filter_type_name(t)}, {"order", f.order}, {"structure", filter_structure_name(s)},
                      {"min_bits", minimum_coefficient_bits(f, spec, s)},
                      {"min_bits_every_wider", minimum_coefficient_bits(f, spec, s, 60, true)}, {"points", pts}});
      }
    }
    j["structures"] = st;
  }

  if (p.has("--json")) {
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::ostringstream os;
  char buf[256];
  os << "stability report: configuration '" << cfg.name << "', " << filter_type_name(cfg.filter_type) << " order "
     << filter.order << ", coefficients " << bc.coef_bits << " bits (" << bc.coef_frac << " fraction), data "
     << bc.data_bits << " bits (" << bc.data_frac << " fraction)\n\n";
  os << "guard: " << (guard.ok() ? "stable and within spec" : "FAILS: " + guard_message(guard, cfg.filter_order))
     << " (tolerance " << guard.tolerance_db << " dB)\n";
  os << "  section  float radius  quantized radius  L1 gain (input -> output)\n";
  for (std::size_t k = 0; k < guard.quantized_poles.size(); ++k) {
    std::snprintf(buf, sizeof buf, "  %7zu  %12.9f  %16.9f  %10.4f%s\n", k + 1, guard.float_radius[k],
                  static_cast<double>(guard.quantized_poles[k].radius), guard.l1_gain[k],
                  guard.quantized_poles[k].stable ? "" : "  UNSTABLE");
    os << buf;
  }
  for (const auto& e : guard.edges) {
    std::snprintf(buf, sizeof buf, "  %s %9.0f Hz  float %9.4f dB  quantized %9.4f dB\n", e.name.c_str(), e.f, e.float_db,
                  e.quantized_db);
    os << buf;
  }
  os << "\noverflow headroom per node (worst-case input, both polarities):\n"
        "  node               L1 gain  bound    measured  limit   headroom  overflows\n";
  for (const auto& h : head) {
    std::snprintf(buf, sizeof buf, "  %-17s %8.4f %8.4f %8.4f %8.4f %7.3f b %6llu\n",
                  h["node"].get<std::string>().c_str(), h["l1_gain"].get<double>(), h["peak_bound"].get<double>(),
                  h["measured_peak"].get<double>(), h["limit"].get<double>(), h["headroom_bits"].get<double>(),
                  static_cast<unsigned long long>(h["overflows"].get<std::uint64_t>()));
    os << buf;
  }
  os << "\ncorrelator bank headroom per node (full-scale worst-case sign sequences, re and im, both\n"
        "polarities, every code; values in each node's own LSB; a saturating node's bound is the\n"
        "value its input demands):\n"
        "  node                        bits  claim               bound      measured   limit      headroom  overflows\n";
  for (const auto& h : bank_head) {
    std::snprintf(buf, sizeof buf, "  %-27s %4d  %-18s %10.4g %10.4g %10.4g %7.3f b %6llu\n",
                  h["node"].get<std::string>().c_str(), h["bits"].get<int>(), h["claim"].get<std::string>().c_str(),
                  h["bound"].get<double>(), h["measured_peak"].get<double>(), h["limit"].get<double>(),
                  h["headroom_bits"].get<double>(), static_cast<unsigned long long>(h["overflows"].get<std::uint64_t>()));
    os << buf;
  }
  os << "\nzero-input limit cycles after each excitation (amplitude in data LSB, period in samples;\n"
        "period 1 at amplitude 0 = at rest, 0 = not periodic within the window):\n";
  for (const auto& l : lcs) {
    std::snprintf(buf, sizeof buf, "  %-14s %-9s %-11s %8.0f LSB  period %5d  overflows %llu\n",
                  l["rounding"].get<std::string>().c_str(), l["overflow"].get<std::string>().c_str(),
                  l["excitation"].get<std::string>().c_str(), l["amplitude_lsb"].get<double>(), l["period"].get<int>(),
                  static_cast<unsigned long long>(l["overflows"].get<std::uint64_t>()));
    os << buf;
  }
  os << "\noverflow oscillations: each section alone as 1/A_k, full-scale excitations, then zeros\n"
        "(worst amplitude in LSB of a full scale of " << osc[0]["full_scale_lsb"].get<double>() << "):\n";
  for (const auto& o : osc) {
    std::snprintf(buf, sizeof buf, "  section %d  %-9s %8.0f LSB  period %5d\n", o["section"].get<int>(),
                  o["overflow"].get<std::string>().c_str(), o["amplitude_lsb"].get<double>(), o["period"].get<int>());
    os << buf;
  }
  os << "\nexhaustive zero-input search, every initial state of each section (coefficients as\n"
        "configured, data words of 6 and 8 bits; largest cycle in LSB / its period):\n"
        "  section bits  truncate/wrap  truncate/sat  half-up/wrap  half-up/sat  convergent/wrap  convergent/sat\n";
  for (std::size_t i = 0; i + 5 < exh.size(); i += 6) {
    std::snprintf(buf, sizeof buf, "  %7d %4d", exh[i]["section"].get<int>(), exh[i]["data_bits"].get<int>());
    os << buf;
    for (std::size_t m = 0; m < 6; ++m) {
      std::snprintf(buf, sizeof buf, " %9lld/%-5d", static_cast<long long>(exh[i + m]["max_amplitude_lsb"].get<std::int64_t>()),
                    exh[i + m]["period"].get<int>());
      os << buf;
    }
    os << "\n";
  }
  if (j.contains("structures")) {
    os << "\nlimit-cycle amplitude (LSB, worst excitation) vs data bits, saturating:\n  bits ";
    for (Rounding r : kRoundings) os << " " << rounding_str(r);
    os << "\n";
    for (int db = 8; db <= 24; ++db) {
      std::snprintf(buf, sizeof buf, "  %4d", db);
      os << buf;
      for (const auto& v : j["limit_cycle_vs_data_bits"]) {
        if (v["data_bits"].get<int>() == db) {
          std::snprintf(buf, sizeof buf, " %8.0f", v["amplitude_lsb"].get<double>());
          os << buf;
        }
      }
      os << "\n";
    }
    os << "\nfilter structures: smallest coefficient bits that keep every pole inside the unit circle\n"
          "and meet the spec (tolerance " << guard.tolerance_db << " dB):\n";
    for (const auto& s : j["structures"]) {
      std::snprintf(buf, sizeof buf, "  %-7s order %2d  %-6s  %3d bits (every width from %d bits on)\n",
                    s["type"].get<std::string>().c_str(), s["order"].get<int>(), s["structure"].get<std::string>().c_str(),
                    s["min_bits"].get<int>(), s["min_bits_every_wider"].get<int>());
      os << buf;
    }
  }
  std::cout << os.str();
  return 0;
}

}  // namespace ranging::tool
