// `verilator --lint-only -Wall` is clean on every RTL file: each module with the parameters the
// generator gives it, and every generated top (default and large receiver, the ranging system).
// The modules' parameter defaults are the default configuration's (generated/default/rtl/*.vc):
// a module elaborated on its own is the default design, not a drifting second copy of it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "model/hw/ip_package.hpp"
#include "tests/process.hpp"

namespace {

const std::string kRoot = RANGING_SOURCE_DIR;

void expect_clean(const std::string& args) {
  const auto r = ranging::testing_support::run_command("verilator --lint-only -Wall " + args);
  EXPECT_EQ(r.status, 0) << args << "\n" << r.out << r.err;
  EXPECT_EQ(r.out + r.err, "") << args;
}

const std::string kReceiver = [] {
  std::string files;
  for (const auto& f : ranging::receiver_rtl_sources()) files += " " + kRoot + "/rtl/" + f;
  return files;
}();

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// A Verilog number (decimal, or <size>'h|d|b<digits>) as lower-case hex without leading
// zeros: equal values compare equal whatever their size or base.
std::string canonical(std::string v) {
  v.erase(std::remove(v.begin(), v.end(), '_'), v.end());
  int base = 10;
  std::string digits = v;
  if (const auto q = v.find('\''); q != std::string::npos) {
    const char b = static_cast<char>(std::tolower(v.at(q + 1)));
    base = b == 'h' ? 16 : b == 'b' ? 2 : 10;
    digits = v.substr(q + 2);
  }
  // base conversion on a little-endian vector of hex nibbles
  std::vector<int> nib{0};
  for (char c : digits) {
    const int d = std::isdigit(static_cast<unsigned char>(c)) ? c - '0' : std::tolower(c) - 'a' + 10;
    int carry = d;
    for (int& n : nib) {
      const int x = n * base + carry;
      n = x % 16;
      carry = x / 16;
    }
    while (carry) {
      nib.push_back(carry % 16);
      carry /= 16;
    }
  }
  while (nib.size() > 1 && nib.back() == 0) nib.pop_back();
  std::string out;
  for (auto it = nib.rbegin(); it != nib.rend(); ++it) out += "0123456789abcdef"[*it];
  return out;
}

// NAME -> default value of every parameter in the module's header (comments stripped).
std::map<std::string, std::string> parameter_defaults(const std::string& path, const std::string& module) {
  std::string src = read_file(path);
  src = std::regex_replace(src, std::regex("//[^\n]*"), "");
  const auto start = src.find("module " + module);
  const auto end = src.find(") (", start);
  EXPECT_NE(start, std::string::npos) << path;
  const std::string header = src.substr(start, end - start);
  std::map<std::string, std::string> out;
  const std::regex def("\\b([A-Z][A-Z0-9_]*)\\s*=\\s*([0-9][0-9a-fA-F_'hHdDbB]*)");
  for (auto it = std::sregex_iterator(header.begin(), header.end(), def); it != std::sregex_iterator(); ++it) {
    out[(*it)[1]] = (*it)[2];
  }
  return out;
}

}  // namespace

TEST(RtlDefaults, CanonicalNumbers) {
  EXPECT_EQ(canonical("20"), canonical("32'd20"));
  EXPECT_EQ(canonical("16'h8000"), canonical("32768"));
  EXPECT_EQ(canonical("41'h00000000007"), "7");
  EXPECT_EQ(canonical("8'b1010_0101"), "a5");
  EXPECT_NE(canonical("1005"), canonical("1000"));
}

TEST(RtlDefaults, EqualTheDefaultConfiguration) {
  struct Module {
    std::string file, module, vc;
  };
  const std::vector<Module> modules = {
      {"rtl/bandpass_sos.v", "bandpass_sos", "bandpass_sos"},
      {"rtl/correlator_bank.v", "correlator_bank", "correlator_bank"},
      {"rtl/peak_detector.v", "peak_detector", "peak_detector"},
      {"rtl/ranging_system.v", "ranging_system", "ranging_system"},
      // the Icarus bench passes its parameters through to correlator_bank
      {"tb/correlator_bank_iverilog_tb.v", "correlator_bank_iverilog_tb", "correlator_bank"}};
  for (const Module& mod : modules) {
    const std::string& m = mod.module;
    const auto defaults = parameter_defaults(kRoot + "/" + mod.file, m);
    std::istringstream vc(read_file(kRoot + "/generated/default/rtl/" + mod.vc + ".vc"));
    int checked = 0;
    for (std::string line; std::getline(vc, line);) {
      if (line.rfind("-G", 0) != 0) continue;
      const auto eq = line.find('=');
      const std::string key = line.substr(2, eq - 2), value = line.substr(eq + 1);
      const auto it = defaults.find(key);
      ASSERT_NE(it, defaults.end()) << m << ": parameter " << key << " has no default";
      EXPECT_EQ(canonical(it->second), canonical(value))
          << mod.file << ": default " << key << " = " << it->second << ", the default configuration's is "
          << value << " (generated/default/rtl/" << mod.vc << ".vc)";
      ++checked;
    }
    EXPECT_GT(checked, 5) << m;
  }
}

TEST(RtlLint, EveryModuleOnItsOwnWithItsDefaults) {
  for (const auto& e : std::filesystem::directory_iterator(kRoot + "/rtl")) {
    if (e.path().extension() != ".v") continue;
    const std::string m = e.path().stem().string();
    // ranging_system instantiates the generated receiver top; the others find the modules they
    // instantiate (uart_tx, fx_quantize) in rtl/
    const std::string extra =
        (m == "ranging_system" ? " -y " + kRoot + "/generated/default/rtl" : std::string()) + " -y " + kRoot + "/rtl";
    expect_clean(e.path().string() + extra + " --top-module " + m);
  }
}

TEST(RtlLint, EveryReceiverModuleWithItsGeneratedParameters) {
  for (const char* m : {"bandpass_sos", "correlator_bank", "peak_detector"}) {
    expect_clean("-f " + kRoot + "/generated/default/rtl/" + m + ".vc " + kRoot + "/rtl/" + m + ".v -y " + kRoot +
                 "/rtl --top-module " + m);
  }
}

TEST(RtlLint, GeneratedReceiverTops) {
  for (const char* c : {"default", "large"}) {
    expect_clean(kRoot + "/generated/" + c + "/rtl/receiver_top.v " + kReceiver + " --top-module receiver_top");
  }
}

TEST(RtlLint, GeneratedSystemTop) {
  expect_clean(kRoot + "/generated/default/rtl/ranging_system_top.v " + kRoot + "/generated/default/rtl/receiver_top.v " +
               kReceiver + " " + kRoot + "/rtl/adc_interface.v " + kRoot + "/rtl/tx_scheduler.v " + kRoot +
               "/rtl/tof_distance.v " + kRoot + "/rtl/uart_tx.v " + kRoot + "/rtl/measurement_uart.v " + kRoot +
               "/rtl/ranging_system.v --top-module ranging_system_top");
}
