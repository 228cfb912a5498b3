#pragma once
// Overflow headroom of the fixed-point correlator bank (model/dsp/correlator_bank.hpp), node by
// node, under each node's own worst-case input (issue 12 section 4).
//
// The bank is linear in its input y up to the quantizers (mixer, F_q, C_q), so every linear node
// X at a decimated output N is X = sum_m a_X[m] y[N-m] plus rounding, with
//   mixer       a_B[m]   = lo(N-m) [m = 0]                       lo = lo_cos (Re) or -lo_sin (Im)
//   decimator   a_Bd[m]  = lo(N-m) [0 <= m < P]
//   chip FIR    a_F[m]   = lo(N-m) T(m),  T(m) = sum_{i : 0 <= m - i D < P} g_q[i]
//   combiner    a_Cj[m]  = lo(N-m) sum_c s_j(c) T(m - (L-1-c) Nc)
// (in units of y * LO before the mixer's shift). Its L1 bound is 2^(data_bits-1) sum_m |a_X[m]|,
// attained by the full-scale sign sequence y[N-m] = sign(a_X[m]) (the worst case), maximized over
// the P phases N mod P of the output. The bounds below add every rounding (+-1/2 LSB per
// quantizer, propagated) so that no input can exceed them:
//   B   <= 2^(db-1) max|lo| / 2^ms + 1/2                        (ms = mix_shift)
//   Bd  <= 2^(db-1) sum_p |lo_p| / 2^ms + P/2
//   F   <= 2^(db-1) max_N sum|a_F| / 2^ms + P/2 sum|g_q|        (accumulator LSBs, fir_bits)
//   F_q demand F / 2^cs + 1/2, held to 2^(chip_bits-1)          (cs = chip_shift; saturates)
//   C_j <= min(2^(db-1) sum|a_Cj| / 2^(ms+cs) + L (1/2 + P/2 sum|g_q| / 2^cs), L 2^(chip_bits-1))
//   C_q demand C / 2^rs + 1/2, held to 2^(corr_bits-1)          (rs = corr_shift; saturates)
//   P_j <= 2 C_q^2,  Q_j <= P_j w_j,  E <= W 2^(2 (db-1))
// headroom_bits = log2(limit / bound): >= 0 means the node cannot overflow; a negative value on a
// saturating node (F_q, C_q) says how far a worst-case input drives it into saturation, and the
// measured run counts those saturations. Nodes the layout sizes as exact (Bd, F, C, P, Q, E) have
// headroom >= 0 by construction; the measurement checks it (0 overflows, peak <= bound).
#include <cstdint>
#include <string>
#include <vector>

#include "model/dsp/correlator_bank.hpp"

namespace ranging {

// A node of the bank, in data-path order.
enum class BankNode { Mixer, Decimator, ChipFir, ChipQ, Combiner, CorrQ, Power, Weighted, Energy };
const char* bank_node_name(BankNode n);

struct BankNodeHeadroom {
  BankNode node = BankNode::Mixer;
  std::string name;        // bank_node_name
  int bits = 0;            // word length (unsigned for P, Q, E)
  bool exact = true;       // sized to hold its bound (no quantizer), or saturating (counted)
  double bound = 0;        // largest |value| any input can give, in the node's own LSBs (for
                           //   a saturating node: the value its input demands, before the rail)
  double limit = 0;        // largest |value| the word holds
  double headroom_bits = 0;  // log2(limit / bound)
  double measured = 0;     // largest |value| under the node's worst-case sequences (fixed model)
  std::uint64_t overflows = 0;  // saturations of this node during those runs (0 for exact nodes)
  int worst_code = -1;     // for per-code nodes: the code whose worst case gave the bound
};

// The full-scale worst-case input of `node` (Mixer..CorrQ, and Energy: full scale throughout),
// for code `code` (per-code nodes), real or imaginary part, both polarities (negate): a sequence
// from reset whose last sample is a decimated output. Throws InputError for Power/Weighted (they
// take the C_q worst case).
std::vector<std::int64_t> correlator_worst_case(const CorrelatorReference& ref, const CorrelatorFixedConfig& cfg,
                                                BankNode node, int code, bool imag, bool negate);

// Every node's bound, limit, headroom and measured peak (each node driven by its worst cases:
// real and imaginary part, both polarities, every code for the per-code nodes).
std::vector<BankNodeHeadroom> correlator_headroom(const CorrelatorReference& ref, const CorrelatorFixedConfig& cfg);

}  // namespace ranging
