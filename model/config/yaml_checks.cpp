#include "model/config/yaml_checks.hpp"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <sstream>
#include <vector>

#include "model/base/error.hpp"

namespace ranging::yaml {
namespace {

[[noreturn]] void fail_line(const std::string& origin, std::size_t line, const std::string& what) {
  throw InputError(origin + ":" + std::to_string(line) + ": " + what);
}

std::string hex(unsigned char c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", c);
  return buf;
}

// Saturating add: node counts of alias bombs overflow any integer.
std::size_t sat_add(std::size_t a, std::size_t b) { return a > kMaxNodes * 4 - b ? kMaxNodes * 4 : a + b; }

class StructureCheck : public YAML::EventHandler {
 public:
  explicit StructureCheck(const std::string& origin) : origin_(origin) {}

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& m, YAML::anchor_t a) override { leaf(m, a, nullptr); }
  void OnAlias(const YAML::Mark& m, YAML::anchor_t a) override {
    const std::size_t n = a < anchor_size_.size() ? anchor_size_[a] : 1;
    before_node(m, nullptr);
    add(m, n);
  }
  void OnScalar(const YAML::Mark& m, const std::string&, YAML::anchor_t a, const std::string& v) override {
    leaf(m, a, &v);
  }
  void OnSequenceStart(const YAML::Mark& m, const std::string&, YAML::anchor_t a, YAML::EmitterStyle::value) override {
    open(m, a, false);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark& m, const std::string&, YAML::anchor_t a, YAML::EmitterStyle::value) override {
    open(m, a, true);
  }
  void OnMapEnd() override { close(); }

 private:
  struct Frame {
    bool map = false;
    YAML::anchor_t anchor = YAML::NullAnchor;
    std::size_t nodes = 1;        // this node and everything below it, aliases expanded
    bool expect_key = true;       // maps alternate key, value
    std::map<std::string, std::size_t> keys;  // key -> line of its first occurrence
  };

  // Called for every node before it is counted: a key of a mapping is checked for duplicates.
  void before_node(const YAML::Mark& m, const std::string* scalar) {
    if (stack_.empty()) return;
    Frame& f = stack_.back();
    if (!f.map) return;
    const bool is_key = f.expect_key;
    f.expect_key = !f.expect_key;
    if (!is_key || scalar == nullptr) return;
    const std::size_t line = static_cast<std::size_t>(m.line) + 1;
    const auto [it, fresh] = f.keys.emplace(*scalar, line);
    if (!fresh) {
      fail_line(origin_, line, key_path(*scalar) + ": duplicate key (first at " + origin_ + ":" +
                                   std::to_string(it->second) + "); each key may appear once in a mapping");
    }
  }
  std::string key_path(const std::string& k) const {
    std::string p;
    for (std::size_t i = 0; i + 1 < stack_.size(); ++i) {
      if (stack_[i].map && !current_key_[i].empty()) p += current_key_[i] + ".";
    }
    return p + k;
  }
  void leaf(const YAML::Mark& m, YAML::anchor_t a, const std::string* scalar) {
    before_node(m, scalar);
    remember_key(scalar);
    if (a != YAML::NullAnchor) set_anchor(a, 1);
    add(m, 1);
  }
  // Remembers the key under which the next value sits (for the dotted path of messages).
  void remember_key(const std::string* scalar) {
    if (stack_.empty()) return;
    const Frame& f = stack_.back();
    if (f.map && !f.expect_key) current_key_.back() = scalar ? *scalar : std::string("?");
  }
  void add(const YAML::Mark& m, std::size_t n) {
    if (stack_.empty()) {
      total_ = sat_add(total_, n);
    } else {
      stack_.back().nodes = sat_add(stack_.back().nodes, n);
      if (stack_.back().nodes > kMaxNodes) too_many(m);
    }
    if (total_ > kMaxNodes) too_many(m);
  }
  [[noreturn]] void too_many(const YAML::Mark& m) {
    fail_line(origin_, static_cast<std::size_t>(m.line) + 1,
              "the document expands to more than " + std::to_string(kMaxNodes) +
                  " nodes (aliases counted at every use; an alias bomb?); valid: at most " +
                  std::to_string(kMaxNodes));
  }
  void open(const YAML::Mark& m, YAML::anchor_t a, bool map) {
    before_node(m, nullptr);
    remember_key(nullptr);
    if (stack_.size() >= kMaxDepth) {
      fail_line(origin_, static_cast<std::size_t>(m.line) + 1,
                "nesting deeper than " + std::to_string(kMaxDepth) + " levels; valid: at most " +
                    std::to_string(kMaxDepth));
    }
    Frame f;
    f.map = map;
    f.anchor = a;
    stack_.push_back(std::move(f));
    current_key_.emplace_back();
    marks_.push_back(m);
  }
  void close() {
    Frame f = std::move(stack_.back());
    const YAML::Mark m = marks_.back();
    stack_.pop_back();
    current_key_.pop_back();
    marks_.pop_back();
    if (f.anchor != YAML::NullAnchor) set_anchor(f.anchor, f.nodes);
    add(m, f.nodes);
  }
  void set_anchor(YAML::anchor_t a, std::size_t n) {
    if (a >= anchor_size_.size()) anchor_size_.resize(a + 1, 1);
    anchor_size_[a] = n;
  }

  const std::string& origin_;
  std::vector<Frame> stack_;
  std::vector<std::string> current_key_;
  std::vector<YAML::Mark> marks_;
  std::vector<std::size_t> anchor_size_;
  std::size_t total_ = 0;
};

}  // namespace

std::string strip_bom(const std::string& text) {
  return text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? text.substr(3) : text;
}

void check_yaml_text(const std::string& text, const std::string& origin) {
  const auto* s = reinterpret_cast<const unsigned char*>(text.data());
  const std::size_t n = text.size();
  std::size_t line = 1;
  std::size_t i = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
  auto bad = [&](std::size_t at, const std::string& what) {
    fail_line(origin, line, what + " at byte " + std::to_string(at) + "; valid: UTF-8 text");
  };
  while (i < n) {
    const unsigned char c = s[i];
    if (c < 0x80) {
      if (c == '\n') {
        ++line;
      } else if (c < 0x20 && c != '\t' && c != '\r') {
        bad(i, "control character " + hex(c));
      } else if (c == 0x7F) {
        bad(i, "control character 0x7F");
      }
      ++i;
      continue;
    }
    std::size_t len = 1;  // every branch below sets it or throws (bad)
    std::uint32_t cp = 0;
    if (c >= 0xC2 && c <= 0xDF) {
      len = 2, cp = c & 0x1Fu;
    } else if (c >= 0xE0 && c <= 0xEF) {
      len = 3, cp = c & 0x0Fu;
    } else if (c >= 0xF0 && c <= 0xF4) {
      len = 4, cp = c & 0x07u;
    } else {
      bad(i, "byte " + hex(c) + " is not UTF-8");
    }
    if (i + len > n) bad(i, "truncated UTF-8 sequence (byte " + hex(c) + ")");
    for (std::size_t k = 1; k < len; ++k) {
      if ((s[i + k] & 0xC0u) != 0x80u) bad(i, "byte " + hex(c) + " starts a broken UTF-8 sequence (Latin-1 text?)");
      cp = (cp << 6) | (s[i + k] & 0x3Fu);
    }
    if ((len == 3 && cp < 0x800) || (len == 4 && cp < 0x10000)) bad(i, "overlong UTF-8 sequence");
    if (cp >= 0xD800 && cp <= 0xDFFF) bad(i, "UTF-8 encoded surrogate");
    if (cp > 0x10FFFF) bad(i, "UTF-8 sequence above U+10FFFF");
    i += len;
  }
}

void check_yaml_structure(const std::string& text, const std::string& origin) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  StructureCheck check(origin);
  if (!parser.HandleNextDocument(check)) return;
  // A second document would be ignored by YAML::Load: refuse it.
  struct Ignore : YAML::EventHandler {
    YAML::Mark first{};
    bool any = false;
    void OnDocumentStart(const YAML::Mark& m) override {
      if (!any) first = m;
      any = true;
    }
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
    void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
    void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
    void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
    void OnSequenceEnd() override {}
    void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
    void OnMapEnd() override {}
  } rest;
  if (parser.HandleNextDocument(rest)) {
    fail_line(origin, static_cast<std::size_t>(rest.first.line) + 1,
              "a second YAML document; valid: one document per file");
  }
}

}  // namespace ranging::yaml
