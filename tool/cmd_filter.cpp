// `ranging filter`: design the bandpass filter (default: the paper's spec, Butterworth) and
// print its second-order sections, pole radii, edge attenuations and quantized coefficients,
// and the guard's verdict on the quantized design (model/dsp/stability.hpp): its exact pole
// radii and attenuations beside the float design's; exit 2 if it is unstable or out of spec
// unless --allow-out-of-spec. --plot draws |H(f)| float vs quantized over the spec mask
// (scripts/plot_filter_response.py; the numbers are computed here).
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "model/base/subprocess.hpp"
#include "model/base/error.hpp"
#include "model/dsp/filter_design.hpp"
#include "model/dsp/quantize.hpp"
#include "model/dsp/stability.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/guard.hpp"
#include "tool/json_meta.hpp"
#include "tool/options.hpp"

namespace ranging::tool {
namespace {

std::string g17(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The model names spec fields (a leading "fp2, fs2:" list); the user typed options.
[[noreturn]] void rethrow_as_option(const InputError& e) {
  static const std::pair<std::string_view, const char*> kMap[] = {
      {"fp1", "--fp1"},  {"fp2", "--fp2"}, {"fs1", "--fs1"}, {"fs2", "--fs2"},
      {"rp_db", "--rp"}, {"rs_db", "--rs"}, {"fs", "--fs"},   {"order", "--order"}};
  const std::string msg = e.what();
  const size_t colon = msg.find(':');
  std::string options;
  std::string_view fields = std::string_view(msg).substr(0, colon == std::string::npos ? 0 : colon);
  while (!fields.empty()) {
    const size_t comma = fields.find(", ");
    const std::string_view f = fields.substr(0, comma);
    for (const auto& [name, opt] : kMap) {
      if (f == name) options += (options.empty() ? "" : "/") + std::string(opt);
    }
    fields = comma == std::string_view::npos ? std::string_view{} : fields.substr(comma + 2);
  }
  if (options.empty()) throw e;
  throw InputError("option " + options + ": " + msg.substr(colon + 2));
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& f : v) s += (s.empty() ? "" : "; ") + f;
  return s;
}

// |H(f)| of the float and the quantized design on a grid, written as JSON for the plot
// script; the PNG appears under its name only when the script succeeded.
void plot_response(const std::string& png, const SosFilter& filter, const SosFilter& quantized,
                   const BandpassSpec& spec, int bits, int frac) {
  namespace fs = std::filesystem;
  nlohmann::ordered_json j;
  const double fmax = std::min(spec.fs / 2, 2 * spec.fs2);
  std::vector<double> f, af, aq;
  constexpr int kPoints = 2001;
  for (int i = 0; i < kPoints; ++i) {
    const double fr = fmax * i / (kPoints - 1);
    f.push_back(fr);
    af.push_back(20 * std::log10(std::max(std::abs(sos_response(filter, fr)), 1e-12)));
    aq.push_back(20 * std::log10(std::max(std::abs(sos_response(quantized, fr)), 1e-12)));
  }
  j["f"] = f;
  j["float_db"] = af;
  j["quantized_db"] = aq;
  j["spec"] = {{"fp1", spec.fp1}, {"fp2", spec.fp2}, {"fs1", spec.fs1}, {"fs2", spec.fs2},
               {"rp_db", spec.rp_db}, {"rs_db", spec.rs_db}, {"fs", spec.fs}};
  j["title"] = filter_type_name(filter.type) + " order " + std::to_string(filter.order) + ", coefficients " +
               std::to_string(bits) + " bits (" + std::to_string(frac) + " fraction)";
  const std::string data = png + ".data.json", tmp = png + ".tmp";
  {
    std::ofstream out(data);
    out << j.dump() << "\n";
    if (!out) throw InputError("option --plot: cannot write '" + data + "'");
  }
  std::string script = (fs::path(__FILE__).parent_path().parent_path() / "scripts/plot_filter_response.py").string();
  if (!fs::exists(script)) script = "scripts/plot_filter_response.py";
  const std::string cmd = "/usr/bin/python3 '" + script + "' '" + data + "' '" + tmp + "' > /dev/null";
  const int rc = run_shell(cmd);
  std::error_code ec;
  fs::remove(data, ec);
  if (rc != 0) {
    fs::remove(tmp, ec);
    throw InputError("option --plot: '" + cmd + "' failed (matplotlib missing?)");
  }
  fs::rename(tmp, png, ec);
  if (ec) throw InputError("option --plot: cannot write '" + png + "': " + ec.message());
}

}  // namespace

int cmd_filter(const Args& args) {
  cli::Parser p = command_parser("filter");
  p.option("--type", "TYPE", "butter | cheby1 | ellip", "butter");
  p.option("--fp1", "HZ", "lower passband edge", "150000");
  p.option("--fp2", "HZ", "upper passband edge", "250000");
  p.option("--fs1", "HZ", "lower stopband edge", "50000");
  p.option("--fs2", "HZ", "upper stopband edge", "350000");
  p.option("--rp", "DB", "maximum passband attenuation", "2");
  p.option("--rs", "DB", "minimum stopband attenuation", "30");
  p.option("--fs", "HZ", "sample rate", "5000000");
  p.option("--order", "N", "prototype order, 1..20 (default: the minimum meeting the spec)");
  p.option("--coef-bits", "B", "coefficient word length, 2..32", "16");
  p.option("--coef-frac", "F", "coefficient fraction bits, 0..62 (default: B-2)");
  p.option("--plot", "FILE.png", "draw |H(f)| of the float and the quantized design over the spec mask");
  p.flag("--allow-out-of-spec", "print a design whose quantized filter is unstable or out of spec (exit 0)");
  add_output_options(p, {.json = true});
  if (!p.parse(args)) return 0;

  const FilterType type = [&] {
    try {
      return parse_filter_type(p.get_or("--type", "butter"));
    } catch (const InputError& e) {
      throw InputError(std::string("option --type: ") + e.what());
    }
  }();
  constexpr double kBig = 1e12;
  BandpassSpec spec;
  spec.fp1 = p.number("--fp1", spec.fp1, 0, kBig);
  spec.fp2 = p.number("--fp2", spec.fp2, 0, kBig);
  spec.fs1 = p.number("--fs1", spec.fs1, 0, kBig);
  spec.fs2 = p.number("--fs2", spec.fs2, 0, kBig);
  spec.rp_db = p.number("--rp", spec.rp_db, 0, 1000);
  spec.rs_db = p.number("--rs", spec.rs_db, 0, 1000);
  spec.fs = p.number("--fs", spec.fs, 0, kBig);
  const int bits = static_cast<int>(p.integer("--coef-bits", 16, 2, 32));
  const int frac = static_cast<int>(p.integer("--coef-frac", bits - 2, 0, 62));

  SosFilter filter;
  std::vector<double> wn;
  try {
    validate(spec);
    filter = p.has("--order")
                 ? design_bandpass(spec, type,
                                   static_cast<int>(p.integer("--order", 0, 1, kMaxFilterOrder)))
                 : design_bandpass(spec, type);
    wn = natural_frequencies(spec, type, filter.order);
  } catch (const InputError& e) {
    rethrow_as_option(e);
  }

  // Quantize everything before printing anything, so a misfit leaves stdout empty.
  std::vector<std::vector<std::int64_t>> q;
  for (size_t k = 0; k < filter.sections.size(); ++k) {
    const Biquad& s = filter.sections[k];
    const std::string where = "option --coef-bits/--coef-frac: section " + std::to_string(k + 1);
    q.push_back({quantize_coefficient(s.b0, bits, frac, where + " b0"),
                 quantize_coefficient(s.b1, bits, frac, where + " b1"),
                 quantize_coefficient(s.b2, bits, frac, where + " b2"),
                 quantize_coefficient(s.a1, bits, frac, where + " a1"),
                 quantize_coefficient(s.a2, bits, frac, where + " a2")});
  }
  double gain = 1;
  for (const Biquad& s : filter.sections) gain *= s.b0;

  // The guard: the quantized integers' exact poles and response against the spec.
  const DesignGuard guard = check_quantized_design(filter, QuantizedSos{q, frac}, spec, bits);
  if (!guard.ok() && !p.has("--allow-out-of-spec")) {
    const std::string hint = " (tolerance " + g17(guard.tolerance_db) + " dB; --allow-out-of-spec prints it anyway)";
    if (!guard.float_within_spec) {
      throw InputError("option --order: " + (p.has("--order") ? *p.get("--order") : std::string("minimum")) +
                       ": the unquantized design misses the spec: " + joined(guard.float_failures) + hint);
    }
    throw InputError("option --coef-bits: " + std::to_string(bits) + " (--coef-frac " + std::to_string(frac) +
                     "): " + joined(guard.failures) + hint);
  }
  const SosFilter quantized = quantized_sos_filter(QuantizedSos{q, frac}, filter);
  if (auto png = p.get("--plot"); png && p.has("--plot")) plot_response(*png, filter, quantized, spec, bits, frac);

  if (p.has("--json")) {
    nlohmann::ordered_json j;
    j["type"] = filter_type_name(type);
    j["order"] = filter.order;
    // An integral sample rate prints as an integer ("fs": 5000000), as in the contract.
    if (filter.fs == static_cast<double>(static_cast<std::int64_t>(filter.fs))) {
      j["fs"] = static_cast<std::int64_t>(filter.fs);
    } else {
      j["fs"] = filter.fs;
    }
    nlohmann::ordered_json sos = nlohmann::ordered_json::array();
    nlohmann::ordered_json radius = nlohmann::ordered_json::array();
    for (const Biquad& s : filter.sections) {
      sos.push_back({s.b0, s.b1, s.b2, 1.0, s.a1, s.a2});
      radius.push_back(pole_radius(s));
    }
    j["sos"] = sos;
    j["pole_radius"] = radius;
    j["natural_frequencies"] = wn;
    j["gain"] = gain;
    nlohmann::ordered_json qradius = nlohmann::ordered_json::array();
    for (const SectionPoles& sp : guard.quantized_poles) qradius.push_back(static_cast<double>(sp.radius));
    j["quantized"] = {{"bits", bits}, {"frac", frac}, {"columns", {"b0", "b1", "b2", "a1", "a2"}},
                      {"sections", q}, {"pole_radius", qradius}};
    j["guard"] = guard_json(guard, filter.order);
    std::cout << stamp_build_info(j).dump() << "\n";
    return 0;
  }

  std::ostringstream os;
  os << "bandpass filter: " << filter_type_name(type) << ", prototype order " << filter.order
     << " (" << 2 * filter.order << " poles), " << filter.sections.size()
     << " second-order sections, fs = " << g17(filter.fs) << " Hz\n";
  os << "spec: passband " << g17(spec.fp1) << " .. " << g17(spec.fp2) << " Hz within "
     << g17(spec.rp_db) << " dB, stopbands <= " << g17(spec.fs1) << " and >= " << g17(spec.fs2)
     << " Hz at least " << g17(spec.rs_db) << " dB down\n";
  os << "natural frequencies: " << g17(wn[0]) << " Hz, " << g17(wn[1]) << " Hz\n\n";
  os << "sections, input first: H_k(z) = (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2)\n";
  for (size_t k = 0; k < filter.sections.size(); ++k) {
    const Biquad& s = filter.sections[k];
    os << "  " << k + 1 << ": b0 " << g17(s.b0) << "  b1 " << g17(s.b1) << "  b2 " << g17(s.b2)
       << "  a1 " << g17(s.a1) << "  a2 " << g17(s.a2) << "  pole radius " << g17(pole_radius(s))
       << "\n";
  }
  os << "overall gain (product of b0): " << g17(gain) << "\n\n";
  os << "pole radius per section, float design vs quantized (" << bits << "-bit, " << frac
     << " fraction bits; exact roots of the integer quadratic):\n";
  for (size_t k = 0; k < filter.sections.size(); ++k) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "  %zu: %.9f  %.9f%s\n", k + 1, guard.float_radius[k],
                  static_cast<double>(guard.quantized_poles[k].radius),
                  guard.quantized_poles[k].stable ? "" : "  UNSTABLE (>= 1)");
    os << buf;
  }
  os << "\nattenuation at the spec edges, float vs quantized:\n";
  const std::pair<const char*, double> edges[] = {
      {"fs1", spec.fs1}, {"fp1", spec.fp1}, {"fp2", spec.fp2}, {"fs2", spec.fs2}};
  for (const auto& [name, f] : edges) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "  %s %12.1f Hz  %10.4f dB  %10.4f dB\n", name, f,
                  attenuation_db(filter, f), attenuation_db(quantized, f));
    os << buf;
  }
  {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "  worst in the passband: %.4f dB (%.0f Hz) vs %.4f dB (%.0f Hz), spec <= %g dB\n"
                  "  worst in the stopbands: %.4f dB (%.0f Hz) vs %.4f dB (%.0f Hz), spec >= %g dB\n",
                  guard.passband.float_db, guard.passband.float_f, guard.passband.quantized_db,
                  guard.passband.quantized_f, spec.rp_db, guard.stopband.float_db, guard.stopband.float_f,
                  guard.stopband.quantized_db, guard.stopband.quantized_f, spec.rs_db);
    os << buf;
  }
  os << "quantized design: "
     << (guard.ok() ? std::string("stable and within spec")
                    : "REFUSED without --allow-out-of-spec: " +
                          joined(guard.float_within_spec ? guard.failures : guard.float_failures))
     << " (tolerance " << g17(guard.tolerance_db) << " dB)\n";
  os << "\nquantized coefficients (" << bits << "-bit signed, " << frac
     << " fraction bits, round to nearest): b0 b1 b2 a1 a2\n";
  for (size_t k = 0; k < q.size(); ++k) {
    os << "  " << k + 1 << ":";
    for (std::int64_t v : q[k]) os << " " << v;
    os << "\n";
  }
  std::cout << os.str();
  return 0;
}

}  // namespace ranging::tool
