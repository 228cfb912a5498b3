#pragma once
// Spreading-code generators: LFSR m-sequences, Gold codes, and the code families of the
// paper (Lu et al. 2025, Tables 1-3: M1..M4, Gold1..Gold7) plus generic families for trade
// studies ("mseq-N", "gold-N"). Everything is exact integer arithmetic over GF(2).
//
// Conventions (docs/codes.md has the derivation):
// - A chip is 0 or 1. Correlations map 0 -> -1 and 1 -> +1.
// - Feedback polynomial mask: bit k is the coefficient of x^k; bits `degree` and 0 must be
//   set and no higher bit. x^3 + x + 1 is 0xB, x^4 + x + 1 is 0x13.
// - The sequence s satisfies the recurrence of that polynomial:
//       s[i + degree] = XOR over k < degree with bit k set of s[i + k].
// - The register starts so that the first `degree` chips are 1, 0, ..., 0, 1. With this phase
//   msequence(3, 0xB), msequence(3, 0xD), msequence(4, 0x13), msequence(4, 0x19) are exactly
//   the first codes of the paper's M1, M2, M3, M4 (no extra shift needed).
// - "Shift left by k": rotate_left(c, k)[i] = c[(i + k) mod N].
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace ranging {

using Code = std::vector<std::uint8_t>;  // chips, each 0 or 1

struct CodeFamily {
  std::string name;          // e.g. "Gold4"
  int length = 0;            // chips per code
  std::vector<Code> codes;   // codes[j-1] is code j of the paper (j = 1..eta)
  int eta() const { return static_cast<int>(codes.size()); }
};

// The paper's families M1 M2 M3 M4 Gold1..Gold7, then the generic ones mseq-2..mseq-10 and
// gold-3, gold-5, gold-6, gold-7, gold-9, gold-10.
std::vector<std::string> code_family_names();

// One family by name (case-sensitive). Throws InputError("unknown code family 'X'; valid: ...")
// for an unknown name, and an InputError naming the valid degrees for e.g. "mseq-11".
CodeFamily code_family(std::string_view name);

// One line describing a family (for `ranging codes --list`); same errors as code_family.
std::string code_family_description(std::string_view name);

// True iff `poly` (mask convention above) is a primitive polynomial of exactly this degree.
// Degree outside [2, 16] throws InputError; a mask of the wrong degree is simply not primitive.
bool is_primitive_polynomial(int degree, std::uint32_t poly);

// A primitive polynomial of each degree 2..16 from a fixed table (x^3+x+1, x^4+x+1, ...).
std::uint32_t default_primitive_polynomial(int degree);

// One period (2^degree - 1 chips) of the m-sequence of `poly`, phase as documented above.
// Throws InputError for a degree outside [2, 16] or a polynomial that is not primitive.
Code msequence(int degree, std::uint32_t poly);

// A preferred pair (f, g) of primitive polynomials: f is the default polynomial and g the
// minimal polynomial of the decimation of f's m-sequence by q = 2^k + 1 (k = 1 for odd degree,
// k = 2 for degree = 2 mod 4), so their cross-correlation is three-valued. Valid degrees:
// 3..16, not a multiple of 4 (degree 2 has a single primitive polynomial). preferred_pair(3)
// is (0xB, 0xD): the paper's M1 and M2.
std::pair<std::uint32_t, std::uint32_t> preferred_pair(int degree);

// The Gold set of 2^degree + 1 codes: u, v, then u xor rotate_left(v, k) for k = 0..N-1, where
// u = msequence(degree, f), v = msequence(degree, g), (f, g) = preferred_pair(degree).
// Valid degrees: 3, 5, 6, 7, 9, 10, 11 (the set grows as 4^degree).
std::vector<Code> gold_codes(int degree);

// "x^3 + x + 1" for 0xB (mask convention above).
std::string polynomial_string(std::uint32_t poly);

// Cyclic left rotation: result[i] = c[(i + k) mod N]; any integer k (negative rotates right).
Code rotate_left(const Code& c, long long k);

// Periodic correlation sum_i a'[i] * b'[(i + shift) mod N] with chips mapped 0 -> -1,
// 1 -> +1. Any integer shift. Throws InputError unless a and b are non-empty and equally long.
int periodic_correlation(const Code& a, const Code& b, int shift);

}  // namespace ranging
