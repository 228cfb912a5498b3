#pragma once
// Strict YAML reading shared by the receiver configuration (receiver.cpp) and the scenes
// (scene.cpp): every key must be known, every value of the right type and range, and every
// error names the file, line and field ("file:line: key: what").
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <initializer_list>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "model/base/error.hpp"

namespace ranging::yaml {

// Parses YAML text; a syntax error names origin and line.
inline YAML::Node load(const std::string& text, const std::string& origin) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw InputError(origin + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
}

[[noreturn]] inline void fail(const std::string& origin, const YAML::Node& node, const std::string& key,
                       const std::string& what) {
  std::ostringstream os;
  os << origin << ":" << node.Mark().line + 1 << ": " << key << ": " << what;
  throw InputError(os.str());
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
  template <class T>
  T scalar(const YAML::Node& v, const std::string& name) const {
    if (!v.IsScalar()) fail(origin_, v, name, "expected a scalar");
    T out{};
    try {
      out = v.as<T>();
    } catch (const YAML::Exception&) {
      fail(origin_, v, name, "'" + v.Scalar() + "' has the wrong type");
    }
    if constexpr (std::is_floating_point_v<T>) {
      if (!std::isfinite(out)) fail(origin_, v, name, "value is not finite");
    }
    return out;
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
    if (!get(k, out)) return false;
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
      const std::string k = kv.first.as<std::string>();
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
