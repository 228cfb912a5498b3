#pragma once
// The receiver configuration file (configs/*.yaml, docs/configuration.md): parse, load and
// write a ReceiverConfig. Unknown keys, wrong types and out-of-range values are errors naming
// the file, line and key; the values are checked by validate() (model/dsp/receiver.hpp).
#include <string>

#include "model/dsp/receiver.hpp"

namespace ranging {

// YAML (docs/configuration.md). Unknown keys, wrong types and out-of-range values are
// errors naming the file, line and key; so is a quantized filter that is unstable or out of
// spec (model/dsp/stability.hpp) unless allow_out_of_spec (set in the returned config too).
ReceiverConfig load_receiver_config(const std::string& path, bool allow_out_of_spec = false);
ReceiverConfig parse_receiver_config(const std::string& yaml_text, const std::string& origin,
                                     bool allow_out_of_spec = false);
std::string receiver_config_yaml(const ReceiverConfig& cfg);

}  // namespace ranging
