#include "tool/cli.hpp"

#include <charconv>
#include <cmath>
#include <iostream>
#include <sstream>

#include "model/base/error.hpp"

namespace cli {

using ranging::InputError;

Parser::Parser(std::string usage, std::string description)
    : usage_(std::move(usage)), description_(std::move(description)) {
  flag("--help", "show this help and exit");
}

void Parser::flag(const std::string& name, const std::string& help) {
  opts_.push_back({name, "", help, false, std::nullopt});
}

void Parser::option(const std::string& name, const std::string& metavar, const std::string& help,
                    std::optional<std::string> default_value) {
  opts_.push_back({name, metavar, help, true, std::move(default_value)});
}

void Parser::positional(const std::string& metavar, const std::string& help, bool required) {
  pos_.push_back({metavar, help, required});
}

const Parser::Opt* Parser::find(const std::string& name) const {
  for (const Opt& o : opts_) {
    if (o.name == name) return &o;
  }
  return nullptr;
}

namespace {
// A help text under its option: every line indented 6 spaces, the continuation lines too.
std::string indented(const std::string& text) {
  std::string out = "      ";
  for (char c : text) {
    out += c;
    if (c == '\n') out += "      ";
  }
  return out;
}
}  // namespace

std::string Parser::help_text() const {
  std::ostringstream os;
  os << "usage: " << usage_;
  for (const Pos& p : pos_) os << (p.required ? " " : " [") << p.metavar << (p.required ? "" : "]");
  os << " [options]\n\n" << description_ << "\n";
  if (!pos_.empty()) {
    os << "\narguments:\n";
    for (const Pos& p : pos_) os << "  " << p.metavar << "\n" << indented(p.help) << "\n";
  }
  os << "\noptions:\n";
  for (const Opt& o : opts_) {
    os << "  " << o.name;
    if (o.takes_value) os << " " << o.metavar;
    os << "\n" << indented(o.help);
    if (o.default_value) os << " (default: " << *o.default_value << ")";
    os << "\n";
  }
  return os.str();
}

bool Parser::parse(const std::vector<std::string>& args) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a.size() > 2 && a.rfind("--", 0) == 0) {
      std::string name = a, value;
      bool inline_value = false;
      if (auto eq = a.find('='); eq != std::string::npos) {
        name = a.substr(0, eq);
        value = a.substr(eq + 1);
        inline_value = true;
      }
      const Opt* o = find(name);
      if (o == nullptr) {
        std::string valid;
        for (const Opt& k : opts_) valid += (valid.empty() ? "" : ", ") + k.name;
        throw InputError("unknown option '" + name + "'; valid: " + valid + " (see --help)");
      }
      if (o->name == "--help") {
        std::cout << help_text();
        return false;
      }
      if (o->takes_value) {
        if (!inline_value) {
          if (i + 1 >= args.size()) {
            throw InputError("option " + name + " needs a value " + o->metavar);
          }
          value = args[++i];
        }
      } else if (inline_value) {
        throw InputError("option " + name + " takes no value");
      }
      given_.emplace_back(name, value);
    } else {
      positionals_.push_back(a);
    }
  }
  size_t required = 0;
  for (const Pos& p : pos_) required += p.required ? 1 : 0;
  if (positionals_.size() < required) {
    throw InputError("missing argument " + pos_[positionals_.size()].metavar);
  }
  if (positionals_.size() > pos_.size()) {
    throw InputError("unexpected argument '" + positionals_[pos_.size()] + "'");
  }
  return true;
}

bool Parser::has(const std::string& name) const {
  for (const auto& [n, v] : given_) {
    if (n == name) return true;
  }
  return false;
}

std::optional<std::string> Parser::get(const std::string& name) const {
  std::optional<std::string> out;
  for (const auto& [n, v] : given_) {
    if (n == name) out = v;  // the last occurrence wins
  }
  if (!out) {
    if (const Opt* o = find(name)) out = o->default_value;
  }
  return out;
}

std::vector<std::string> Parser::values(const std::string& name) const {
  std::vector<std::string> out;
  for (const auto& [n, v] : given_) {
    if (n == name) out.push_back(v);
  }
  return out;
}

std::vector<std::string> Parser::items(const std::string& name) const {
  std::vector<std::string> out;
  std::stringstream ss(get(name).value_or(""));
  std::string item;
  while (std::getline(ss, item, ',')) out.push_back(item);
  return out;
}

std::vector<double> Parser::number_list(const std::string& name) const {
  std::vector<double> out;
  for (const std::string& item : items(name)) out.push_back(list_number(name, item));
  return out;
}

double list_number(const std::string& option, const std::string& item) {
  try {
    std::size_t used = 0;
    const double v = std::stod(item, &used);
    if (used != item.size()) throw std::invalid_argument(item);
    return v;
  } catch (const std::exception&) {
    throw InputError("option " + option + ": '" + item + "' is not a number");
  }
}

std::string Parser::get_or(const std::string& name, const std::string& fallback) const {
  return get(name).value_or(fallback);
}

std::string Parser::required(const std::string& name) const {
  const auto v = get(name);
  if (!v) throw InputError("option " + name + " is required");
  return *v;
}

namespace {

// The whole of `text` as a T (from_chars), or InputError "option NAME: 'text' is not a KIND".
template <class T, class Range>
T parse_whole(const std::string& name, const std::string& text, const char* kind, Range lo, Range hi) {
  T x{};
  const char* b = text.data();
  const char* e = text.data() + text.size();
  auto [ptr, ec] = std::from_chars(b, e, x);
  if (ec != std::errc() || ptr != e) {
    std::ostringstream os;
    os << "option " << name << ": '" << text << "' is not " << kind << "; valid range is [" << lo << ", " << hi << "]";
    throw InputError(os.str());
  }
  return x;
}

}  // namespace

double Parser::number(const std::string& name, double fallback, double lo, double hi) const {
  const auto v = get(name);
  const double x = v ? parse_whole<double>(name, *v, "a number", lo, hi) : fallback;
  std::ostringstream range;
  range << "option " << name;
  ranging::require_in_range(range.str(), x, lo, hi);
  return x;
}

long long Parser::integer(const std::string& name, long long fallback, long long lo,
                          long long hi) const {
  const auto v = get(name);
  const long long x = v ? parse_whole<long long>(name, *v, "an integer", lo, hi) : fallback;
  if (x < lo || x > hi) {
    std::ostringstream os;
    os << "option " << name << ": " << x << " is out of range; valid range is [" << lo << ", "
       << hi << "]";
    throw InputError(os.str());
  }
  return x;
}

}  // namespace cli
