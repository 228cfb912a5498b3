#pragma once
// The tools' side of the quantized-design guard (model/dsp/stability.hpp): the
// --allow-out-of-spec flag, the verdict on stderr when a study overrides it, and its JSON.
#include <nlohmann/json.hpp>

#include <string>

#include "model/dsp/receiver.hpp"
#include "model/dsp/stability.hpp"

namespace ranging::tool {

inline constexpr const char* kAllowOutOfSpecHelp =
    "accept a receiver whose quantized filter is unstable or out of spec (for a study; the "
    "guard's verdict goes to stderr)";

// If cfg.allow_out_of_spec and the guard fails: "ranging CMD: warning: <verdict>" on stderr.
void warn_if_out_of_spec(const std::string& cmd, const ReceiverConfig& cfg);

// {"ok", "stable", "within_spec", "tolerance_db", "message", "sections": [{float_radius,
// quantized_radius, stable}], "edges": [...], "passband_worst", "stopband_worst", "l1_gain"}.
nlohmann::ordered_json guard_json(const DesignGuard& g, int filter_order);

}  // namespace ranging::tool
