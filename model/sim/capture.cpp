#include "model/sim/capture.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string_view>
#include <system_error>

#include <nlohmann/json.hpp>

#include "model/base/atomic_file.hpp"
#include "model/base/error.hpp"
#include "model/base/input_file.hpp"
#include "model/sim/capture_stream.hpp"

namespace ranging {

char csv_separator(std::string_view line) {
  if (line.find(';') != std::string_view::npos) return ';';
  if (line.find(',') != std::string_view::npos) return ',';
  return '\0';
}

namespace {

// strtod's value, end and ERANGE verdict for the number at p (C locale) within [p, end), faster
// in the common case: std::from_chars (correctly rounded, as glibc's strtod) when it reads a
// normal value; everything else (a leading '+' or space, hex, inf, nan, zero, subnormals,
// overflow) goes to strtod itself, on a NUL-terminated copy of [p, end) (a cell inside its
// line). (Checked against strtod on 6 M
// strings: random characters, doubles in %e/%g/%f/%a/%E/%+e, the subnormal and overflow edges.)
struct Decimal {
  double value;
  const char* end;   // past the last character read
  bool range_error;  // strtod's ERANGE
};
// Clinger's fast path first: [-]D+[.D+][(e|E)[+|-]D{1,3}] with at most 19 digits whose integer
// m is at most 2^53, scaled by 10^k, |k| <= 22. m and 10^|k| are exact doubles, so one IEEE
// multiply or divide rounds the exact value m 10^k once, to nearest: strtod's correctly rounded
// value. A scope's %.9e cells all take it (zeros too: m == 0 is +-0 exactly); anything else
// goes on to from_chars.
// The 8 characters at q as a number when all are digits (SWAR: one 64-bit load, three
// multiplies; little-endian hosts, else false and the caller's loop reads them one by one).
inline bool eight_digits(const char* q, std::uint64_t& v) {
  if constexpr (std::endian::native != std::endian::little) {
    return false;
  } else {
    std::uint64_t x = 0;
    std::memcpy(&x, q, 8);
    if (((x & 0xF0F0F0F0F0F0F0F0ULL) | (((x + 0x0606060606060606ULL) & 0xF0F0F0F0F0F0F0F0ULL) >> 4)) !=
        0x3333333333333333ULL) {
      return false;
    }
    x -= 0x3030303030303030ULL;
    x = x * 10 + (x >> 8);  // byte pairs: 10 a + b in every even byte
    v = (((x & 0x000000FF000000FFULL) * (100 + (1000000ULL << 32))) +
         (((x >> 16) & 0x000000FF000000FFULL) * (1 + (10000ULL << 32)))) >> 32;
    return true;
  }
}

bool fast_decimal(const char* p, const char* end, double& v, const char*& stop) {
  static constexpr double kPow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                        1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const auto digit = [&](const char* q) { return q != end && static_cast<unsigned>(*q - '0') < 10u; };
  const bool neg = p != end && *p == '-';
  const char* q = p + (neg ? 1 : 0);
  std::uint64_t m = 0, m8 = 0;  // m wraps (unsigned) past 19 digits, which are refused below
  int digits = 0, k = 0;
  if (!digit(q)) return false;
  // A scope's %.9e cell, d.ddddddddde(+|-)dd not followed by a digit, read in one go: the
  // m and k the digit loops (else) would read (m < 10^10, k = +-dd - 9), so the same value.
  if (end - q >= 15 && q[1] == '.' && eight_digits(q + 2, m8) && digit(q + 10) && (q[11] == 'e' || q[11] == 'E') &&
      (q[12] == '-' || q[12] == '+') && digit(q + 13) && digit(q + 14) && !digit(q + 15)) {
    m = (static_cast<std::uint64_t>(*q - '0') * 100000000 + m8) * 10 + static_cast<unsigned>(q[10] - '0');
    const int e = 10 * (q[13] - '0') + (q[14] - '0');
    k = (q[12] == '-' ? -e : e) - 9;
    q += 15;
  } else {
    for (; end - q >= 8 && eight_digits(q, m8); q += 8, digits += 8) m = 100000000 * m + m8;
    for (; digit(q); ++q, ++digits) m = 10 * m + static_cast<unsigned>(*q - '0');
    if (q != end && *q == '.') {
      if (!digit(++q)) return false;
      for (; end - q >= 8 && eight_digits(q, m8); q += 8, digits += 8, k -= 8) m = 100000000 * m + m8;
      for (; digit(q); ++q, ++digits, --k) m = 10 * m + static_cast<unsigned>(*q - '0');
    }
    if (digits > 19 || m > (std::uint64_t{1} << 53)) return false;
    if (m == 0 && q != end && (*q == 'x' || *q == 'X')) return false;  // "0x...": strtod reads hex
    if (q != end && (*q == 'e' || *q == 'E')) {
      const char* x = q + 1;
      const bool xneg = x != end && *x == '-';
      if (x != end && (*x == '-' || *x == '+')) ++x;
      int e = 0, n = 0;
      for (; digit(x) && n < 4; ++x, ++n) e = 10 * e + (*x - '0');
      if (n == 0 || n == 4) return false;  // no exponent digits (from_chars stops before the 'e'), or many
      k += xneg ? -e : e;
      q = x;
    }
  }
  if (k < -22 || k > 22) return false;
  const double a = static_cast<double>(m);  // m == 0: +0 or -0 whatever k, as strtod reads it
  v = k < 0 ? a / kPow10[-k] : a * kPow10[k];
  if (neg) v = -v;
  stop = q;
  return true;
}

Decimal read_decimal(const char* p, const char* end) {
  double v = 0;
  if (const char* stop = nullptr; fast_decimal(p, end, v, stop)) return {v, stop, false};
  const auto r = std::from_chars(p, end, v);
  if (r.ec == std::errc() && std::isnormal(v)) return {v, r.ptr, false};
  const std::string copy(p, end);
  char* e = nullptr;
  errno = 0;
  v = std::strtod(copy.c_str(), &e);
  return {v, p + (e - copy.c_str()), errno == ERANGE};
}

}  // namespace

double csv_row_value(std::string_view line, int cell) {
  const char sep = csv_separator(line);
  const char* p = line.data();
  const char* const end = p + line.size();
  if (sep == '\0') {  // whitespace-separated: the cell-th token, split as split_cells splits
    const auto space = [](char ch) { return std::isspace(static_cast<unsigned char>(ch)) != 0; };
    for (int c = 0;; ++c) {
      while (p != end && space(*p)) ++p;
      if (c == cell) break;
      while (p != end && !space(*p)) ++p;
    }
  } else {
    for (int c = 0; c < cell; ++c) {  // past the cells before it
      while (p != end && *p != sep) ++p;
      if (p != end) ++p;
    }
    while (p != end && (*p == ' ' || *p == '\t' || *p == '\r' || *p == '"')) ++p;  // what trim drops
  }
  return read_decimal(p, end).value;
}
double csv_plain_cell(std::string_view line, int cell, char sep) {
  const char* p = line.data();
  const char* const end = p + line.size();
  for (int c = 0; c < cell; ++c) {
    const void* s = std::memchr(p, sep, static_cast<std::size_t>(end - p));
    p = s == nullptr ? end : static_cast<const char*>(s) + 1;
  }
  return read_decimal(p, end).value;
}

namespace {

[[noreturn]] void fail_at(const std::string& origin, std::size_t line, const std::string& what) {
  throw InputError(origin + ":" + std::to_string(line) + ": " + what);
}

std::string_view trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\"");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r\"");
  return s.substr(b, e - b + 1);
}

// Strict number: the whole cell must parse (strtod also accepts nan/inf: refused by caller).
bool parse_number(std::string_view cell, double& out) {
  if (cell.empty()) return false;
  const char* e = cell.data() + cell.size();
  const Decimal d = read_decimal(cell.data(), e);
  out = d.value;
  return d.end == e && !d.range_error;
}

// The cells of one line, views into it. Separator (csv_separator): ';' if the line has one (a
// European export; decimal commas are not read: such a cell is refused as not a number), else
// ',' if it has one, else runs of tabs and spaces (numpy.savetxt's default, SPICE and
// tab-separated exports). (By hand, not through a std::stringstream per line: its construction
// and locale look-ups were a fifth of a CSV decode; views, not strings: a row's allocations were
// a sixth.) Whitespace runs split as operator>> does (C-locale isspace); a separator splits into
// every field, so "a,b," is "a", "b", "".
void split_cells(std::string_view line, std::vector<std::string_view>& cells) {
  cells.clear();
  const char sep = csv_separator(line);
  if (sep == '\0') {
    std::size_t i = 0;
    const auto space = [&](std::size_t k) { return std::isspace(static_cast<unsigned char>(line[k])) != 0; };
    while (i < line.size()) {
      while (i < line.size() && space(i)) ++i;
      const std::size_t b = i;
      while (i < line.size() && !space(i)) ++i;
      if (i > b) cells.push_back(line.substr(b, i - b));
    }
    return;
  }
  if (line.empty()) return;
  for (std::size_t b = 0;;) {
    const std::size_t e = line.find(sep, b);
    cells.push_back(trim(line.substr(b, e == std::string_view::npos ? std::string_view::npos : e - b)));
    if (e == std::string_view::npos) break;
    b = e + 1;
  }
}

}  // namespace

namespace {

void check_meta(const CaptureMeta& m, const std::function<std::string(const char*)>& where) {
  if (m.code_sent && (*m.code_sent < 0 || *m.code_sent > 1000)) {
    throw InputError(where("code_sent") + ": " + std::to_string(*m.code_sent) + " is out of range; valid 0..1000");
  }
  auto range = [&](const char* key, const std::optional<double>& v, double lo, double hi) {
    if (v && !(std::isfinite(*v) && *v > lo && *v <= hi)) {
      std::ostringstream os;
      os << where(key) << ": " << *v << " is out of range; valid (" << lo << ", " << hi << "]";
      throw InputError(os.str());
    }
  };
  range("true_distance_m", m.true_distance_m, 0, 1000);
  range("speed_of_sound", m.speed_of_sound, 100, 10000);
  range("sample_rate", m.sample_rate, 0, 1e12);
  range("period_s", m.period_s, 0, 10);
}

void read_meta_line(CaptureMeta& m, const std::string& key, const std::string& value, const std::string& origin,
                    std::size_t line) {
  auto number = [&]() {
    double x = 0;
    if (!parse_number(value, x)) fail_at(origin, line, key + ": '" + value + "' is not a number");
    return x;
  };
  if (key == "Scene") m.scene = value;
  else if (key == "Family") m.family = value;
  else if (key == "Code Sent") {
    const double x = number();
    if (x != std::floor(x)) fail_at(origin, line, key + ": '" + value + "' is not an integer");
    m.code_sent = static_cast<int>(std::clamp(x, -1.0, 1e6));
  } else if (key == "True Distance (m)") m.true_distance_m = number();
  else if (key == "Speed of Sound (m/s)") m.speed_of_sound = number();
  else if (key == "Sample Rate (Hz)") m.sample_rate = number();
  else if (key == "Burst Period (s)") m.period_s = number();
  else return;
  check_meta(m, [&](const char*) { return origin + ":" + std::to_string(line) + ": " + key; });
}

}  // namespace

std::string capture_meta_json(const CaptureMeta& m) {
  nlohmann::json j = nlohmann::json::object();
  if (m.scene) j["scene"] = *m.scene;
  if (m.family) j["family"] = *m.family;
  if (m.code_sent) j["code_sent"] = *m.code_sent;
  if (m.true_distance_m) j["true_distance_m"] = *m.true_distance_m;
  if (m.speed_of_sound) j["speed_of_sound"] = *m.speed_of_sound;
  if (m.sample_rate) j["sample_rate"] = *m.sample_rate;
  if (m.period_s) j["period_s"] = *m.period_s;
  return j.dump(2) + "\n";
}

CaptureMeta parse_capture_meta_json(const std::string& text, const std::string& origin) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError(origin + ": not valid JSON: " + e.what());
  }
  if (!j.is_object()) throw InputError(origin + ": expected a JSON object of capture metadata");
  CaptureMeta m;
  for (const auto& item : j.items()) {
    // plain references, not a structured binding: clang 14 (the fuzz build) cannot capture
    // structured bindings in the lambdas below
    const std::string& key = item.key();
    const nlohmann::json& v = item.value();
    auto num = [&]() {
      if (!v.is_number()) throw InputError(origin + ": key " + key + ": expected a number");
      return v.get<double>();
    };
    auto str = [&]() {
      if (!v.is_string()) throw InputError(origin + ": key " + key + ": expected a string");
      return v.get<std::string>();
    };
    if (key == "scene") m.scene = str();
    else if (key == "family") m.family = str();
    else if (key == "code_sent") {
      if (!v.is_number_integer()) throw InputError(origin + ": key code_sent: expected an integer 0..1000");
      m.code_sent = static_cast<int>(std::clamp<long long>(v.get<long long>(), -1, 1000000));
    } else if (key == "true_distance_m") m.true_distance_m = num();
    else if (key == "speed_of_sound") m.speed_of_sound = num();
    else if (key == "sample_rate") m.sample_rate = num();
    else if (key == "period_s") m.period_s = num();
    else {
      throw InputError(origin + ": unknown key '" + key +
                       "'; valid: scene, family, code_sent, true_distance_m, speed_of_sound, sample_rate, period_s");
    }
  }
  check_meta(m, [&](const char* key) { return origin + ": key " + key; });
  return m;
}

CsvCaptureScan::CsvCaptureScan(std::string origin, const CaptureRead& how)
    : origin_(std::move(origin)), channel_(how.channel), given_rate_(how.sample_rate) {
  if (channel_ < 1) throw InputError(origin_ + ": channel " + std::to_string(channel_) + " is out of range; valid >= 1");
  if (!(given_rate_ >= 0 && given_rate_ <= 1e12)) {
    throw InputError(origin_ + ": sample rate " + std::to_string(given_rate_) + " Hz is out of range; valid [0, 1e12] (0: the file's own)");
  }
}

bool CsvCaptureScan::plain_cells(std::string_view text, double& t, double& v) const {
  const char* p = text.data();
  const char* end = p + text.size();
  if (p != end && end[-1] == '\r') --end;
  const auto number = [&](const char* q, double& x) -> const char* {  // past the number, or nullptr
    if (q == end || !(*q == '-' || static_cast<unsigned>(*q - '0') < 10u)) return nullptr;
    const Decimal d = read_decimal(q, end);
    if (d.end == q || d.range_error || !std::isfinite(d.value)) return nullptr;
    if (d.end != end && *d.end != sep_) return nullptr;  // more in the cell: a space, a quote, text
    x = d.value;
    return d.end;
  };
  double tv = 0, vv = 0;
  const char* q = number(p, tv);
  if (q == nullptr || q == end) return false;
  for (int c = 1; c < channel_; ++c) {  // past the cells before the channel's
    const void* s = std::memchr(q + 1, sep_, static_cast<std::size_t>(end - (q + 1)));
    if (s == nullptr) return false;
    if (sep_ == ',' && std::memchr(q + 1, ';', static_cast<std::size_t>(static_cast<const char*>(s) - (q + 1)))) {
      return false;
    }
    q = static_cast<const char*>(s);
  }
  const char* r = number(q + 1, vv);
  if (r == nullptr) return false;
  if (sep_ == ',' && r != end && std::memchr(r, ';', static_cast<std::size_t>(end - r))) return false;
  t = tv;
  v = vv;
  return true;
}

bool CsvCaptureScan::fast_row(std::string_view text, double& t, double& v) {
  double tv = 0, vv = 0;
  if (!plain_cells(text, tv, vv)) return false;
  if (rows_ > 0 && !(tv > t_last_)) return false;  // the general way names it
  if (rows_ == 0) t_first_ = tv;  // a continuation's first row
  t_last_ = tv;
  last_data_line_ = lineno_;
  ++rows_;
  ++fast_rows_;
  t = tv;
  v = vv;
  return true;
}

bool CsvCaptureScan::line(std::string_view text, double& t, double& v) {
  ++lineno_;
  if (sep_ != '\0' && fast_ && fast_row(text, t, v)) return true;
  if (trim(text).empty()) {
    if (data_) fail_at(origin_, lineno_, "empty line inside the data rows");
    return false;
  }
  split_cells(text, cells_);
  const std::vector<std::string_view>& cells = cells_;
  double first = 0;
  const bool numeric_first = !cells.empty() && parse_number(cells[0], first);
  if (!data_ && !numeric_first) {  // header line (before the first data row); metadata keys
    if (cells.size() >= 2 && cells[0] == "Record Length" && parse_number(cells[1], first)) {
      record_length_ = first;
      record_line_ = lineno_;
    }
    if (cells.size() >= 2) read_meta_line(meta_, std::string(cells[0]), std::string(cells[1]), origin_, lineno_);
    return false;
  }
  if (!data_) {
    first_data_line_ = lineno_;
    no_time_ = cells.size() == 1 && given_rate_ > 0;  // samples alone, at the given rate
    if (!no_time_) sep_ = csv_separator(text);
    channels_ = no_time_ ? 1 : static_cast<int>(std::max<std::size_t>(cells.size(), 1) - 1);
    if (!no_time_ && given_rate_ > 0) {
      std::ostringstream os;
      os.precision(9);
      os << "a sample rate (" << given_rate_ << " Hz) was given, but the rows have a time column, which sets the "
         << "rate; give a rate only for a CSV of one column of samples, or a WAV";
      fail_at(origin_, lineno_, os.str());
    }
  }
  data_ = true;
  if (no_time_) {
    double x = 0;
    if (cells.size() != 1) {
      fail_at(origin_, lineno_, "expected one column of samples (as the first data row), found " +
                                    std::to_string(cells.size()));
    }
    if (channel_ != 1) {
      fail_at(origin_, lineno_, "channel " + std::to_string(channel_) + " is out of range: the rows have 1 channel; valid 1..1");
    }
    if (!parse_number(cells[0], x)) fail_at(origin_, lineno_, "sample: '" + std::string(cells[0]) + "' is not a number");
    if (!std::isfinite(x)) {
      fail_at(origin_, lineno_, "sample: '" + std::string(cells[0]) + "' is not finite (NaN or Inf)");
    }
    t = static_cast<double>(rows_) / given_rate_;
    if (rows_ == 0) t_first_ = t;
    t_last_ = t;
    last_data_line_ = lineno_;
    ++rows_;
    v = x;
    return true;
  }
  const auto ch = static_cast<std::size_t>(channel_);
  if (cells.size() < 2) {
    fail_at(origin_, lineno_, "expected 'time,voltage', found one column (a CSV of samples alone is read with its "
                              "sample rate given: decode --sample-rate HZ)");
  }
  if (cells.size() < ch + 1) {
    fail_at(origin_, lineno_, "channel " + std::to_string(channel_) + " (column " + std::to_string(channel_ + 1) +
                                  ") is out of range: the row has " + std::to_string(cells.size() - 1) +
                                  " channel(s); valid 1.." + std::to_string(cells.size() - 1));
  }
  double val[2] = {0, 0};
  for (int c = 0; c < 2; ++c) {
    const std::string_view cell = cells[c == 0 ? 0 : ch];
    const auto bad = [&](const char* why) {
      const std::string what = c == 0 ? std::string("time") : channel_ == 1 ? std::string("voltage")
                                                                            : "channel " + std::to_string(channel_);
      fail_at(origin_, lineno_, what + " column: '" + std::string(cell) + "' " + why);
    };
    if (!parse_number(cell, val[c])) bad("is not a number");
    if (!std::isfinite(val[c])) bad("is not finite (NaN or Inf)");
  }
  if (rows_ > 0 && !(val[0] > t_last_)) {
    fail_at(origin_, lineno_, "time does not increase (" + std::string(cells[0]) + " after the previous row)");
  }
  if (rows_ == 0) {
    t_first_ = val[0];
    double a = 0, b = 0;
    first_plain_ = sep_ != '\0' && plain_cells(text, a, b);
  }
  t_last_ = val[0];
  last_data_line_ = lineno_;
  ++rows_;
  t = val[0];
  v = val[1];
  return true;
}

CsvCaptureScan CsvCaptureScan::continuation() const {
  CsvCaptureScan part(origin_, CaptureRead{.channel = channel_, .sample_rate = given_rate_});
  part.channels_ = channels_;
  part.no_time_ = no_time_;
  part.data_ = data_;
  part.sep_ = sep_;
  return part;
}

void CsvCaptureScan::append(const CsvCaptureScan& part) {
  lineno_ += part.lineno_;
  if (part.rows_ == 0) return;
  rows_ += part.rows_;
  fast_rows_ += part.fast_rows_;
  last_data_line_ = lineno_ - (part.lineno_ - part.last_data_line_);
  t_last_ = no_time_ ? static_cast<double>(rows_ - 1) / given_rate_ : part.t_last_;
}

void CsvCaptureScan::finish() {
  if (record_length_ >= 0 && record_length_ != static_cast<double>(rows_)) {
    std::ostringstream os;
    os << "Record Length: the header declares " << record_length_ << " rows, the file holds " << rows_
       << " data rows (truncated?); valid: the number of data rows";
    fail_at(origin_, record_line_, os.str());
  }
  if (rows_ == 0) fail_at(origin_, lineno_, "no data rows (empty capture; expected rows 'time_s,volts')");
  if (rows_ < 2) fail_at(origin_, lineno_, "one data row: a capture needs at least two samples");
  if (no_time_) {
    dt_ = 1.0 / given_rate_;
    if (!meta_.empty()) meta_.source = "csv header";
    return;
  }
  const double span = t_last_ - t_first_;
  dt_ = span / static_cast<double>(rows_ - 1);
  if (!std::isfinite(span) || !(dt_ > 0) || !(1.0 / dt_ >= 1.0 && 1.0 / dt_ <= 1e12)) {
    std::ostringstream os;
    os.precision(9);
    os << "time: a span of " << span << " s over " << rows_ - 1 << " steps is not a sample rate in [1 Hz, 1e12 Hz]";
    fail_at(origin_, last_data_line_, os.str());
  }
  if (!meta_.empty()) meta_.source = "csv header";
}

void CsvCaptureScan::check_grid(std::size_t n, double t, std::size_t line) const {
  const double grid = t_first_ + dt_ * static_cast<double>(n);
  if (!on_grid(t_first_, dt_, n, t)) {
    std::ostringstream os;
    os.precision(9);
    os << "uneven sampling: time " << t << " s is " << (t - grid) / dt_ << " steps off the uniform grid of step "
       << dt_ << " s (tolerance 0.02 step)";
    fail_at(origin_, line, os.str());
  }
}

Capture parse_capture_csv(const std::string& text, const std::string& origin, const CaptureRead& how) {
  CsvCaptureScan scan(origin, how);
  std::vector<double> t, v;
  std::vector<std::size_t> lines;
  std::stringstream in(text);
  std::string line;
  double tv = 0, vv = 0;
  while (std::getline(in, line)) {
    if (!scan.line(line, tv, vv)) continue;
    t.push_back(tv);
    v.push_back(vv);
    lines.push_back(scan.lineno());
  }
  scan.finish();
  for (std::size_t n = 0; n < t.size(); ++n) scan.check_grid(n, t[n], lines[n]);
  Capture c;
  c.sample_rate = scan.sample_rate();
  c.t0 = scan.t0();
  c.meta = scan.meta();
  c.samples = std::move(v);
  c.channel = how.channel;
  c.channels = scan.channels();
  c.file_rate = scan.has_time() ? c.sample_rate : 0;
  return c;
}

namespace {

std::uint32_t le32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8) | static_cast<unsigned char>(b[at + static_cast<std::size_t>(i)]);
  return v;
}
std::uint16_t le16(const std::string& b, std::size_t at) {
  return static_cast<std::uint16_t>(static_cast<unsigned char>(b[at]) |
                                    (static_cast<unsigned char>(b[at + 1]) << 8));
}
[[noreturn]] void fail_wav(const std::string& origin, std::size_t at, const std::string& what) {
  throw InputError(origin + ": byte " + std::to_string(at) + ": " + what);
}

}  // namespace

WavLayout parse_wav_layout(const std::function<std::string(std::size_t, std::size_t)>& bytes,
                           std::size_t file_size, const std::string& origin, int channel) {
  if (channel < 1) fail_wav(origin, 0, "channel " + std::to_string(channel) + " is out of range; valid >= 1");
  if (file_size == 0) fail_wav(origin, 0, "empty file");
  const std::string head = bytes(0, std::min<std::size_t>(12, file_size));
  if (head.size() < 12 || head.compare(0, 4, "RIFF") != 0 || head.compare(8, 4, "WAVE") != 0) {
    fail_wav(origin, 0, "not a RIFF/WAVE file");
  }
  std::size_t at = 12;
  bool have_fmt = false;
  std::uint16_t format = 0, channels = 0, bits = 0;
  std::uint32_t rate = 0;
  while (true) {
    if (at + 8 > file_size) {
      fail_wav(origin, at, have_fmt ? "truncated: no data chunk" : "truncated: no fmt chunk");
    }
    const std::string ch = bytes(at, 8);
    const std::string id = ch.substr(0, 4);
    const std::uint32_t size = le32(ch, 4);
    const std::size_t body = at + 8;
    if (id == "fmt ") {
      if (size < 16 || body + size > file_size) fail_wav(origin, at, "truncated or short fmt chunk");
      const std::string b = bytes(body, std::min<std::size_t>(size, 40));
      format = le16(b, 0);
      channels = le16(b, 2);
      rate = le32(b, 4);
      bits = le16(b, 14);
      if (format == 0xFFFE) {
        if (size < 40) fail_wav(origin, at, "WAVE_FORMAT_EXTENSIBLE fmt chunk shorter than 40 bytes");
        format = le16(b, 24);  // the sub-format GUID starts with the format code
      }
      have_fmt = true;
    } else if (id == "data") {
      if (!have_fmt) fail_wav(origin, at, "data chunk before the fmt chunk");
      if (channels == 0) fail_wav(origin, at, "fmt declares 0 channels");
      if (rate == 0) fail_wav(origin, at, "fmt declares a sample rate of 0");
      const bool pcm = format == 1 && (bits == 8 || bits == 16 || bits == 24 || bits == 32);
      const bool flt = format == 3 && (bits == 32 || bits == 64);
      if (!pcm && !flt) {
        fail_wav(origin, at, "unsupported sample format (format " + std::to_string(format) + ", " +
                                 std::to_string(bits) + " bits); valid: 8/16/24/32-bit PCM, 32/64-bit float");
      }
      WavLayout w;
      w.rate = rate;
      w.flt = flt;
      w.bits = bits;
      if (static_cast<unsigned>(channel) > channels) {
        fail_wav(origin, at, "channel " + std::to_string(channel) + " is out of range: the file has " +
                                 std::to_string(channels) + " channel(s); valid 1.." + std::to_string(channels));
      }
      w.frame = static_cast<std::size_t>(bits / 8u) * channels;
      w.channels = channels;
      w.offset = static_cast<std::size_t>(bits / 8u) * static_cast<std::size_t>(channel - 1);
      w.body = body;
      w.chunk_at = at;
      if (body + size > file_size) {
        fail_wav(origin, at, "truncated: the data chunk declares " + std::to_string(size) +
                                 " bytes, the file holds " + std::to_string(file_size - body));
      }
      if (size % w.frame != 0) fail_wav(origin, at, "truncated: data size is not a whole number of frames");
      w.n = size / w.frame;
      return w;
    }
    // RIFF chunks are padded to an even size.
    at = body + size + (size & 1u);
  }
}

void wav_samples(const char* p, std::size_t frames, const WavLayout& w, const std::string& origin, std::size_t i0,
                 double* out) {
  const std::size_t f = w.frame;
  const auto* u = reinterpret_cast<const unsigned char*>(p) + w.offset;
  auto le = [](const unsigned char* b, int n) {  // n little-endian bytes
    std::uint64_t v = 0;
    for (int i = n - 1; i >= 0; --i) v = (v << 8) | b[i];
    return v;
  };
  auto not_finite = [&](std::size_t k) {
    const std::size_t i = i0 + k;
    fail_wav(origin, w.body + i * w.frame + w.offset, "sample " + std::to_string(i) + " is not finite (NaN or Inf)");
  };
  if (w.flt && w.bits == 32 && f == 4 && std::endian::native == std::endian::little) {
    // one channel of float32 on a little-endian host: contiguous, vectorizes
    std::uint32_t bad = 0;
    for (std::size_t k = 0; k < frames; ++k) {
      std::uint32_t bits;
      std::memcpy(&bits, u + 4 * k, sizeof bits);
      bad |= static_cast<std::uint32_t>((bits & 0x7f800000u) == 0x7f800000u);  // exponent all ones: NaN, Inf
      out[k] = std::bit_cast<float>(bits);
    }
    if (bad) {
      for (std::size_t k = 0; k < frames; ++k) {
        if (!std::isfinite(out[k])) not_finite(k);
      }
    }
  } else if (w.flt && w.bits == 32) {
    for (std::size_t k = 0; k < frames; ++k, u += f) {
      const auto bits = static_cast<std::uint32_t>(le(u, 4));
      float x;
      std::memcpy(&x, &bits, sizeof x);
      if (!std::isfinite(x)) not_finite(k);
      out[k] = x;
    }
  } else if (w.flt) {  // 64-bit float
    for (std::size_t k = 0; k < frames; ++k, u += f) {
      const std::uint64_t bits = le(u, 8);
      double x;
      std::memcpy(&x, &bits, sizeof x);
      if (!std::isfinite(x)) not_finite(k);
      out[k] = x;
    }
  } else if (w.bits == 8) {  // unsigned, 128 is zero
    for (std::size_t k = 0; k < frames; ++k, u += f) out[k] = (static_cast<int>(u[0]) - 128) / 128.0;
  } else if (w.bits == 32) {
    for (std::size_t k = 0; k < frames; ++k, u += f) {
      out[k] = static_cast<std::int32_t>(static_cast<std::uint32_t>(le(u, 4))) / 2147483648.0;
    }
  } else if (w.bits == 16) {
    for (std::size_t k = 0; k < frames; ++k, u += f) {
      out[k] = static_cast<std::int16_t>(static_cast<std::uint16_t>(u[0] | (u[1] << 8))) / 32768.0;
    }
  } else {
    for (std::size_t k = 0; k < frames; ++k, u += f) {
      std::int32_t s = static_cast<std::int32_t>(u[0] | (u[1] << 8) | (u[2] << 16));
      if (s & 0x800000) s -= 0x1000000;
      out[k] = s / 8388608.0;
    }
  }
}

Capture parse_capture_wav(const std::string& b, const std::string& origin, const CaptureRead& how) {
  const WavLayout w = parse_wav_layout([&](std::size_t at, std::size_t len) { return b.substr(at, len); }, b.size(),
                                       origin, how.channel);
  Capture c;
  c.channel = how.channel;
  c.channels = static_cast<int>(w.channels);
  c.file_rate = w.rate;
  c.sample_rate = how.sample_rate > 0 ? how.sample_rate : w.rate;
  c.samples.resize(w.n);
  wav_samples(b.data() + w.body, w.n, w, origin, 0, c.samples.data());
  if (w.n < 2) fail_wav(origin, w.chunk_at, "the data chunk holds fewer than two samples");
  return c;
}

void merge_capture_sidecar(CaptureMeta& o, const std::string& path) {
  const std::string sidecar = path.substr(0, path.size() - 4) + ".json";
  std::ifstream js(sidecar, std::ios::binary);
  if (js) {
    std::stringstream sj;
    sj << js.rdbuf();
    const CaptureMeta m = parse_capture_meta_json(sj.str(), sidecar);
    const bool had = !o.empty();
    if (!o.scene) o.scene = m.scene;
    if (!o.family) o.family = m.family;
    if (!o.code_sent) o.code_sent = m.code_sent;
    if (!o.true_distance_m) o.true_distance_m = m.true_distance_m;
    if (!o.speed_of_sound) o.speed_of_sound = m.speed_of_sound;
    if (!o.sample_rate) o.sample_rate = m.sample_rate;
    if (!o.period_s) o.period_s = m.period_s;
    if (!m.empty()) o.source = had ? o.source + " and " + sidecar : sidecar;
  }
}

bool capture_is_csv(const std::string& path) {
  // the file name's extension only (a dot in a directory's name is not one)
  const std::string name = std::filesystem::path(path).filename().string();
  const auto dot = name.find_last_of('.');
  std::string ext = dot == std::string::npos ? std::string() : name.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
  if (ext == "csv" || ext == "wav") return ext == "csv";
  const std::string what = dot == std::string::npos ? "has no file extension" : "unknown capture type '." + ext + "'";
  throw InputError(path + ": " + what + "; valid: .csv (oscilloscope export), .wav");
}

Capture read_capture(const std::string& path, const CaptureRead& how) {
  const bool csv = capture_is_csv(path);
  const std::string bytes = read_input_file(path, "capture file", std::size_t{1} << 30);
  Capture c = csv ? parse_capture_csv(bytes, path, how) : parse_capture_wav(bytes, path, how);
  merge_capture_sidecar(c.meta, path);
  return c;
}

std::string capture_csv(const Capture& c) {
  std::ostringstream os;
  os.precision(9);
  os << "Model,ranging simulate\nRecord Length," << c.samples.size() << "\nSample Interval,"
     << 1.0 / c.sample_rate << "\n";
  const CaptureMeta& m = c.meta;
  os.precision(12);
  if (m.scene) os << "Scene," << *m.scene << "\n";
  if (m.family) os << "Family," << *m.family << "\n";
  if (m.code_sent) os << "Code Sent," << *m.code_sent << "\n";
  if (m.true_distance_m) os << "True Distance (m)," << *m.true_distance_m << "\n";
  if (m.speed_of_sound) os << "Speed of Sound (m/s)," << *m.speed_of_sound << "\n";
  if (m.sample_rate) os << "Sample Rate (Hz)," << *m.sample_rate << "\n";
  if (m.period_s) os << "Burst Period (s)," << *m.period_s << "\n";
  os << "TIME,CH1\n";
  char buf[64];
  for (std::size_t n = 0; n < c.samples.size(); ++n) {
    std::snprintf(buf, sizeof buf, "%.9e,%.9e\n", c.t0 + static_cast<double>(n) / c.sample_rate, c.samples[n]);
    os << buf;
  }
  return os.str();
}

std::string capture_wav(const Capture& c, WavFormat fmt, double full_scale) {
  const double r = std::round(c.sample_rate);
  if (std::abs(r - c.sample_rate) > 1e-6 * c.sample_rate || r < 1 || r > 4294967295.0) {
    throw InputError("capture: sample rate " + std::to_string(c.sample_rate) + " Hz is not a WAV rate (integer Hz)");
  }
  if (c.t0 != 0) throw InputError("capture: a WAV file starts at t = 0; this capture starts at t0 != 0");
  require_in_range("full_scale", full_scale, 1e-12, 1e12);
  const bool flt = fmt == WavFormat::Float32 || fmt == WavFormat::Float64;
  const int bytes = fmt == WavFormat::Pcm8    ? 1
                    : fmt == WavFormat::Pcm16 ? 2
                    : fmt == WavFormat::Pcm24 ? 3
                    : fmt == WavFormat::Float64 ? 8
                                                : 4;
  const std::uint32_t data = static_cast<std::uint32_t>(c.samples.size() * static_cast<std::size_t>(bytes));
  std::string out;
  auto put = [&](std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  out += "RIFF";
  put(36 + data, 4);
  out += "WAVEfmt ";
  put(16, 4);
  put(flt ? 3 : 1, 2);
  put(1, 2);
  put(static_cast<std::uint32_t>(r), 4);
  put(static_cast<std::uint64_t>(r) * static_cast<std::uint64_t>(bytes), 4);
  put(static_cast<std::uint64_t>(bytes), 2);
  put(static_cast<std::uint64_t>(8 * bytes), 2);
  out += "data";
  put(data, 4);
  for (double x : c.samples) {
    if (fmt == WavFormat::Float32) {
      const float f = static_cast<float>(x);
      std::uint32_t u;
      std::memcpy(&u, &f, sizeof u);
      put(u, 4);
    } else if (fmt == WavFormat::Float64) {
      std::uint64_t u;
      std::memcpy(&u, &x, sizeof u);
      put(u, 8);
    } else {
      // 2^(bits-1); 8-bit PCM is unsigned, offset by 128
      const double scale = std::ldexp(1.0, 8 * bytes - 1);
      const double q = std::clamp(std::round(x / full_scale * scale), -scale, scale - 1);
      const auto v = static_cast<std::int64_t>(q) + (fmt == WavFormat::Pcm8 ? 128 : 0);
      put(static_cast<std::uint64_t>(v), bytes);
    }
  }
  return out;
}

// write_file_atomic: model/base/atomic_file.cpp (temporary name in the same folder, renamed).

}  // namespace ranging
