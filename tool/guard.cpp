#include "tool/guard.hpp"

#include <cmath>
#include <iostream>

namespace ranging::tool {

namespace {
// JSON has no infinity: an unbounded gain / an exact zero's attenuation is null.
nlohmann::ordered_json num(double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(); }
}  // namespace

void warn_if_out_of_spec(const std::string& cmd, const ReceiverConfig& cfg) {
  if (!cfg.allow_out_of_spec) return;
  const DesignGuard g = check_quantized_design(cfg);
  if (g.ok()) return;
  std::cerr << "ranging " << cmd << ": warning: " << guard_message(g, cfg.filter_order)
            << " (accepted: --allow-out-of-spec)\n";
}

nlohmann::ordered_json guard_json(const DesignGuard& g, int filter_order) {
  nlohmann::ordered_json j = {{"ok", g.ok()},
                              {"stable", g.stable},
                              {"within_spec", g.within_spec},
                              {"float_within_spec", g.float_within_spec},
                              {"tolerance_db", g.tolerance_db},
                              {"coef_bits", g.coef_bits},
                              {"coef_frac", g.coef_frac},
                              {"message", guard_message(g, filter_order)}};
  nlohmann::ordered_json sec = nlohmann::ordered_json::array();
  for (std::size_t k = 0; k < g.quantized_poles.size(); ++k) {
    const SectionPoles& p = g.quantized_poles[k];
    sec.push_back({{"float_radius", g.float_radius[k]},
                   {"quantized_radius", static_cast<double>(p.radius)},
                   {"complex_pair", p.complex_pair},
                   {"stable", p.stable},
                   {"l1_gain", num(g.l1_gain[k])}});
  }
  j["sections"] = sec;
  nlohmann::ordered_json edges = nlohmann::ordered_json::array();
  for (const auto& e : g.edges) {
    edges.push_back({{"name", e.name}, {"f", e.f}, {"float_db", num(e.float_db)}, {"quantized_db", num(e.quantized_db)}});
  }
  j["edges"] = edges;
  j["passband_worst"] = {{"float_db", num(g.passband.float_db)}, {"float_f", g.passband.float_f},
                         {"quantized_db", num(g.passband.quantized_db)}, {"quantized_f", g.passband.quantized_f}};
  j["stopband_worst"] = {{"float_db", num(g.stopband.float_db)}, {"float_f", g.stopband.float_f},
                         {"quantized_db", num(g.stopband.quantized_db)}, {"quantized_f", g.stopband.quantized_f}};
  return j;
}

}  // namespace ranging::tool
