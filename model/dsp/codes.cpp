// Spreading-code generators (see codes.hpp for the conventions, docs/codes.md for why).
#include "model/dsp/codes.hpp"

#include <array>
#include <bit>
#include <charconv>
#include <sstream>

#include "model/base/error.hpp"

namespace ranging {
namespace {

constexpr int kMinDegree = 2;
constexpr int kMaxDegree = 16;
constexpr int kMseqFamilyMax = 10;  // largest N of the generic "mseq-N" family
constexpr int kGoldMaxDegree = 11;  // gold_codes: 2049 codes of 2047 chips is ~4 MB
constexpr std::array<int, 6> kGoldFamilyDegrees = {3, 5, 6, 7, 9, 10};

// Primitive polynomials (mask: bit k = coefficient of x^k), low weight; degrees 3 and 4 are
// the paper's M1 and M3 polynomials.
constexpr std::array<std::uint32_t, 17> kDefaultPoly = {
    0,       0,
    0x7,      // x^2 + x + 1
    0xB,      // x^3 + x + 1
    0x13,     // x^4 + x + 1
    0x25,     // x^5 + x^2 + 1
    0x43,     // x^6 + x + 1
    0x83,     // x^7 + x + 1
    0x11D,    // x^8 + x^4 + x^3 + x^2 + 1
    0x211,    // x^9 + x^4 + 1
    0x409,    // x^10 + x^3 + 1
    0x805,    // x^11 + x^2 + 1
    0x1053,   // x^12 + x^6 + x^4 + x + 1
    0x201B,   // x^13 + x^4 + x^3 + x + 1
    0x4443,   // x^14 + x^10 + x^6 + x + 1
    0x8003,   // x^15 + x + 1
    0x1100B,  // x^16 + x^12 + x^3 + x + 1
};

void require_degree(const std::string& field, int degree, int lo, int hi) {
  if (degree < lo || degree > hi) {
    throw InputError(field + ": " + std::to_string(degree) + " is out of range; valid range is [" +
                     std::to_string(lo) + ", " + std::to_string(hi) + "]");
  }
}

std::string hex(std::uint32_t v) {
  std::ostringstream os;
  os << "0x" << std::hex << std::uppercase << v;
  return os.str();
}

// (a * b) mod p over GF(2), deg a, deg b < degree <= 16.
std::uint32_t mulmod(std::uint32_t a, std::uint32_t b, std::uint32_t p, int degree) {
  std::uint64_t prod = 0;
  for (int k = 0; k < degree; ++k) {
    if ((b >> k) & 1U) prod ^= static_cast<std::uint64_t>(a) << k;
  }
  for (int k = 2 * degree - 2; k >= degree; --k) {
    if ((prod >> k) & 1U) prod ^= static_cast<std::uint64_t>(p) << (k - degree);
  }
  return static_cast<std::uint32_t>(prod);
}

// x^e mod p.
std::uint32_t xpow(std::uint64_t e, std::uint32_t p, int degree) {
  std::uint32_t result = 1;
  std::uint32_t base = 2;  // x (degree >= 2, so already reduced)
  while (e != 0) {
    if (e & 1U) result = mulmod(result, base, p, degree);
    base = mulmod(base, base, p, degree);
    e >>= 1;
  }
  return result;
}

// LFSR output of `length` chips from the documented initial phase; no validation.
Code run_lfsr(int degree, std::uint32_t poly, std::size_t length) {
  const std::uint32_t taps = poly & ((1U << degree) - 1U);
  std::uint32_t state = 1U | (1U << (degree - 1));  // bit k = s[i + k]: chips 1, 0, ..., 0, 1
  Code out(length);
  for (std::size_t i = 0; i < length; ++i) {
    out[i] = static_cast<std::uint8_t>(state & 1U);
    const std::uint32_t fb = static_cast<std::uint32_t>(std::popcount(state & taps) & 1);
    state = (state >> 1) | (fb << (degree - 1));
  }
  return out;
}

// Berlekamp-Massey over GF(2): the shortest recurrence of s, as a mask in our convention.
std::uint32_t minimal_polynomial(const Code& s, int degree) {
  std::vector<std::uint8_t> c(s.size() + 1, 0), b(s.size() + 1, 0);
  c[0] = b[0] = 1;
  int L = 0;
  std::size_t m = 1;
  for (std::size_t i = 0; i < s.size(); ++i) {
    std::uint8_t d = s[i];
    for (int k = 1; k <= L; ++k) d ^= static_cast<std::uint8_t>(c[k] & s[i - k]);
    if (d == 0) {
      ++m;
      continue;
    }
    const std::vector<std::uint8_t> t = c;
    for (std::size_t k = 0; k + m < c.size(); ++k) c[k + m] ^= b[k];
    if (2 * static_cast<std::size_t>(L) <= i) {
      L = static_cast<int>(i + 1) - L;
      b = t;
      m = 1;
    } else {
      ++m;
    }
  }
  if (L != degree) throw std::logic_error("minimal_polynomial: unexpected linear complexity");
  // s[i] = sum_{k=1..L} c[k] s[i-k]  <=>  s[i+L] = sum_{j<L} c[L-j] s[i+j]: mask bit j = c[L-j].
  std::uint32_t mask = 0;
  for (int j = 0; j <= L; ++j) mask |= static_cast<std::uint32_t>(c[L - j]) << j;
  return mask;
}

// Parsed family name.
struct FamilySpec {
  enum Kind { kM, kGold, kMseq, kGoldGeneric } kind;
  int n;  // Mi / Goldi index, or degree of the generic families
};

bool parse_int_suffix(std::string_view text, int& out) {
  if (text.empty() || text.size() > 3 || text[0] == '0') return false;
  for (char ch : text) {
    if (ch < '0' || ch > '9') return false;
  }
  auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && ptr == text.data() + text.size();
}

std::string valid_names() {
  std::string all;
  for (const std::string& n : code_family_names()) all += (all.empty() ? "" : ", ") + n;
  return all;
}

FamilySpec parse_family(std::string_view name) {
  int n = 0;
  const std::string label = "code family '" + std::string(name) + "'";
  if (name.size() == 2 && name[0] == 'M' && parse_int_suffix(name.substr(1), n) && n >= 1 &&
      n <= 4) {
    return {FamilySpec::kM, n};
  }
  if (name.substr(0, 4) == "Gold" && parse_int_suffix(name.substr(4), n) && n >= 1 && n <= 7 &&
      name.size() == 5) {
    return {FamilySpec::kGold, n};
  }
  if (name.substr(0, 5) == "mseq-" && parse_int_suffix(name.substr(5), n)) {
    if (n < kMinDegree || n > kMseqFamilyMax) {
      throw InputError(label + ": degree " + std::to_string(n) +
                       " is out of range; valid range is [" + std::to_string(kMinDegree) + ", " +
                       std::to_string(kMseqFamilyMax) + "] (mseq-2 .. mseq-10)");
    }
    return {FamilySpec::kMseq, n};
  }
  if (name.substr(0, 5) == "gold-" && parse_int_suffix(name.substr(5), n)) {
    for (int d : kGoldFamilyDegrees) {
      if (d == n) return {FamilySpec::kGoldGeneric, n};
    }
    throw InputError(label + ": degree " + std::to_string(n) +
                     " is not supported; valid degrees are 3, 5, 6, 7, 9, 10");
  }
  throw InputError("unknown code family '" + std::string(name) + "'; valid: " + valid_names());
}

// The paper's four base polynomials: M2 and M4 use the reciprocals of M1's and M3's.
std::uint32_t paper_m_polynomial(int i) {
  constexpr std::array<std::uint32_t, 4> polys = {0xB, 0xD, 0x13, 0x19};
  return polys.at(static_cast<std::size_t>(i - 1));
}

std::vector<Code> shifted_family(const Code& base, std::size_t count) {
  std::vector<Code> codes;
  codes.reserve(count);
  for (std::size_t j = 0; j < count; ++j) codes.push_back(rotate_left(base, static_cast<long long>(j)));
  return codes;
}

// Gold1 per NOTES.md: [M1-1, M2-1, M1-1 xor shift^k(M2-1) for k = 0..6].
std::vector<Code> paper_gold1() {
  const Code u = msequence(3, paper_m_polynomial(1));
  const Code v = msequence(3, paper_m_polynomial(2));
  std::vector<Code> codes = {u, v};
  for (int k = 0; k < 7; ++k) {
    Code w = rotate_left(v, k);
    for (std::size_t i = 0; i < w.size(); ++i) w[i] ^= u[i];
    codes.push_back(w);
  }
  return codes;
}

}  // namespace

std::vector<std::string> code_family_names() {
  std::vector<std::string> names = {"M1", "M2", "M3", "M4"};
  for (int i = 1; i <= 7; ++i) names.push_back("Gold" + std::to_string(i));
  for (int n = kMinDegree; n <= kMseqFamilyMax; ++n) names.push_back("mseq-" + std::to_string(n));
  for (int n : kGoldFamilyDegrees) names.push_back("gold-" + std::to_string(n));
  return names;
}

CodeFamily code_family(std::string_view name) {
  const FamilySpec spec = parse_family(name);
  CodeFamily fam;
  fam.name = std::string(name);
  switch (spec.kind) {
    case FamilySpec::kM: {
      const int degree = spec.n <= 2 ? 3 : 4;
      const Code base = msequence(degree, paper_m_polynomial(spec.n));
      fam.codes = shifted_family(base, base.size());
      break;
    }
    case FamilySpec::kGold: {
      for (const Code& c : paper_gold1()) fam.codes.push_back(rotate_left(c, spec.n - 1));
      break;
    }
    case FamilySpec::kMseq: {
      const Code base = msequence(spec.n, default_primitive_polynomial(spec.n));
      fam.codes = shifted_family(base, base.size());
      break;
    }
    case FamilySpec::kGoldGeneric:
      fam.codes = gold_codes(spec.n);
      break;
  }
  fam.length = static_cast<int>(fam.codes.front().size());
  return fam;
}

std::string code_family_description(std::string_view name) {
  const FamilySpec spec = parse_family(name);
  switch (spec.kind) {
    case FamilySpec::kM: {
      const std::uint32_t p = paper_m_polynomial(spec.n);
      const int len = spec.n <= 2 ? 7 : 15;
      std::string d = std::to_string(len) + "-chip m-sequence of " + polynomial_string(p) +
                      " (" + hex(p) + ")";
      if (spec.n == 2) d += ", reciprocal of M1";
      if (spec.n == 4) d += ", reciprocal of M3";
      return d + "; code j = code 1 shifted left by j-1 (paper Table " + (len == 7 ? "1" : "2") +
             ")";
    }
    case FamilySpec::kGold:
      if (spec.n == 1) return "7-chip Gold codes: M1-1, M2-1, M1-1 xor shift^k(M2-1) k=0..6 (paper Table 3)";
      return "Gold1 with every code shifted left by " + std::to_string(spec.n - 1) +
             " (paper Table 3)";
    case FamilySpec::kMseq: {
      const std::uint32_t p = default_primitive_polynomial(spec.n);
      return "m-sequence of " + polynomial_string(p) + " (" + hex(p) +
             "); code j = code 1 shifted left by j-1";
    }
    case FamilySpec::kGoldGeneric: {
      const auto [f, g] = preferred_pair(spec.n);
      return "Gold set of the preferred pair " + hex(f) + ", " + hex(g) +
             ": u, v, u xor shift^k(v) k=0..N-1";
    }
  }
  return {};
}

bool is_primitive_polynomial(int degree, std::uint32_t poly) {
  require_degree("polynomial degree", degree, kMinDegree, kMaxDegree);
  if ((poly >> degree) != 1U || (poly & 1U) == 0) return false;  // exact degree, constant term
  const std::uint64_t period = (std::uint64_t{1} << degree) - 1;
  // Primitive <=> the order of x modulo poly is exactly 2^degree - 1.
  if (xpow(period, poly, degree) != 1U) return false;
  std::uint64_t rest = period;
  std::vector<std::uint64_t> primes;
  for (std::uint64_t q = 2; q * q <= rest; ++q) {
    if (rest % q != 0) continue;
    primes.push_back(q);
    while (rest % q == 0) rest /= q;
  }
  if (rest > 1) primes.push_back(rest);
  for (std::uint64_t q : primes) {
    if (xpow(period / q, poly, degree) == 1U) return false;
  }
  return true;
}

std::uint32_t default_primitive_polynomial(int degree) {
  require_degree("polynomial degree", degree, kMinDegree, kMaxDegree);
  return kDefaultPoly[static_cast<std::size_t>(degree)];
}

Code msequence(int degree, std::uint32_t poly) {
  require_degree("m-sequence degree", degree, kMinDegree, kMaxDegree);
  if (!is_primitive_polynomial(degree, poly)) {
    throw InputError("m-sequence polynomial: " + hex(poly) + " is not a primitive polynomial of degree " +
                     std::to_string(degree) + " (mask: bit k = coefficient of x^k, bits " +
                     std::to_string(degree) + " and 0 set); e.g. " +
                     hex(default_primitive_polynomial(degree)));
  }
  return run_lfsr(degree, poly, (std::size_t{1} << degree) - 1);
}

std::pair<std::uint32_t, std::uint32_t> preferred_pair(int degree) {
  require_degree("preferred pair degree", degree, 3, kMaxDegree);
  if (degree % 4 == 0) {
    throw InputError("preferred pair degree: " + std::to_string(degree) +
                     " is a multiple of 4 (no preferred pair exists); valid: 3..16 except 4, 8, 12, 16");
  }
  const std::uint32_t f = default_primitive_polynomial(degree);
  // Gold: q = 2^k + 1 with gcd(degree, k) = 1 (odd degree) or 2 (degree = 2 mod 4).
  const std::size_t q = degree % 2 == 1 ? 3 : 5;
  const Code u = msequence(degree, f);
  Code w(2 * static_cast<std::size_t>(degree));
  for (std::size_t i = 0; i < w.size(); ++i) w[i] = u[(q * i) % u.size()];
  const std::uint32_t g = minimal_polynomial(w, degree);
  if (g == f || !is_primitive_polynomial(degree, g)) {
    throw std::logic_error("preferred_pair: decimation did not give a distinct primitive polynomial");
  }
  return {f, g};
}

std::vector<Code> gold_codes(int degree) {
  require_degree("Gold code degree", degree, 3, kGoldMaxDegree);
  if (degree % 4 == 0) {
    throw InputError("Gold code degree: " + std::to_string(degree) +
                     " is a multiple of 4; valid degrees are 3, 5, 6, 7, 9, 10, 11");
  }
  const auto [f, g] = preferred_pair(degree);
  const Code u = msequence(degree, f);
  const Code v = msequence(degree, g);
  std::vector<Code> codes;
  codes.reserve(u.size() + 2);
  codes.push_back(u);
  codes.push_back(v);
  for (std::size_t k = 0; k < u.size(); ++k) {
    Code w = rotate_left(v, static_cast<long long>(k));
    for (std::size_t i = 0; i < w.size(); ++i) w[i] ^= u[i];
    codes.push_back(std::move(w));
  }
  return codes;
}

std::string polynomial_string(std::uint32_t poly) {
  std::string s;
  for (int k = 31; k >= 0; --k) {
    if (((poly >> k) & 1U) == 0) continue;
    if (!s.empty()) s += " + ";
    s += k == 0 ? "1" : k == 1 ? "x" : "x^" + std::to_string(k);
  }
  return s.empty() ? "0" : s;
}

Code rotate_left(const Code& c, long long k) {
  if (c.empty()) return c;
  const long long n = static_cast<long long>(c.size());
  const std::size_t r = static_cast<std::size_t>(((k % n) + n) % n);
  Code out(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) out[i] = c[(i + r) % c.size()];
  return out;
}

int periodic_correlation(const Code& a, const Code& b, int shift) {
  if (a.empty() || a.size() != b.size()) {
    throw InputError("periodic_correlation: codes must be non-empty and of equal length (got " +
                     std::to_string(a.size()) + " and " + std::to_string(b.size()) + " chips)");
  }
  const long long n = static_cast<long long>(a.size());
  std::size_t j = static_cast<std::size_t>(((shift % n) + n) % n);
  int sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sum += (a[i] == b[j]) ? 1 : -1;  // (+-1)(+-1) = +1 iff the chips agree
    if (++j == b.size()) j = 0;
  }
  return sum;
}

}  // namespace ranging
