#pragma once
// Strict YAML reading shared by the receiver configuration (receiver.cpp) and the scenes
// (scene.cpp): every key must be known, every value of the right type and range, and every
// error names the file, line and field ("file:line: key: what").
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "model/base/error.hpp"
#include "model/config/yaml_checks.hpp"

namespace ranging::yaml {

// Parses YAML text; a syntax error names origin and line. The text must be UTF-8 (a BOM and
// CRLF line endings are accepted) and hold one document without duplicate keys, deep nesting
// or alias bombs (yaml_checks.hpp).
inline YAML::Node load(const std::string& raw, const std::string& origin) {
  check_yaml_text(raw, origin);
  const std::string text = strip_bom(raw);
  try {
    check_yaml_structure(text, origin);
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(origin + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw InputError(origin + ":" + std::to_string(e.mark.line + 1) + ": YAML error: " + e.msg);
  }
}

[[noreturn]] inline void fail(const std::string& origin, const YAML::Node& node, const std::string& key,
                       const std::string& what) {
  std::ostringstream os;
  os << origin << ":" << node.Mark().line + 1 << ": " << key << ": " << what;
  throw InputError(os.str());
}

// "origin:line: message" when the message starts with a dotted key ("signal.fs: ...") found
// in root (the checks made after parsing, e.g. validate(), name keys but not lines), else
// "origin: message".
inline std::string locate(const YAML::Node& root, const std::string& origin, const std::string& message) {
  const auto colon = message.find(':');
  if (colon != std::string::npos && colon > 0 && root && root.IsMap()) {
    const std::string key = message.substr(0, colon);
    if (key.find_first_of(" /()") == std::string::npos) {
      YAML::Node n;
      n.reset(root);  // (Node::operator= would assign into the tree)
      std::size_t at = 0;
      bool found = true;
      while (found && at <= key.size()) {
        const auto dot = std::min(key.find('.', at), key.size());
        const std::string part = key.substr(at, dot - at);
        const YAML::Node& cn = n;
        if (!cn.IsMap() || part.empty() || !cn[part]) {
          found = false;
        } else {
          n.reset(cn[part]);
        }
        at = dot + 1;
      }
      if (found && n.Mark().line >= 0) return origin + ":" + std::to_string(n.Mark().line + 1) + ": " + message;
    }
  }
  return origin + ": " + message;
}

// A strict mapping reader: get() marks a key as known; finish() refuses the unknown ones.
class Reader {
 public:
  Reader(const YAML::Node& node, std::string origin, std::string path)
      : node_(node), origin_(std::move(origin)), path_(std::move(path)) {
    if (!node_.IsMap()) fail(origin_, node_, path_.empty() ? "(top)" : path_, "expected a mapping");
  }
  std::string key(const std::string& k) const { return path_.empty() ? k : path_ + "." + k; }
  bool has(const std::string& k) const { return static_cast<bool>(node_[k]); }
  YAML::Node node(const std::string& k) const { return node_[k] ? node_[k] : node_; }

  template <class T>
  bool get(const std::string& k, T& out) {
    seen_.insert(k);
    const YAML::Node v = node_[k];
    if (!v) return false;
    out = scalar<T>(v, key(k));
    return true;
  }
  // `valid` (e.g. "; valid range is [1, 64]") is appended to the type and finiteness errors.
  template <class T>
  T scalar(const YAML::Node& v, const std::string& name, const std::string& valid = "") const {
    if (!v.IsScalar()) fail(origin_, v, name, "expected a scalar (" + type_name<T>() + ")" + valid);
    T out{};
    try {
      out = v.as<T>();
    } catch (const YAML::Exception&) {
      fail(origin_, v, name, "'" + v.Scalar() + "' is not " + type_name<T>() + valid);
    }
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(out)) fail(origin_, v, name, "'" + v.Scalar() + "' is not a finite number" + valid);
    }
    return out;
  }
  template <class T>
  static std::string type_name() {
    if constexpr (std::is_same_v<T, bool>) {
      return "true or false";
    } else if constexpr (std::is_integral_v<T>) {
      return "an integer (in the range of its type)";
    } else if constexpr (std::is_floating_point_v<T>) {
      return "a finite number";
    } else {
      return "a string";
    }
  }
  template <class T>
  bool get_opt(const std::string& k, std::optional<T>& out) {
    T v{};
    if (!get(k, v)) return false;
    out = v;
    return true;
  }
  // A number in [lo, hi]; the error names file, line and field.
  template <class T>
  bool get_range(const std::string& k, T& out, double lo, double hi) {
    seen_.insert(k);
    const YAML::Node v = node_[k];
    if (!v) return false;
    std::ostringstream valid;
    valid << "; valid range is [" << lo << ", " << hi << "]";
    out = scalar<T>(v, key(k), valid.str());
    check(k, static_cast<double>(out), lo, hi);
    return true;
  }
  void check(const std::string& k, double v, double lo, double hi) const {
    if (v < lo || v > hi) {
      std::ostringstream os;
      os << v << " is out of range; valid range is [" << lo << ", " << hi << "]";
      fail(origin_, node(k), key(k), os.str());
    }
  }
  template <class T>
  bool get_list(const std::string& k, std::vector<T>& out) {
    seen_.insert(k);
    const YAML::Node v = node_[k];
    if (!v) return false;
    if (!v.IsSequence()) fail(origin_, v, key(k), "expected a list");
    out.clear();
    for (std::size_t i = 0; i < v.size(); ++i) out.push_back(scalar<T>(v[i], key(k) + "[" + std::to_string(i) + "]"));
    return true;
  }
  // An integer, or "auto" (stored as -1).
  bool get_auto(const std::string& k, int& out) {
    const YAML::Node v = node_[k];
    if (v && v.IsScalar() && v.Scalar() == "auto") {
      seen_.insert(k);
      out = -1;
      return true;
    }
    return get(k, out);
  }
  YAML::Node child(const std::string& k) {
    seen_.insert(k);
    return node_[k];
  }
  void finish() const {
    for (const auto& kv : node_) {
      if (!kv.first.IsScalar()) fail(origin_, kv.first, path_.empty() ? "(top)" : path_, "a key must be a plain name");
      const std::string k = kv.first.Scalar();
      if (!seen_.count(k)) fail(origin_, kv.first, key(k), "unknown key");
    }
  }
  [[noreturn]] void error(const std::string& k, const std::string& what) const { fail(origin_, node(k), key(k), what); }
  const std::string& origin() const { return origin_; }

 private:
  YAML::Node node_;
  std::string origin_, path_;
  std::set<std::string> seen_;
};

// Reads the mapping `name` of `top` with body(Reader&) if present (a bare "name:" means all
// defaults); returns whether it was there.
template <class F>
bool section(Reader& top, const std::string& name, F&& body) {
  YAML::Node n = top.child(name);
  if (!n) return false;
  if (n.IsNull()) n = YAML::Node(YAML::NodeType::Map);  // "transducers:" alone: all defaults
  Reader r(n, top.origin(), top.key(name));
  body(r);
  r.finish();
  return true;
}

inline void one_of(Reader& r, const std::string& k, const std::string& v, std::initializer_list<const char*> valid) {
  std::string list;
  for (const char* s : valid) {
    if (v == s) return;
    list += (list.empty() ? "" : ", ") + std::string(s);
  }
  r.error(k, "'" + v + "' is not valid; valid: " + list);
}

}  // namespace ranging::yaml
