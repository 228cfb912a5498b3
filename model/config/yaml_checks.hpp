#pragma once
// Checks on YAML text that yaml-cpp does not make, run by yaml::load (yaml_reader.hpp) before
// the text becomes a node tree. Each failure is an InputError "origin:line: what".
//
// check_yaml_text: the text is UTF-8 (every sequence well formed: no stray continuation
// bytes, no overlong forms, no surrogates, nothing above U+10FFFF) and holds no control
// characters other than TAB, LF and CR (YAML 1.2 section 5.1). A UTF-8 byte order mark at
// the start is allowed (strip_bom removes it); CRLF line endings are allowed.
//
// check_yaml_structure: one pass over the parser's events (YAML::Parser, so every node still
// has its mark) that refuses
//   - a key that appears twice in one mapping (yaml-cpp keeps the later value silently): the
//     message names the key and the lines of both occurrences;
//   - more than one document;
//   - nesting deeper than kMaxDepth;
//   - a document that, with its aliases expanded, has more than kMaxNodes nodes (a "billion
//     laughs" alias bomb is a few hundred bytes that expand to 10^9 nodes).
#include <cstddef>
#include <string>

namespace ranging::yaml {

inline constexpr std::size_t kMaxDepth = 64;
inline constexpr std::size_t kMaxNodes = 1000000;

void check_yaml_text(const std::string& text, const std::string& origin);
void check_yaml_structure(const std::string& text, const std::string& origin);
// The text without a leading UTF-8 BOM (EF BB BF).
std::string strip_bom(const std::string& text);

}  // namespace ranging::yaml
