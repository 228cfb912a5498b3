// rtl/fx_quantize.v against the model's fx_quantize (model/dsp/fixed_point.hpp), bit for bit:
// every input word of small widths, every rounding and overflow mode, shifts of 0, inside and
// beyond the input width, outputs narrower and wider than the rounded value. One Icarus run
// instantiates every parameter set; each set is also linted by Verilator on its own.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "model/dsp/fixed_point.hpp"

using namespace ranging;

namespace {

struct Set {
  int in_w, out_w, shift, rounding, saturate;
};

std::vector<Set> sets() {
  std::vector<Set> v;
  const int shapes[][3] = {{8, 4, 3}, {8, 8, 0}, {6, 8, 2}, {5, 3, 7}, {10, 6, 4}, {9, 2, 1}, {7, 7, 6}};
  for (const auto& s : shapes) {
    for (int r = 0; r < 3; ++r) {
      for (int sat = 0; sat < 2; ++sat) v.push_back({s[0], s[1], s[2], r, sat});
    }
  }
  return v;
}

std::string params(const Set& s) {
  return ".IN_W(" + std::to_string(s.in_w) + "), .OUT_W(" + std::to_string(s.out_w) + "), .SHIFT(" +
         std::to_string(s.shift) + "), .ROUNDING(" + std::to_string(s.rounding) + "), .SATURATE(" +
         std::to_string(s.saturate) + ")";
}

const std::string kRtl = std::string(RANGING_SOURCE_DIR) + "/rtl/fx_quantize.v";
const std::string kWork = std::string(RANGING_TRACE_DIR) + "/tb_fx_quantize_work";

}  // namespace

TEST(FxQuantizeRtl, EveryInputEveryModeBitExactWithTheModel) {
  const auto all = sets();
  std::filesystem::create_directories(kWork);
  // The bench: instance i sweeps x over every IN_W-bit word, printing "i x y fits".
  std::ostringstream v;
  v << "`timescale 1ns/1ps\nmodule fx_quantize_tb;\n";
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Set& s = all[i];
    v << "  reg [" << s.in_w - 1 << ":0] x" << i << ";\n  wire [" << s.out_w - 1 << ":0] y" << i << ";\n  wire f" << i
      << ";\n  fx_quantize #(" << params(s) << ") u" << i << " (.x(x" << i << "), .y(y" << i << "), .fits(f" << i
      << "));\n";
  }
  v << "  integer k;\n  initial begin\n";
  for (std::size_t i = 0; i < all.size(); ++i) {
    v << "    for (k = 0; k < " << (1 << all[i].in_w) << "; k = k + 1) begin x" << i << " = k; #1 $display(\"" << i
      << " %0d %0d %0d\", k, y" << i << ", f" << i << "); end\n";
  }
  v << "    $finish;\n  end\nendmodule\n";
  std::ofstream(kWork + "/fx_quantize_tb.v") << v.str();
  const std::string cmd = "cd " + kWork + " && iverilog -g2012 -Wall -o sim.vvp fx_quantize_tb.v " + kRtl +
                          " > build.log 2>&1 && vvp -n sim.vvp > out.txt 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << "see " << kWork << "/build.log";

  std::ifstream out(kWork + "/out.txt");
  std::vector<std::size_t> seen(all.size(), 0);
  std::size_t i = 0;
  long long x = 0, y = 0, fits = 0;
  std::size_t checked = 0, overflows = 0;
  while (out >> i >> x >> y >> fits) {
    ASSERT_LT(i, all.size());
    const Set& s = all[i];
    // The word as a signed IN_W-bit value, SHIFT fraction bits, into a signed OUT_W-bit integer.
    const std::int64_t sx = x >= (1LL << (s.in_w - 1)) ? x - (1LL << s.in_w) : x;
    FixedFormat fmt;
    fmt.width = s.out_w;
    fmt.frac = 0;
    fmt.rounding = s.rounding == 0 ? Rounding::Truncate : s.rounding == 1 ? Rounding::RoundHalfUp : Rounding::Convergent;
    fmt.overflow = s.saturate ? Overflow::Saturate : Overflow::Wrap;
    OverflowCounter c;
    const std::int64_t want = fx_quantize(sx, s.shift, fmt, &c);
    const std::uint64_t want_bits = static_cast<std::uint64_t>(want) & ((std::uint64_t{1} << s.out_w) - 1);
    ASSERT_EQ(static_cast<std::uint64_t>(y), want_bits)
        << "set " << i << " (" << params(s) << ") x = " << sx << ": model " << want;
    ASSERT_EQ(fits != 0, c.total() == 0) << "set " << i << " (" << params(s) << ") x = " << sx;
    overflows += c.total();
    ++seen[i];
    ++checked;
  }
  for (std::size_t k = 0; k < all.size(); ++k) {
    EXPECT_EQ(seen[k], std::size_t{1} << all[k].in_w) << "set " << k << ": outputs missing (see out.txt)";
  }
  EXPECT_GT(overflows, 0u) << "the sets must exercise the overflow modes";
  std::cout << checked << " words compared over " << all.size() << " parameter sets, " << overflows
            << " of them overflowed\n";
}

TEST(FxQuantizeRtl, VerilatorLintCleanForEverySet) {
  for (const Set& s : sets()) {
    const std::string log = kWork + "/lint.log";
    std::filesystem::create_directories(kWork);
    const std::string cmd = "verilator --lint-only -Wall -GIN_W=" + std::to_string(s.in_w) + " -GOUT_W=" +
                            std::to_string(s.out_w) + " -GSHIFT=" + std::to_string(s.shift) + " -GROUNDING=" +
                            std::to_string(s.rounding) + " -GSATURATE=" + std::to_string(s.saturate) + " " + kRtl +
                            " > " + log + " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << params(s) << ": see " << log;
  }
}
