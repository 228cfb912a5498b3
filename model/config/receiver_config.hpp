#pragma once
// The receiver configuration file (configs/*.yaml, docs/configuration.md): parse, load and
// write a ReceiverConfig. Unknown keys, wrong types and out-of-range values are errors naming
// the file, line and key; the values are checked by validate() (model/dsp/receiver.hpp).
#include <string>

#include "model/config/overrides.hpp"
#include "model/dsp/receiver.hpp"

namespace ranging {

// YAML (docs/configuration.md). Unknown keys, wrong types and out-of-range values are
// errors naming the file, line and key.
// overrides (--set KEY=VALUE, model/config/overrides.hpp) are applied to the document before
// it is parsed; their errors name the override. allow_out_of_spec is carried in the returned
// config: design_receiver refuses a quantized filter that is unstable or out of spec
// (model/dsp/stability.hpp) unless it is set.
ReceiverConfig load_receiver_config(const std::string& path, const Overrides& overrides = {},
                                    bool allow_out_of_spec = false);
ReceiverConfig parse_receiver_config(const std::string& yaml_text, const std::string& origin,
                                     const Overrides& overrides = {}, bool allow_out_of_spec = false);
// An empty document with overrides: the built-in default configuration, overridden.
ReceiverConfig default_receiver_config(const Overrides& overrides);
std::string receiver_config_yaml(const ReceiverConfig& cfg);

// "path:line: message" when message starts with a key ("system.max_range_m: ...") that the
// configuration file at path sets, else "path: message": for the checks made after loading
// (the system design of generate and the bitstream, model/hw/hw_system.hpp).
std::string locate_in_config(const std::string& path, const std::string& message);

}  // namespace ranging
