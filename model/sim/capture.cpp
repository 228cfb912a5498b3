#include "model/sim/capture.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>

#include <nlohmann/json.hpp>

#include "model/base/atomic_file.hpp"
#include "model/base/error.hpp"
#include "model/base/input_file.hpp"

namespace ranging {
namespace {

[[noreturn]] void fail_at(const std::string& origin, std::size_t line, const std::string& what) {
  throw InputError(origin + ":" + std::to_string(line) + ": " + what);
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\"");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\"");
  return s.substr(b, e - b + 1);
}

// Strict number: the whole cell must parse (strtod also accepts nan/inf: refused by caller).
bool parse_number(const std::string& cell, double& out) {
  if (cell.empty()) return false;
  const char* b = cell.c_str();
  char* end = nullptr;
  errno = 0;
  out = std::strtod(b, &end);
  return end == b + cell.size() && errno != ERANGE;
}

std::vector<std::string> split_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::stringstream ss(line);
  while (std::getline(ss, cell, ',')) cells.push_back(trim(cell));
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
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

Capture parse_capture_csv(const std::string& text, const std::string& origin) {
  Capture c;
  std::vector<double> t, v;
  std::vector<std::size_t> lines;
  std::stringstream in(text);
  std::string line;
  std::size_t lineno = 0;
  bool data = false;
  double record_length = -1;  // the header's "Record Length" (rows the scope says it wrote)
  std::size_t record_line = 0;
  while (std::getline(in, line)) {
    ++lineno;
    if (trim(line).empty()) {
      if (data) fail_at(origin, lineno, "empty line inside the data rows");
      continue;
    }
    const auto cells = split_cells(line);
    double first = 0;
    const bool numeric_first = !cells.empty() && parse_number(cells[0], first);
    if (!data && !numeric_first) {  // header line (before the first data row); metadata keys
      if (cells.size() >= 2 && cells[0] == "Record Length" && parse_number(cells[1], first)) {
        record_length = first;
        record_line = lineno;
      }
      if (cells.size() >= 2) read_meta_line(c.meta, cells[0], cells[1], origin, lineno);
      continue;
    }
    data = true;
    if (cells.size() < 2) fail_at(origin, lineno, "expected 'time,voltage', found one column");
    double val[2];
    for (int c = 0; c < 2; ++c) {
      const std::string& cell = cells[static_cast<std::size_t>(c)];
      if (!parse_number(cell, val[c])) {
        fail_at(origin, lineno, std::string(c == 0 ? "time" : "voltage") + " column: '" + cell +
                                    "' is not a number");
      }
      if (!std::isfinite(val[c])) {
        fail_at(origin, lineno, std::string(c == 0 ? "time" : "voltage") + " column: '" + cell +
                                    "' is not finite (NaN or Inf)");
      }
    }
    if (!t.empty() && !(val[0] > t.back())) {
      fail_at(origin, lineno, "time does not increase (" + cells[0] + " after the previous row)");
    }
    t.push_back(val[0]);
    v.push_back(val[1]);
    lines.push_back(lineno);
  }
  if (record_length >= 0 && record_length != static_cast<double>(t.size())) {
    std::ostringstream os;
    os << "Record Length: the header declares " << record_length << " rows, the file holds " << t.size()
       << " data rows (truncated?); valid: the number of data rows";
    fail_at(origin, record_line, os.str());
  }
  if (t.empty()) fail_at(origin, lineno, "no data rows (empty capture; expected rows 'time_s,volts')");
  if (t.size() < 2) fail_at(origin, lineno, "one data row: a capture needs at least two samples");
  const double span = t.back() - t.front();
  const double dt = span / static_cast<double>(t.size() - 1);
  if (!std::isfinite(span) || !(dt > 0) || !(1.0 / dt >= 1.0 && 1.0 / dt <= 1e12)) {
    std::ostringstream os;
    os.precision(9);
    os << "time: a span of " << span << " s over " << t.size() - 1
       << " steps is not a sample rate in [1 Hz, 1e12 Hz]";
    fail_at(origin, lines.back(), os.str());
  }
  for (std::size_t n = 0; n < t.size(); ++n) {
    const double grid = t.front() + dt * static_cast<double>(n);
    if (std::abs(t[n] - grid) > 0.02 * dt) {
      std::ostringstream os;
      os.precision(9);
      os << "uneven sampling: time " << t[n] << " s is " << (t[n] - grid) / dt
         << " steps off the uniform grid of step " << dt << " s (tolerance 0.02 step)";
      fail_at(origin, lines[n], os.str());
    }
  }
  c.sample_rate = 1.0 / dt;
  c.t0 = t.front();
  if (!c.meta.empty()) c.meta.source = "csv header";
  c.samples = std::move(v);
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

Capture parse_capture_wav(const std::string& b, const std::string& origin) {
  if (b.empty()) fail_wav(origin, 0, "empty file");
  if (b.size() < 12 || b.compare(0, 4, "RIFF") != 0 || b.compare(8, 4, "WAVE") != 0) {
    fail_wav(origin, 0, "not a RIFF/WAVE file");
  }
  std::size_t at = 12;
  bool have_fmt = false;
  std::uint16_t format = 0, channels = 0, bits = 0;
  std::uint32_t rate = 0;
  while (true) {
    if (at + 8 > b.size()) {
      fail_wav(origin, at, have_fmt ? "truncated: no data chunk" : "truncated: no fmt chunk");
    }
    const std::string id = b.substr(at, 4);
    const std::uint32_t size = le32(b, at + 4);
    const std::size_t body = at + 8;
    if (id == "fmt ") {
      if (size < 16 || body + size > b.size()) fail_wav(origin, at, "truncated or short fmt chunk");
      format = le16(b, body);
      channels = le16(b, body + 2);
      rate = le32(b, body + 4);
      bits = le16(b, body + 14);
      if (format == 0xFFFE) {
        if (size < 40) fail_wav(origin, at, "WAVE_FORMAT_EXTENSIBLE fmt chunk shorter than 40 bytes");
        format = le16(b, body + 24);  // the sub-format GUID starts with the format code
      }
      have_fmt = true;
    } else if (id == "data") {
      if (!have_fmt) fail_wav(origin, at, "data chunk before the fmt chunk");
      if (channels == 0) fail_wav(origin, at, "fmt declares 0 channels");
      if (rate == 0) fail_wav(origin, at, "fmt declares a sample rate of 0");
      const bool pcm = format == 1 && (bits == 16 || bits == 24);
      const bool flt = format == 3 && bits == 32;
      if (!pcm && !flt) {
        fail_wav(origin, at, "unsupported sample format (format " + std::to_string(format) + ", " +
                                 std::to_string(bits) + " bits); valid: 16/24-bit PCM, 32-bit float");
      }
      const std::size_t bytes = bits / 8u, frame = bytes * channels;
      if (body + size > b.size()) {
        fail_wav(origin, at, "truncated: the data chunk declares " + std::to_string(size) +
                                 " bytes, the file holds " + std::to_string(b.size() - body));
      }
      if (size % frame != 0) fail_wav(origin, at, "truncated: data size is not a whole number of frames");
      Capture c;
      c.sample_rate = rate;
      const std::size_t n = size / frame;
      c.samples.resize(n);
      for (std::size_t i = 0; i < n; ++i) {
        const std::size_t p = body + i * frame;
        double x;
        if (flt) {
          const std::uint32_t u = le32(b, p);
          float f;
          std::memcpy(&f, &u, sizeof f);
          if (!std::isfinite(f)) fail_wav(origin, p, "sample " + std::to_string(i) + " is not finite (NaN or Inf)");
          x = f;
        } else if (bits == 16) {
          x = static_cast<std::int16_t>(le16(b, p)) / 32768.0;
        } else {
          std::int32_t s = static_cast<std::int32_t>(static_cast<unsigned char>(b[p]) |
                                                     (static_cast<unsigned char>(b[p + 1]) << 8) |
                                                     (static_cast<unsigned char>(b[p + 2]) << 16));
          if (s & 0x800000) s -= 0x1000000;
          x = s / 8388608.0;
        }
        c.samples[i] = x;
      }
      if (n < 2) fail_wav(origin, at, "the data chunk holds fewer than two samples");
      return c;
    }
    // RIFF chunks are padded to an even size.
    at = body + size + (size & 1u);
  }
}

Capture read_capture(const std::string& path) {
  std::string ext;
  if (const auto dot = path.find_last_of('.'); dot != std::string::npos) ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
  if (ext != "csv" && ext != "wav") {
    throw InputError(path + ": unknown capture type '." + ext + "'; valid: .csv (oscilloscope export), .wav");
  }
  const std::string bytes = read_input_file(path, "capture file", std::size_t{1} << 30);
  Capture c = ext == "csv" ? parse_capture_csv(bytes, path) : parse_capture_wav(bytes, path);
  const std::string sidecar = path.substr(0, path.size() - 4) + ".json";
  std::ifstream js(sidecar, std::ios::binary);
  if (js) {
    std::stringstream sj;
    sj << js.rdbuf();
    const CaptureMeta m = parse_capture_meta_json(sj.str(), sidecar);
    CaptureMeta& o = c.meta;
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
  const int bytes = fmt == WavFormat::Pcm16 ? 2 : fmt == WavFormat::Pcm24 ? 3 : 4;
  const std::uint32_t data = static_cast<std::uint32_t>(c.samples.size() * static_cast<std::size_t>(bytes));
  std::string out;
  auto put = [&](std::uint64_t v, int n) {
    for (int i = 0; i < n; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  out += "RIFF";
  put(36 + data, 4);
  out += "WAVEfmt ";
  put(16, 4);
  put(fmt == WavFormat::Float32 ? 3 : 1, 2);
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
    } else {
      const double scale = fmt == WavFormat::Pcm16 ? 32768.0 : 8388608.0;
      const double q = std::clamp(std::round(x / full_scale * scale), -scale, scale - 1);
      put(static_cast<std::uint64_t>(static_cast<std::int64_t>(q)), bytes);
    }
  }
  return out;
}

// write_file_atomic: model/base/atomic_file.cpp (temporary name in the same folder, renamed).

}  // namespace ranging
