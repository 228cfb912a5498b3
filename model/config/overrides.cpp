#include "model/config/overrides.hpp"

#include <sstream>

#include "model/config/yaml_reader.hpp"

namespace ranging {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split_key(const Override& o) {
  std::vector<std::string> parts;
  std::string cur;
  for (char c : o.key) {
    if (c == '.') {
      parts.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  parts.push_back(cur);
  for (const auto& p : parts) {
    if (p.empty()) throw InputError("--set " + override_text(o) + ": the key has an empty component; write a.b.c");
  }
  return parts;
}

// A copy of n without source marks (so the parser's errors on it are attributed to --set).
YAML::Node unmarked(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Scalar: return YAML::Node(n.Scalar());
    case YAML::NodeType::Sequence: {
      YAML::Node out(YAML::NodeType::Sequence);
      for (const auto& e : n) out.push_back(unmarked(e));
      return out;
    }
    case YAML::NodeType::Map: {
      YAML::Node out(YAML::NodeType::Map);
      for (const auto& kv : n) out[kv.first.Scalar()] = unmarked(kv.second);
      return out;
    }
    default: return YAML::Node(YAML::NodeType::Null);
  }
}

YAML::Node value_node(const Override& o) {
  const std::string v = trim(o.value);
  if (!v.empty() && (v.front() == '[' || v.front() == '{')) {
    YAML::Node n;
    try {
      n = YAML::Load(v);
    } catch (const YAML::Exception& e) {
      throw InputError("--set " + override_text(o) + ": the value is not valid YAML: " + e.msg);
    }
    return unmarked(n);
  }
  if (!v.empty() && (v.front() == '"' || v.front() == '\'')) {
    try {
      return unmarked(YAML::Load(v));
    } catch (const YAML::Exception& e) {
      throw InputError("--set " + override_text(o) + ": the value is not valid YAML: " + e.msg);
    }
  }
  return YAML::Node(v);
}

}  // namespace

Override parse_override(const std::string& s) {
  const auto eq = s.find('=');
  if (eq == std::string::npos) throw InputError("--set '" + s + "': expected KEY=VALUE (e.g. correlator_fixed.chip_bits=18)");
  Override o{trim(s.substr(0, eq)), trim(s.substr(eq + 1))};
  if (o.key.empty()) throw InputError("--set '" + s + "': the key is empty; expected KEY=VALUE");
  if (o.value.empty()) throw InputError("--set '" + s + "': the value is empty; expected KEY=VALUE");
  (void)split_key(o);
  return o;
}

Overrides parse_overrides(const std::vector<std::string>& v) {
  Overrides out;
  for (const auto& s : v) out.push_back(parse_override(s));
  return out;
}

std::string override_text(const Override& o) { return o.key + "=" + o.value; }

void apply_overrides(YAML::Node& root, const Overrides& overrides, const std::string& origin) {
  if (overrides.empty()) return;
  if (!root || root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) throw InputError(origin + ": the document is not a mapping; --set needs one");
  for (const auto& o : overrides) {
    const auto parts = split_key(o);
    YAML::Node node = root;
    std::string path;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      if (!path.empty()) path.push_back('.');
      path.append(parts[i]);
      YAML::Node child = node[parts[i]];
      if (!child || child.IsNull()) {
        node[parts[i]] = YAML::Node(YAML::NodeType::Map);
        child = node[parts[i]];
      } else if (!child.IsMap()) {
        throw InputError("--set " + override_text(o) + ": '" + path + "' is not a mapping in " + origin);
      }
      node.reset(child);
    }
    node[parts.back()] = value_node(o);
  }
}

Overrides overrides_under(const Overrides& overrides, const std::string& prefix) {
  Overrides out;
  for (const auto& o : overrides) {
    if (o.key.rfind(prefix + ".", 0) == 0) out.push_back({o.key.substr(prefix.size() + 1), o.value});
  }
  return out;
}

Overrides overrides_not_under(const Overrides& overrides, const std::string& prefix) {
  Overrides out;
  for (const auto& o : overrides) {
    if (o.key.rfind(prefix + ".", 0) != 0) out.push_back(o);
  }
  return out;
}

std::string override_error(const std::string& message, const std::string& origin, const Overrides& overrides) {
  if (overrides.empty() || message.rfind("--set", 0) == 0) return message;
  const std::string unmarked_prefix = origin + ":0: ";
  if (message.rfind(unmarked_prefix, 0) == 0) {
    const std::string rest = message.substr(unmarked_prefix.size());  // "key: what"
    const std::string key = rest.substr(0, rest.find(": "));
    // The override that made this node: the same key, or a key above it (a list, a mapping).
    const Override* best = nullptr;
    for (const auto& o : overrides) {
      const bool match = key == o.key || key.rfind(o.key + ".", 0) == 0 || key.rfind(o.key + "[", 0) == 0 ||
                         o.key.rfind(key + ".", 0) == 0;
      if (match && (best == nullptr || o.key.size() >= best->key.size())) best = &o;
    }
    if (best) return "--set " + override_text(*best) + ": " + rest;
    return "--set: " + rest;
  }
  // A check after parsing (validate()) that names an overridden key: "origin: key: what".
  const std::string body = message.rfind(origin + ": ", 0) == 0 ? message.substr(origin.size() + 2) : message;
  for (auto it = overrides.rbegin(); it != overrides.rend(); ++it) {
    if (body.rfind(it->key + ":", 0) == 0 || body.rfind(it->key + " ", 0) == 0) {
      return "--set " + override_text(*it) + ": " + body + " (in " + origin + ")";
    }
  }
  std::string list;
  for (const auto& o : overrides) {
    if (!list.empty()) list.push_back(' ');
    list.append("--set ").append(override_text(o));
  }
  return message + " (with " + list + ")";
}

std::string emit_yaml(const YAML::Node& root) {
  YAML::Emitter e;
  e << root;
  return std::string(e.c_str()) + "\n";
}

}  // namespace ranging
