// `ranging codes`: list the code families, print one family, or print one m-sequence.
#include <charconv>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "model/dsp/codes.hpp"
#include "model/base/error.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/json_meta.hpp"
#include "tool/options.hpp"

namespace ranging::tool {
namespace {

std::string hex_string(std::uint32_t v) {
  std::ostringstream os;
  os << "0x" << std::hex << std::uppercase << v;
  return os.str();
}

std::string chips_string(const Code& c) {
  std::string s;
  s.reserve(c.size());
  for (std::uint8_t chip : c) s += chip ? '1' : '0';
  return s;
}

nlohmann::ordered_json chips_json(const Code& c) {
  nlohmann::ordered_json a = nlohmann::ordered_json::array();
  for (std::uint8_t chip : c) a.push_back(static_cast<int>(chip));
  return a;
}

// --poly accepts 0x-prefixed hex or plain decimal; anything else names the option.
std::uint32_t parse_poly(const std::string& text) {
  const bool is_hex = text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
  const char* first = text.data() + (is_hex ? 2 : 0);
  const char* last = text.data() + text.size();
  std::uint32_t value = 0;
  auto [ptr, ec] = std::from_chars(first, last, value, is_hex ? 16 : 10);
  if (first == last || ec != std::errc() || ptr != last || value > 0x1FFFFU) {
    throw InputError("--poly: '" + text +
                     "' is not a polynomial mask; expected hex like 0x13 (x^4 + x + 1) in "
                     "[0x7, 0x1FFFF]");
  }
  return value;
}

int list_families(bool json) {
  if (json) {
    nlohmann::ordered_json out;
    out["families"] = nlohmann::ordered_json::array();
    for (const std::string& name : code_family_names()) {
      const CodeFamily f = code_family(name);
      out["families"].push_back({{"name", name}, {"length", f.length}, {"eta", f.eta()},
                                 {"description", code_family_description(name)}});
    }
    std::cout << stamp_build_info(out).dump() << "\n";
    return 0;
  }
  for (const std::string& name : code_family_names()) {
    const CodeFamily f = code_family(name);
    std::cout << std::left << std::setw(8) << name << std::right << " length " << std::setw(4)
              << f.length << "  eta " << std::setw(4) << f.eta() << "  "
              << code_family_description(name) << "\n";
  }
  return 0;
}

int print_family(const std::string& name, bool json) {
  CodeFamily f;
  try {
    f = code_family(name);
  } catch (const InputError& e) {
    throw InputError(std::string("--family: ") + e.what());
  }
  if (json) {
    nlohmann::ordered_json codes = nlohmann::ordered_json::array();
    for (const Code& c : f.codes) codes.push_back(chips_json(c));
    nlohmann::ordered_json out = {{"family", f.name}, {"length", f.length}, {"codes", codes}};
    std::cout << stamp_build_info(out).dump() << "\n";
    return 0;
  }
  std::cout << "# " << f.name << ": " << f.eta() << " codes of " << f.length << " chips; "
            << code_family_description(name) << "\n";
  std::cout << "   j  chips\n";
  for (int j = 1; j <= f.eta(); ++j) {
    std::cout << std::setw(4) << j << "  " << chips_string(f.codes[static_cast<std::size_t>(j - 1)])
              << "\n";
  }
  return 0;
}

int print_msequence(int degree, std::uint32_t poly, bool json) {
  const Code c = msequence(degree, poly);
  if (json) {
    nlohmann::ordered_json out = {{"degree", degree},
                                {"poly", poly},
                                {"length", c.size()},
                                {"chips", chips_json(c)}};
    std::cout << stamp_build_info(out).dump() << "\n";
    return 0;
  }
  std::cout << "# m-sequence degree " << degree << ", " << polynomial_string(poly) << " (" << hex_string(poly)
            << "), " << c.size() << " chips\n"
            << chips_string(c) << "\n";
  return 0;
}

}  // namespace

int cmd_codes(const Args& args) {
  cli::Parser p = command_parser("codes");
  p.flag("--list", "one line per family: name, length, eta, description");
  add_family_option(p, "print every code of it");
  p.option("--degree", "N", "print one m-sequence of this degree (2..16)");
  p.option("--poly", "0xHEX", "feedback polynomial for --degree (default: the table's primitive one)");
  add_output_options(p, {.json = true});
  if (!p.parse(args)) return 0;

  const int modes = int(p.has("--list")) + int(p.has("--family")) + int(p.has("--degree"));
  if (modes != 1) {
    throw InputError("--list, --family, --degree: give exactly one of them (got " +
                     std::to_string(modes) + ")");
  }
  if (p.has("--poly") && !p.has("--degree")) {
    throw InputError("--poly: only valid together with --degree");
  }
  const bool json = p.has("--json");
  if (p.has("--list")) {
    return list_families(json);
  }
  if (p.has("--family")) return print_family(*p.get("--family"), json);

  const int degree = static_cast<int>(p.integer("--degree", 0, 2, 16));
  std::uint32_t poly = default_primitive_polynomial(degree);
  if (p.has("--poly")) {
    poly = parse_poly(*p.get("--poly"));
    if (!is_primitive_polynomial(degree, poly)) {
      throw InputError("--poly: " + hex_string(poly) + " is not a primitive polynomial of degree " +
                       std::to_string(degree) + " (bits " + std::to_string(degree) +
                       " and 0 must be set); e.g. " + hex_string(default_primitive_polynomial(degree)));
    }
  }
  return print_msequence(degree, poly, json);
}

}  // namespace ranging::tool
