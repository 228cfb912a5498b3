#pragma once
// JSON text exactly as nlohmann::json's dump(2) writes it, for outputs with many elements that
// would otherwise build a json object (a std::map and a node per member) per element: decode's
// detections, 50 000 in a 100 M-sample capture, about 2 us each through nlohmann objects.
//
// JsonObjectText: one object's members, written as they are added. The caller adds them in
// nlohmann's order (its object is a std::map: keys in increasing byte order; std::logic_error
// otherwise, so the text can never differ from dump()'s by its order). Keys are written as given
// (no escaping: plain ASCII names only; std::logic_error on '"', '\\' or a control character).
// Values as dump() writes them: a finite double by nlohmann's own formatter
// (detail::to_chars: the shortest digits that read back to the same double, "0.0", "-0.0",
// "1e-05", "2.5"), NaN and +-Inf as null; an integer in decimal.
//
// json_array_text(v, write, depth, jobs): the text of an array whose element i is the object
// write(o, v[i]) fills, as dump(2) places it as the value of a key at depth `depth` (1: a key of
// the top-level object); elements are written in chunks on up to `jobs` threads (the text does
// not depend on jobs). It is kept in those chunks (JsonArrayText: str() joins them).
//
// json_splice(os, doc, arrays): writes doc (a dump(2) with string values as markers where arrays
// go) with the first occurrence of each marker replaced by its array's text, piece by piece: a
// document of megabytes is never assembled in one string (each copy of it is fresh memory, a page
// fault per 4 KiB). std::logic_error if a marker is missing.
#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <ostream>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "model/base/parallel.hpp"

namespace ranging::tool {

class JsonObjectText {
 public:
  // The object's text goes to the end of out; indent: the columns before its closing brace
  // (dump(2)'s current indent where the object is written).
  JsonObjectText(std::string& out, std::size_t indent) : out_(out), indent_(indent) { out_ += '{'; }
  void number(std::string_view key, double v) {
    member(key);
    if (!std::isfinite(v)) {
      out_ += "null";
      return;
    }
    char buf[64];  // nlohmann's serializer's number buffer
    char* end = nlohmann::detail::to_chars(buf, buf + sizeof buf, v);
    out_.append(buf, static_cast<std::size_t>(end - buf));
  }
  void integer(std::string_view key, long long v) {
    member(key);
    char buf[24];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    out_.append(buf, static_cast<std::size_t>(r.ptr - buf));
  }
  // Closes the object ("{}" when it has no member); nothing may be added after.
  void finish() {
    if (any_) {
      out_ += '\n';
      out_.append(indent_, ' ');
    }
    out_ += '}';
  }

 private:
  std::string& out_;
  std::size_t indent_;
  std::string last_;
  bool any_ = false;
  void member(std::string_view key) {
    if (any_ && !(last_ < key)) {
      throw std::logic_error("JsonObjectText: key \"" + std::string(key) + "\" after \"" + last_ +
                             "\"; nlohmann writes an object's keys in increasing order");
    }
    for (char ch : key) {
      if (ch == '"' || ch == '\\' || static_cast<unsigned char>(ch) < 0x20) {
        throw std::logic_error("JsonObjectText: key \"" + std::string(key) + "\" needs escaping");
      }
    }
    out_ += any_ ? ",\n" : "\n";
    out_.append(indent_ + 2, ' ');
    out_ += '"';
    out_ += key;
    out_ += "\": ";
    last_.assign(key);
    any_ = true;
  }
};

struct JsonArrayText {
  std::vector<std::string> pieces;  // in order: the text is their concatenation
  std::string str() const {
    std::size_t n = 0;
    for (const auto& p : pieces) n += p.size();
    std::string out;
    out.reserve(n);
    for (const auto& p : pieces) out += p;
    return out;
  }
};

template <class T, class Write>
JsonArrayText json_array_text(const std::vector<T>& v, const Write& write, int depth, int jobs) {
  if (v.empty()) return {{"[]"}};
  const std::size_t indent = static_cast<std::size_t>(2 * (depth + 1));
  constexpr std::size_t kChunk = 512;
  const std::size_t chunks = (v.size() + kChunk - 1) / kChunk;
  JsonArrayText a;
  a.pieces.resize(chunks + 2);
  a.pieces.front() = "[";
  parallel_items(chunks, std::min<std::size_t>(static_cast<std::size_t>(std::max(jobs, 1)), chunks),
                 [&](std::size_t c, std::size_t) {
                   std::string& out = a.pieces[c + 1];
                   for (std::size_t i = c * kChunk; i < std::min(v.size(), (c + 1) * kChunk); ++i) {
                     out += i == 0 ? "\n" : ",\n";
                     out.append(indent, ' ');
                     JsonObjectText o(out, indent);
                     write(o, v[i]);
                     o.finish();
                   }
                 });
  a.pieces.back() = "\n" + std::string(indent - 2, ' ') + "]";
  return a;
}

inline void json_splice(std::ostream& os, std::string_view doc,
                        const std::vector<std::pair<std::string, const JsonArrayText*>>& arrays) {
  std::vector<std::pair<std::size_t, std::size_t>> at;  // (position in doc, index in arrays)
  for (std::size_t i = 0; i < arrays.size(); ++i) {
    const std::size_t p = doc.find(arrays[i].first);
    if (p == std::string_view::npos) throw std::logic_error("json_splice: the marker " + arrays[i].first + " is missing");
    at.emplace_back(p, i);
  }
  std::sort(at.begin(), at.end());
  std::size_t from = 0;
  for (const auto& [p, i] : at) {
    if (p < from) throw std::logic_error("json_splice: the marker " + arrays[i].first + " overlaps another");
    os.write(doc.data() + from, static_cast<std::streamsize>(p - from));
    for (const auto& piece : arrays[i].second->pieces) os.write(piece.data(), static_cast<std::streamsize>(piece.size()));
    from = p + arrays[i].first.size();
  }
  os.write(doc.data() + from, static_cast<std::streamsize>(doc.size() - from));
}

}  // namespace ranging::tool
