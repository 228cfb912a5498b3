#pragma once
// `--set KEY=VALUE` overrides of a YAML document (receiver configuration or scene).
//
// A key is a dotted path of mapping keys ("correlator_fixed.chip_bits", "noise.noise_v");
// missing intermediate mappings are created. A value is a YAML scalar ("18", "ellip") or a
// flow sequence/mapping ("[0.1, 0.5]"). Overrides are applied to the document before the
// normal strict parser runs, so they are validated exactly like the file: an unknown key, a
// wrong type or a value out of range is the parser's own error, reported with the override
// as its origin ("--set correlator_fixed.chip_bits=99: correlator_fixed.chip_bits: 99 is out
// of range; valid range is [...]"). Nodes created by an override carry no source mark, which
// is how their errors are told from the file's (yaml::fail prints line 0 for them).
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

namespace ranging {

struct Override {
  std::string key;    // dotted path
  std::string value;  // YAML text of the value
};
using Overrides = std::vector<Override>;

// "KEY=VALUE" -> Override; a missing '=' or an empty key or value is an InputError naming --set.
Override parse_override(const std::string& key_eq_value);
Overrides parse_overrides(const std::vector<std::string>& key_eq_values);
std::string override_text(const Override& o);  // "KEY=VALUE"

// Applies the overrides in order (the last of equal keys wins). root may be null (an empty
// document): it becomes a mapping. A path through a non-mapping is an InputError naming --set.
void apply_overrides(YAML::Node& root, const Overrides& overrides, const std::string& origin);

// Overrides whose key starts with prefix + "." , with the prefix removed (the rest keep their key).
Overrides overrides_under(const Overrides& overrides, const std::string& prefix);
Overrides overrides_not_under(const Overrides& overrides, const std::string& prefix);

// Turns an error of the parser of an overridden document into one naming the override:
// "origin:0: key: what" (a node the override created) becomes "--set KEY=VALUE: key: what";
// another error gets the overrides in effect appended. Messages already naming --set pass.
std::string override_error(const std::string& message, const std::string& origin, const Overrides& overrides);

// Runs parse() and rewrites its InputError with override_error (no overrides: unchanged).
template <class F>
auto with_override_errors(const Overrides& overrides, const std::string& origin, F&& parse) -> decltype(parse());

// The document as YAML text (block style), for the effective configuration/scene files.
std::string emit_yaml(const YAML::Node& root);

}  // namespace ranging

#include "model/base/error.hpp"

template <class F>
auto ranging::with_override_errors(const Overrides& overrides, const std::string& origin, F&& parse)
    -> decltype(parse()) {
  if (overrides.empty()) return parse();
  try {
    return parse();
  } catch (const InputError& e) {
    throw InputError(override_error(e.what(), origin, overrides));
  }
}
