// `ranging filter`: design the bandpass filter (default: the paper's spec, Butterworth) and
// print its second-order sections, pole radii, edge attenuations and quantized coefficients.
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "model/base/error.hpp"
#include "model/dsp/filter_design.hpp"
#include "model/dsp/quantize.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/json_meta.hpp"

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

}  // namespace

int cmd_filter(const Args& args) {
  cli::Parser p("ranging filter",
                "Design the bandpass IIR filter (analog prototype -> bandpass -> bilinear, as\n"
                "scipy/MATLAB) and print its second-order sections. Defaults are the paper's\n"
                "spec (section 3.3.1).");
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
  p.flag("--json", "machine-readable output");
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
    j["quantized"] = {{"bits", bits}, {"frac", frac}, {"columns", {"b0", "b1", "b2", "a1", "a2"}},
                      {"sections", q}};
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
  os << "attenuation at the spec edges:\n";
  const std::pair<const char*, double> edges[] = {
      {"fs1", spec.fs1}, {"fp1", spec.fp1}, {"fp2", spec.fp2}, {"fs2", spec.fs2}};
  for (const auto& [name, f] : edges) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "  %s %12.1f Hz  %10.4f dB\n", name, f,
                  attenuation_db(filter, f));
    os << buf;
  }
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
