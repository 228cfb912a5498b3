// Code generators: the paper's printed tables, m-sequence and Gold-code properties from
// theory (not from the implementation), input refusal, and the `ranging codes` CLI.
#include <gtest/gtest.h>

#include "tests/process.hpp"
#include <sys/wait.h>

#include <algorithm>
#include <bit>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "model/dsp/codes.hpp"
#include "model/base/error.hpp"
#include "tool/build_info.hpp"

using ranging::Code;
using ranging::InputError;

namespace {

// ---------------------------------------------------------------------------------------------
// Every row printed in Tables 1-3 of Lu et al. 2025, copied as printed.
struct Row {
  const char* family;
  int j;
  Code chips;
};

const std::vector<Row>& printed_rows() {
  static const std::vector<Row> rows = {
      // Table 1 (all rows)
      {"M1", 1, {1, 0, 1, 1, 1, 0, 0}}, {"M2", 1, {1, 0, 1, 0, 0, 1, 1}},
      {"M1", 2, {0, 1, 1, 1, 0, 0, 1}}, {"M2", 2, {0, 1, 0, 0, 1, 1, 1}},
      {"M1", 3, {1, 1, 1, 0, 0, 1, 0}}, {"M2", 3, {1, 0, 0, 1, 1, 1, 0}},
      {"M1", 4, {1, 1, 0, 0, 1, 0, 1}}, {"M2", 4, {0, 0, 1, 1, 1, 0, 1}},
      {"M1", 5, {1, 0, 0, 1, 0, 1, 1}}, {"M2", 5, {0, 1, 1, 1, 0, 1, 0}},
      {"M1", 6, {0, 0, 1, 0, 1, 1, 1}}, {"M2", 6, {1, 1, 1, 0, 1, 0, 0}},
      {"M1", 7, {0, 1, 0, 1, 1, 1, 0}}, {"M2", 7, {1, 1, 0, 1, 0, 0, 1}},
      // Table 2 (rows j = 1, 2, 3, 13, 14, 15)
      {"M3", 1, {1, 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 0, 0, 0}},
      {"M4", 1, {1, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 0, 1, 0, 1}},
      {"M3", 2, {0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 0, 0, 0, 1}},
      {"M4", 2, {0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 0, 1, 0, 1, 1}},
      {"M3", 3, {0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 0, 0, 0, 1, 0}},
      {"M4", 3, {0, 1, 0, 0, 0, 1, 1, 1, 1, 0, 1, 0, 1, 1, 0}},
      {"M3", 13, {0, 0, 0, 1, 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1}},
      {"M4", 13, {1, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 0}},
      {"M3", 14, {0, 0, 1, 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 0}},
      {"M4", 14, {0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 0, 1}},
      {"M3", 15, {0, 1, 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 0, 0}},
      {"M4", 15, {1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 0, 1, 0}},
      // Table 3 (columns Gold1, Gold2, Gold6, Gold7; rows j = 1, 2, 3, 7, 8, 9)
      {"Gold1", 1, {1, 0, 1, 1, 1, 0, 0}}, {"Gold2", 1, {0, 1, 1, 1, 0, 0, 1}},
      {"Gold6", 1, {0, 0, 1, 0, 1, 1, 1}}, {"Gold7", 1, {0, 1, 0, 1, 1, 1, 0}},
      {"Gold1", 2, {1, 0, 1, 0, 0, 1, 1}}, {"Gold2", 2, {0, 1, 0, 0, 1, 1, 1}},
      {"Gold6", 2, {1, 1, 1, 0, 1, 0, 0}}, {"Gold7", 2, {1, 1, 0, 1, 0, 0, 1}},
      {"Gold1", 3, {0, 0, 0, 1, 1, 1, 1}}, {"Gold2", 3, {0, 0, 1, 1, 1, 1, 0}},
      {"Gold6", 3, {1, 1, 0, 0, 0, 1, 1}}, {"Gold7", 3, {1, 0, 0, 0, 1, 1, 1}},
      {"Gold1", 7, {1, 1, 0, 0, 1, 1, 0}}, {"Gold2", 7, {1, 0, 0, 1, 1, 0, 1}},
      {"Gold6", 7, {1, 0, 1, 1, 0, 0, 1}}, {"Gold7", 7, {0, 1, 1, 0, 0, 1, 1}},
      {"Gold1", 8, {0, 1, 0, 1, 0, 0, 0}}, {"Gold2", 8, {1, 0, 1, 0, 0, 0, 0}},
      {"Gold6", 8, {0, 0, 0, 1, 0, 1, 0}}, {"Gold7", 8, {0, 0, 1, 0, 1, 0, 0}},
      {"Gold1", 9, {0, 1, 1, 0, 1, 0, 1}}, {"Gold2", 9, {1, 1, 0, 1, 0, 1, 0}},
      {"Gold6", 9, {0, 1, 0, 1, 1, 0, 1}}, {"Gold7", 9, {1, 0, 1, 1, 0, 1, 0}},
  };
  return rows;
}

// Codes as strings for std::set (GCC 12 warns falsely on set<vector<uint8_t>> comparisons).
std::string key(const Code& c) { return std::string(c.begin(), c.end()); }

std::set<std::string> keys(const std::vector<Code>& codes) {
  std::set<std::string> out;
  for (const Code& c : codes) out.insert(key(c));
  return out;
}

std::uint64_t period_of(int n) { return (std::uint64_t{1} << n) - 1; }

// Independent rotation (paper: code j = code 1 shifted left by j-1).
Code rotl(const Code& c, std::size_t k) {
  Code out(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) out[i] = c[(i + k) % c.size()];
  return out;
}

// Euler's totient by trial division: the number of primitive polynomials of degree n is
// phi(2^n - 1) / n.
std::uint64_t totient(std::uint64_t m) {
  std::uint64_t result = m;
  for (std::uint64_t p = 2; p * p <= m; ++p) {
    if (m % p != 0) continue;
    while (m % p == 0) m /= p;
    result -= result / p;
  }
  if (m > 1) result -= result / m;
  return result;
}

// Bit-packed codes for fast all-pairs Gold correlation: bits hold the code twice so that any
// cyclic window of N bits is contiguous.
struct Packed {
  std::size_t n = 0;
  std::vector<std::uint64_t> bits;
  explicit Packed(const Code& c) : n(c.size()), bits((2 * c.size()) / 64 + 2, 0) {
    for (std::size_t i = 0; i < 2 * n; ++i) {
      if (c[i % n]) bits[i / 64] |= std::uint64_t{1} << (i % 64);
    }
  }
  std::uint64_t word_at(std::size_t pos) const {
    const std::size_t w = pos / 64, off = pos % 64;
    std::uint64_t v = bits[w] >> off;
    if (off != 0) v |= bits[w + 1] << (64 - off);
    return v;
  }
};

// sum (+-1)a[i] (+-1)b[(i + shift) mod N] = N - 2 * (number of disagreeing chips).
int packed_correlation(const Packed& a, const Packed& b, std::size_t shift) {
  std::size_t disagree = 0;
  for (std::size_t i = 0; i < a.n; i += 64) {
    std::uint64_t x = a.word_at(i) ^ b.word_at(i + shift);
    const std::size_t valid = std::min<std::size_t>(64, a.n - i);
    if (valid < 64) x &= (std::uint64_t{1} << valid) - 1;
    disagree += static_cast<std::size_t>(std::popcount(x));
  }
  return static_cast<int>(a.n) - 2 * static_cast<int>(disagree);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The paper's tables.

TEST(PaperTables, EveryPrintedRowIsReproduced) {
  std::map<std::string, ranging::CodeFamily> fams;
  for (const Row& r : printed_rows()) {
    if (!fams.count(r.family)) fams.emplace(r.family, ranging::code_family(r.family));
    const ranging::CodeFamily& f = fams.at(r.family);
    ASSERT_LE(r.j, f.eta()) << r.family;
    EXPECT_EQ(f.codes[static_cast<std::size_t>(r.j - 1)], r.chips) << r.family << " j=" << r.j;
  }
  EXPECT_EQ(printed_rows().size(), 14U + 12U + 24U);
}

TEST(PaperTables, FamilySizesAndShiftRule) {
  const std::map<std::string, std::pair<int, int>> sizes = {
      {"M1", {7, 7}}, {"M2", {7, 7}}, {"M3", {15, 15}}, {"M4", {15, 15}}};
  for (const auto& [name, le] : sizes) {
    const ranging::CodeFamily f = ranging::code_family(name);
    EXPECT_EQ(f.name, name);
    EXPECT_EQ(f.length, le.first);
    EXPECT_EQ(f.eta(), le.second);
    for (int j = 1; j <= f.eta(); ++j) {
      EXPECT_EQ(f.codes[static_cast<std::size_t>(j - 1)],
                rotl(f.codes[0], static_cast<std::size_t>(j - 1)))
          << name << " j=" << j;
    }
  }
  const ranging::CodeFamily g1 = ranging::code_family("Gold1");
  for (int i = 1; i <= 7; ++i) {
    const ranging::CodeFamily g = ranging::code_family("Gold" + std::to_string(i));
    EXPECT_EQ(g.length, 7);
    ASSERT_EQ(g.eta(), 9);
    for (std::size_t j = 0; j < 9; ++j) {
      EXPECT_EQ(g.codes[j], rotl(g1.codes[j], static_cast<std::size_t>(i - 1))) << i << " " << j;
    }
  }
}

// NOTES.md: M2 is the reverse of M1 and M4 the reverse of M3 -- as sets of cyclic shifts; the
// printed first codes are not the literal reversal (reverse(M1-1) is M2 j=4).
TEST(PaperTables, ReciprocalFamiliesAreTimeReversals) {
  for (const auto& [a, b] : {std::pair{"M1", "M2"}, std::pair{"M3", "M4"}}) {
    const auto fa = ranging::code_family(a);
    const auto fb = ranging::code_family(b);
    std::set<std::string> reversed;
    for (Code c : fa.codes) {
      std::reverse(c.begin(), c.end());
      reversed.insert(key(c));
    }
    EXPECT_EQ(reversed, keys(fb.codes)) << a << " vs " << b;
  }
  Code r = ranging::code_family("M1").codes[0];
  std::reverse(r.begin(), r.end());
  EXPECT_EQ(r, ranging::code_family("M2").codes[3]);
  r = ranging::code_family("M3").codes[0];
  std::reverse(r.begin(), r.end());
  EXPECT_EQ(r, ranging::code_family("M4").codes[4]);
}

// The paper's bases come straight out of msequence() (phase: first chips 1, 0, ..., 0, 1).
TEST(PaperTables, BasesAreLfsrMsequences) {
  EXPECT_EQ(ranging::msequence(3, 0xB), (Code{1, 0, 1, 1, 1, 0, 0}));
  EXPECT_EQ(ranging::msequence(3, 0xD), (Code{1, 0, 1, 0, 0, 1, 1}));
  EXPECT_EQ(ranging::msequence(4, 0x13), (Code{1, 0, 0, 1, 1, 0, 1, 0, 1, 1, 1, 1, 0, 0, 0}));
  EXPECT_EQ(ranging::msequence(4, 0x19), (Code{1, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 0, 1, 0, 1}));
  // Gold1 is the generic Gold set of degree 3 (preferred pair = the paper's M1/M2 polynomials).
  EXPECT_EQ(ranging::preferred_pair(3), (std::pair<std::uint32_t, std::uint32_t>{0xB, 0xD}));
  EXPECT_EQ(ranging::gold_codes(3), ranging::code_family("Gold1").codes);
  EXPECT_EQ(ranging::code_family("gold-3").codes, ranging::code_family("Gold1").codes);
}

// ---------------------------------------------------------------------------------------------
// m-sequence properties, checked from theory for the default polynomials of degree 2..16.

TEST(Msequence, FullPeriodRecurrenceAndBalance) {
  for (int n = 2; n <= 16; ++n) {
    const std::uint32_t poly = ranging::default_primitive_polynomial(n);
    EXPECT_EQ(poly >> n, 1U) << n;
    EXPECT_EQ(poly & 1U, 1U) << n;
    const Code s = ranging::msequence(n, poly);
    const std::size_t N = period_of(n);
    ASSERT_EQ(s.size(), N) << n;
    // One period of the LFSR: the recurrence of `poly` holds cyclically, across the wrap.
    for (std::size_t i = 0; i < N; ++i) {
      std::uint8_t fb = 0;
      for (int k = 0; k < n; ++k) {
        if ((poly >> k) & 1U) fb ^= s[(i + static_cast<std::size_t>(k)) % N];
      }
      ASSERT_EQ(s[(i + static_cast<std::size_t>(n)) % N], fb) << "n=" << n << " i=" << i;
    }
    // ... and no smaller period: not periodic with any proper divisor of N.
    for (std::size_t d = 1; d < N; ++d) {
      if (N % d != 0) continue;
      bool periodic = true;
      for (std::size_t i = 0; i < N && periodic; ++i) periodic = s[i] == s[(i + d) % N];
      EXPECT_FALSE(periodic) << "n=" << n << " has period " << d;
    }
    const auto ones = static_cast<std::size_t>(std::count(s.begin(), s.end(), std::uint8_t{1}));
    EXPECT_EQ(ones, std::size_t{1} << (n - 1)) << n;
    for (std::uint8_t c : s) ASSERT_LE(c, 1) << n;
  }
}

TEST(Msequence, TwoValuedAutocorrelation) {
  for (int n = 2; n <= 16; ++n) {
    const Code s = ranging::msequence(n, ranging::default_primitive_polynomial(n));
    const int N = static_cast<int>(s.size());
    EXPECT_EQ(ranging::periodic_correlation(s, s, 0), N);
    EXPECT_EQ(ranging::periodic_correlation(s, s, N), N);
    std::vector<int> shifts;
    if (n <= 12) {
      for (int k = 1; k < N; ++k) shifts.push_back(k);
    } else {
      for (int k = 1; k < N; k += N / 61) shifts.push_back(k);  // ~61 spread shifts
      shifts.push_back(N - 1);
      shifts.push_back(-1);
    }
    for (int k : shifts) {
      ASSERT_EQ(ranging::periodic_correlation(s, s, k), -1) << "n=" << n << " shift=" << k;
    }
  }
}

TEST(Msequence, GenericFamilyIsShiftsOfTheDefaultSequence) {
  for (int n = 2; n <= 10; ++n) {
    const auto f = ranging::code_family("mseq-" + std::to_string(n));
    const Code base = ranging::msequence(n, ranging::default_primitive_polynomial(n));
    ASSERT_EQ(f.eta(), static_cast<int>(period_of(n)));
    EXPECT_EQ(f.length, static_cast<int>(period_of(n)));
    // All eta codes distinct, each the base rotated left by j-1.
    EXPECT_EQ(keys(f.codes).size(), f.codes.size());
    for (std::size_t j = 0; j < f.codes.size(); j += 1 + f.codes.size() / 17) {
      EXPECT_EQ(f.codes[j], rotl(base, j)) << n << " " << j;
    }
  }
  EXPECT_EQ(ranging::code_family("mseq-3").codes, ranging::code_family("M1").codes);
  EXPECT_EQ(ranging::code_family("mseq-4").codes, ranging::code_family("M3").codes);
}

// ---------------------------------------------------------------------------------------------
// Primitive polynomials.

TEST(Primitive, CountMatchesTotientFormula) {
  // Brute force over every mask of exact degree n with constant term: the number of primitive
  // ones must be phi(2^n - 1) / n, and every one of them gives a full-period sequence.
  for (int n = 2; n <= 14; ++n) {
    std::uint64_t count = 0;
    for (std::uint32_t poly = (1U << n) | 1U; poly < (2U << n); poly += 2) {
      if (ranging::is_primitive_polynomial(n, poly)) ++count;
    }
    EXPECT_EQ(count, totient(period_of(n)) / static_cast<std::uint64_t>(n)) << "n=" << n;
  }
  for (int n = 2; n <= 16; ++n) {
    EXPECT_TRUE(ranging::is_primitive_polynomial(n, ranging::default_primitive_polynomial(n))) << n;
  }
}

TEST(Primitive, RefusesNonPrimitive) {
  // x^4 + x^2 + 1 = (x^2 + x + 1)^2: reducible.
  EXPECT_FALSE(ranging::is_primitive_polynomial(4, 0x15));
  // x^4 + x^3 + x^2 + x + 1: irreducible but x has order 5, not 15.
  EXPECT_FALSE(ranging::is_primitive_polynomial(4, 0x1F));
  EXPECT_FALSE(ranging::is_primitive_polynomial(4, 0x11));   // x^4 + 1
  EXPECT_FALSE(ranging::is_primitive_polynomial(4, 0x12));   // no constant term
  EXPECT_FALSE(ranging::is_primitive_polynomial(4, 0xB));    // degree 3, not 4
  EXPECT_FALSE(ranging::is_primitive_polynomial(3, 0x13));   // degree 4, not 3
  EXPECT_FALSE(ranging::is_primitive_polynomial(3, 0));
  EXPECT_FALSE(ranging::is_primitive_polynomial(6, 0x49));   // x^6 + x^3 + 1: irreducible, order 9
  EXPECT_FALSE(ranging::is_primitive_polynomial(2, 0x5));    // x^2 + 1 = (x + 1)^2
  EXPECT_TRUE(ranging::is_primitive_polynomial(4, 0x19));    // x^4 + x^3 + 1
  for (std::uint32_t bad : {0x15U, 0x1FU, 0x11U, 0x12U, 0xBU}) {
    EXPECT_THROW(ranging::msequence(4, bad), InputError) << bad;
  }
  for (int degree : {-1, 0, 1, 17, 32}) {
    EXPECT_THROW(ranging::msequence(degree, 0x3), InputError) << degree;
    EXPECT_THROW(ranging::is_primitive_polynomial(degree, 0x3), InputError) << degree;
    EXPECT_THROW(ranging::default_primitive_polynomial(degree), InputError) << degree;
  }
  try {
    ranging::msequence(17, 0x20009);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("[2, 16]"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------------
// Gold codes: three-valued correlation {-1, -t(n), t(n) - 2}, t(n) = 1 + 2^floor((n+2)/2).

TEST(Gold, PackedCorrelationAgreesWithPeriodicCorrelation) {
  const auto codes = ranging::gold_codes(5);
  std::vector<Packed> packed;
  for (const Code& c : codes) packed.emplace_back(c);
  for (std::size_t a = 0; a < codes.size(); a += 3) {
    for (std::size_t b = 0; b < codes.size(); ++b) {
      for (int s = 0; s < 31; ++s) {
        ASSERT_EQ(packed_correlation(packed[a], packed[b], static_cast<std::size_t>(s)),
                  ranging::periodic_correlation(codes[a], codes[b], s));
      }
    }
  }
}

TEST(Gold, ThreeValuedCorrelationForAllPairs) {
  for (int n : {3, 5, 6, 7, 9, 10}) {
    const auto codes = ranging::gold_codes(n);
    const std::size_t N = period_of(n);
    ASSERT_EQ(codes.size(), N + 2) << n;
    const int t = 1 + (1 << ((n + 2) / 2));
    const std::set<int> allowed = {-1, -t, t - 2};
    std::vector<Packed> packed;
    for (const Code& c : codes) {
      ASSERT_EQ(c.size(), N);
      packed.emplace_back(c);
    }
    EXPECT_EQ(keys(codes).size(), codes.size()) << n;

    std::set<int> seen;
    std::uint64_t lcg = 12345;
    for (std::size_t a = 0; a < codes.size(); ++a) {
      for (std::size_t b = a; b < codes.size(); ++b) {
        std::vector<std::size_t> shifts;
        if (n <= 7) {
          for (std::size_t s = 0; s < N; ++s) shifts.push_back(s);
        } else {  // big sets: shift 0, 1 and two pseudo-random shifts per pair
          lcg = lcg * 6364136223846793005ULL + 1442695040888963407ULL;
          shifts = {0, 1, (lcg >> 33) % N, (lcg >> 13) % N};
        }
        for (std::size_t s : shifts) {
          if (a == b && s == 0) continue;  // the autocorrelation peak
          const int r = packed_correlation(packed[a], packed[b], s);
          seen.insert(r);
          if (!allowed.count(r)) {
            FAIL() << "n=" << n << " codes " << a << "," << b << " shift " << s << ": " << r;
          }
        }
      }
    }
    EXPECT_EQ(seen, allowed) << "n=" << n;  // all three values occur
  }
}

TEST(Gold, RefusesBadDegrees) {
  for (int degree : {1, 2, 4, 8, 12, 16, 17}) {
    EXPECT_THROW(ranging::preferred_pair(degree), InputError) << degree;
  }
  for (int degree : {2, 4, 8, 12, 13}) EXPECT_THROW(ranging::gold_codes(degree), InputError) << degree;
  for (int n : {3, 5, 6, 7, 9, 10, 11, 13, 14, 15}) {
    const auto [f, g] = ranging::preferred_pair(n);
    EXPECT_NE(f, g);
    EXPECT_TRUE(ranging::is_primitive_polynomial(n, f));
    EXPECT_TRUE(ranging::is_primitive_polynomial(n, g));
  }
}

// ---------------------------------------------------------------------------------------------
// Correlation, names and errors.

TEST(Correlation, HandWorkedValuesAndShiftWrap) {
  const Code a = {1, 0, 1}, b = {1, 1, 0};
  // a' = (+1, -1, +1); b' shifted by 1 = (b'1, b'2, b'0) = (+1, -1, +1): sum 3.
  EXPECT_EQ(ranging::periodic_correlation(a, b, 1), 3);
  // shift 0: (+1)(+1) + (-1)(+1) + (+1)(-1) = -1.
  EXPECT_EQ(ranging::periodic_correlation(a, b, 0), -1);
  EXPECT_EQ(ranging::periodic_correlation(a, b, -2), 3);
  EXPECT_EQ(ranging::periodic_correlation(a, b, 7), 3);
  EXPECT_THROW(ranging::periodic_correlation(a, Code{1, 0}, 0), InputError);
  EXPECT_THROW(ranging::periodic_correlation(Code{}, Code{}, 0), InputError);
}

TEST(Families, NamesAndErrors) {
  const auto names = ranging::code_family_names();
  const std::vector<std::string> paper = {"M1",    "M2",    "M3",    "M4",    "Gold1", "Gold2",
                                          "Gold3", "Gold4", "Gold5", "Gold6", "Gold7"};
  ASSERT_GE(names.size(), paper.size());
  EXPECT_TRUE(std::equal(paper.begin(), paper.end(), names.begin()));
  for (const char* n : {"mseq-2", "mseq-10", "gold-3", "gold-10"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
  }
  for (const std::string& n : names) {
    const auto f = ranging::code_family(n);
    EXPECT_EQ(f.name, n);
    EXPECT_GT(f.eta(), 0) << n;
    for (const Code& c : f.codes) ASSERT_EQ(static_cast<int>(c.size()), f.length) << n;
  }
  try {
    ranging::code_family("Gold8");
    FAIL() << "no throw";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("unknown code family 'Gold8'; valid: M1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("Gold7"), std::string::npos) << msg;
  }
  try {
    ranging::code_family("mseq-11");
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("[2, 10]"), std::string::npos) << e.what();
  }
  for (const char* bad : {"gold-4", "gold-11", "mseq-1", "mseq-03", "m1", "Gold", "mseq-", ""}) {
    EXPECT_THROW(ranging::code_family(bad), InputError) << bad;
  }
}

// ---------------------------------------------------------------------------------------------
// The CLI, run as a process.

using ToolRun = ranging::testing_support::ProcessResult;
using ranging::testing_support::run_tool;

TEST(Cli, ListsPaperFamilies) {
  const ToolRun r = run_tool("codes --list");
  ASSERT_EQ(r.status, 0) << r.err;
  std::istringstream is(r.out);
  std::string line;
  std::vector<std::string> first_words;
  while (std::getline(is, line)) {
    std::istringstream ls(line);
    std::string w;
    ls >> w;
    first_words.push_back(w);
  }
  const std::vector<std::string> paper = {"M1",    "M2",    "M3",    "M4",    "Gold1", "Gold2",
                                          "Gold3", "Gold4", "Gold5", "Gold6", "Gold7"};
  ASSERT_GE(first_words.size(), paper.size());
  EXPECT_TRUE(std::equal(paper.begin(), paper.end(), first_words.begin())) << r.out;
  EXPECT_EQ(first_words.size(), ranging::code_family_names().size());
}

// The git_commit every JSON output carries is the source tree's commit when the tool was built
// (tool/git_commit.cmake runs at every build), not the one its build folder was configured at:
// a build folder reused across commits stamped outputs with a stale commit. The same git command
// run here must give the same 12 digits; "-dirty" marks tracked changes, and without git (a
// source tarball) the tool says "unknown".
TEST(Cli, GitCommitIsTheCommitTheToolWasBuiltFrom) {
  const ToolRun r = run_tool("codes --family Gold4 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string got = nlohmann::json::parse(r.out).at("git_commit").get<std::string>();
  const ToolRun v = ranging::testing_support::run_tool("--version");
  ASSERT_EQ(v.status, 0) << v.err;
  EXPECT_EQ(v.out, "ranging " + std::string(ranging::tool::build_info::kVersion) + " (git " + got + ")\n");
  const ToolRun head = ranging::testing_support::run_command(
      "git --no-optional-locks -C \"" + std::string(RANGING_SOURCE_DIR) + "\" rev-parse --short=12 HEAD");
  if (head.status != 0) {
    EXPECT_EQ(got, "unknown") << head.err;
    return;
  }
  const std::string commit = head.out.substr(0, head.out.find_last_not_of("\n") + 1);
  ASSERT_EQ(commit.size(), 12u) << head.out;
  EXPECT_TRUE(got == commit || got == commit + "-dirty")
      << got << " is not " << commit << "[-dirty] (a tool built before the last commit: rebuild it)";
}

TEST(Cli, FamilyJsonIsExactlyTheContract) {
  const ToolRun r = run_tool("codes --family Gold4 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.rfind("{\"family\":", 0), 0U) << r.out;  // key order as in the contract
  nlohmann::json j = nlohmann::json::parse(r.out);
  // Every JSON output carries the tool's version and git commit (issue 16); the rest is exact.
  ASSERT_TRUE(j.contains("version") && j.contains("git_commit")) << r.out;
  EXPECT_FALSE(j["version"].get<std::string>().empty());
  j.erase("version");
  j.erase("git_commit");
  const ranging::CodeFamily f = ranging::code_family("Gold4");
  nlohmann::json codes = nlohmann::json::array();
  for (const Code& c : f.codes) {
    nlohmann::json row = nlohmann::json::array();
    for (std::uint8_t chip : c) row.push_back(static_cast<int>(chip));
    codes.push_back(row);
  }
  const nlohmann::json expected = {{"family", "Gold4"}, {"length", 7}, {"codes", codes}};
  EXPECT_EQ(j, expected) << r.out;
  ASSERT_EQ(j.at("codes").size(), 9U);
  for (const auto& row : j.at("codes")) {
    for (const auto& chip : row) ASSERT_TRUE(chip.is_number_integer()) << r.out;
  }
  // Gold4 j=1 is Gold1 j=1 shifted left by 3 (independent of the generator).
  EXPECT_EQ(j.at("codes").at(0), nlohmann::json({1, 1, 0, 0, 1, 0, 1}));
}

TEST(Cli, FamilyTextTable) {
  const ToolRun r = run_tool("codes --family M2");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("   1  1010011\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("   7  1101001\n"), std::string::npos) << r.out;
}

TEST(Cli, UnknownFamilyIsRefused) {
  const ToolRun r = run_tool("codes --family Gold9");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("--family"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Gold9"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("M1"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Gold7"), std::string::npos) << r.err;
}

TEST(Cli, MsequenceByDegreeAndPoly) {
  {
    const ToolRun r = run_tool("codes --degree 4 --poly 0x19 --json");
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("chips"), nlohmann::json({1, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1, 0, 1, 0, 1}));  // M4 j=1
    EXPECT_EQ(j.at("length"), 15);
  }
  {
    const ToolRun r = run_tool("codes --degree 3");
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("\n1011100\n"), std::string::npos) << r.out;  // M1 j=1
  }
  for (const char* bad : {"codes --degree 4 --poly 0x1F", "codes --degree 4 --poly 0x1Q",
                          "codes --degree 17", "codes --degree 1", "codes --poly 0x13",
                          "codes", "codes --list --family M1", "codes --family"}) {
    const ToolRun r = run_tool(bad);
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_TRUE(r.out.empty()) << bad << ": " << r.out;
    EXPECT_NE(r.err.find("--"), std::string::npos) << bad << ": " << r.err;
  }
  const ToolRun r = run_tool("codes --degree 4 --poly 0x1F");
  EXPECT_NE(r.err.find("--poly"), std::string::npos) << r.err;
}
