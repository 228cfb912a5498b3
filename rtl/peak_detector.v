// peak_detector: streaming peak picking on the correlator bank's outputs, bit-exact to
// PeakDetectorFixed (model/dsp/peak_detector.cpp).
//
// Input: the correlator bank's outputs as GROUPS of CODES beats (AXI4-Stream with tlast): beat
// j = 0 .. CODES-1 carries Q_j (s_weighted, WEIGHTED_W unsigned); s_energy = E and s_index = n
// are the group's (same on every beat); s_last marks beat CODES-1 and restarts the detector's
// own beat counter (framing).
//
// What it computes, per group {Q_j, E, n}:
//   best = argmax_j Q_j (lowest j on ties, scanned per beat), second = max_{j != best} Q_j
//   norm = E >> ENERGY_SHIFT;  gate = Q_best >= THRESHOLD * max(norm,1) && norm >= MIN_NORM
//   a pending candidate whose right neighbour is unknown takes Q_next = Q_code(this group)
//   if gate && (no candidate || Q_best * max(norm_cand,1) > Q_cand * max(norm,1)):
//       candidate := {n, best, Q_prev, Q, second, norm}   (the best rho^2 = Q / norm so far)
//   else if candidate && Q_next known && n - n_cand >= HOLDOFF: emit it
//   Q_prev := this group's Q vector
// An event: score  = min(2^SCORE_W-1, floor(Q / max(norm,1))),  margin = score - same(Q2),
//   frac = clamp(trunc((Q_next-Q_prev) 2^FRAC_W / (2 (2Q - Q_prev - Q_next))), +-2^(FRAC_W-1)),
//   0 when the denominator is <= 0; arrival = n 2^FRAC_W + DECIM frac (signed).
//
// Architecture (sequential, one SB_MAC16, one EBR-inferred memory):
//  - Scan: each beat is compared with the running best as it arrives (one beat per clock while
//    s_ready; the first beat of a group loads best) and written into a 4 x 2^max(clog2(CODES),2)
//    x WEIGHTED_W memory (3 EBR at 48 bits): halves 0 / 1 hold this and the previous group
//    (ping-pong by group parity), region 2 the candidate's words Q_prev, Q, Q2, Q_next.
//  - Capture: only when a candidate is taken, the group is re-read from the memory through the
//    same comparator to find second = max_{j != best} (its index), then Q_prev, Q and Q2 are
//    copied into region 2 through the read register (one word per clock); Q_next is copied
//    the same way after the following group. No beat, group or candidate word is in DFFs;
//    Q (the rho^2 operand), Q_prev, Q_next, Q2 are read back into the read register when used.
//  - Both exact tests are D = A1*B1 - A2*B2 on one 16x16 multiplier (registered operands and
//    product), gate: A1*B1 = Q_best*1, A2*B2 = THRESHOLD*norm1; rho^2 test: Q_best*norm1_cand
//    - Q_cand*norm1. Partial products are summed column by column (16-bit digits, i+j = k) in
//    a small signed accumulator that is shifted right 16 bits after each column; the bits
//    shifted out are >= 0 (arithmetic shift = floor), so D = acc 2^(16 cols) + L with
//    0 <= L < 2^(16 cols): D >= 0 <=> acc >= 0 and D > 0 <=> acc > 0 || (acc == 0 && L != 0).
//  - One divider (non-restoring steps: the quotient bits of restoring division, see the
//    datapath) with only the quotient bits that can survive the cap / clamp:
//    score: start with R = Q >> (SCORE_W+1) and run SCORE_W+1 steps over Q[SCORE_W:0]. The
//      first step compares Q >> SCORE_W with norm1: if >=, floor(Q/norm1) >= 2^SCORE_W and the
//      score is the cap (later bits are ignored); else Q >> SCORE_W < norm1 is a valid restoring
//      remainder and the remaining SCORE_W steps give floor(Q/norm1) < 2^SCORE_W exactly.
//    frac: the dividend is |dQ| 2^FRAC_W (its low FRAC_W bits are zero): start with R = |dQ|
//      and run FRAC_W steps shifting in zeros. The first step compares |dQ| 2 = X >> (FRAC_W-1)
//      with den: if >=, floor(X/den) >= 2^(FRAC_W-1) = HALF and the clamped result is HALF;
//      else R < den holds and the remaining FRAC_W-1 steps give floor(X/den) < HALF exactly.
//      The sign is applied afterwards (trunc toward zero = sign * floor(|X|/den)); den <= 0
//      gives 0. Both rules equal the model's floor + min(cap) / trunc + clamp for every input.
//    The steps run on one adder of DA = max(WEIGHTED_W-SCORE_W+1, norm bits+2, (W+3)/2) bits
//    (33 at the defaults): a score step in one clock, a fraction step in two (low half, its
//    carry registered, then high half, at the top of the adder), so no carry chain is longer
//    than DA, and every step's sign (the next add / subtract and quotient bit) is the adder's
//    bit DA-1.
//  - |dQ| = |Q_next - Q_prev| uses one subtractor twice (Q_prev - Q_next, then Q_next -
//    Q_prev if that was negative: no negation adder; carry-select), then Q_prev + Q_next (in
//    two clocks, half the chain each) and den = 4Q - 2(Q_prev + Q_next) (carry-select), in the
//    divider's registers.
//  - Output: the event is presented in S_OUT straight from the registers that computed it
//    (code from the candidate, score from sc1, margin = sc1 - second score on one 16-bit
//    subtractor, arrival = n 2^FRAC_W + DECIM frac written into the divisor register dv_d in the
//    last divider step); the detector stays in S_OUT (s_ready low) until m_ready.
// Bit growth: MAC accumulator 36 + clog2(NA+NB) bits signed (sum of <= 2 min(NA,NB) products
// of 32 bits plus the carried-in column); divider registers max(WEIGHTED_W+3, norm bits+1, DA+1,
// arrival bits+1); DECIM * frac in FRAC_W+2+clog2(DECIM+1) bits; quotients as above. No
// rounding; nothing can overflow.
// Latency / throughput (CODES=9, 48-bit Q, 29-bit norm: NA=3, NB=2 digits): a group takes
// CODES clocks of beats (one per clock, fewer if s_valid has gaps) + 1 (the scan compares
// each beat a clock after taking it) + (2 NA NB + 3) [gate] +
// (2 NA NB + 3) [rho^2 test, only when the gate passes and a candidate exists] + 1, plus
// CODES + 1 + 4 on a capture (re-read, copies) or 2 when Q_next is copied; an event adds
// 6 + 2 FRAC_W + 1 + 2 (SCORE_W + 2) + 1 = 60 clocks (events and captures exclude each other),
// so a group is done in <= 101 clocks after its first beat (measured by tb_peak_detector: 101
// on the edge-case stream, 86 on the paced coded stream) < the 120 between the bank's groups
// (DECIM 20 x 6 clocks): s_ready is high whenever the bank starts a group and stays high for
// its CODES beats. s_ready is low while a group's tests or an event are processed and while the
// event waits for m_ready (back-pressure stalls the bank; nothing is lost).
// Streams: valid/ready with AXI4-Stream rules (m_* stable while m_valid && !m_ready).
// Reset: synchronous, active high, clears only the control state (state, beat counter,
// candidate and MAC flags); data registers and the memory have no reset. The previous-group
// vector reads as zeros until a group has been taken (Q_prev is written as 0 then; so is Q2
// when no j != best exceeds 0).
// Resources (yosys synth_ice40 -dsp of peak_detector alone with the default parameters, then
// nextpnr-ice40 --up5k --pack-only): 1854 logic cells, 1 SB_MAC16, 3 SB_RAM40_4K; mostly the
// divider, the MAC digit multiplexers and accumulator, the scan compares, the hold-off test and
// the arrival adder. How it got there: docs/bitstream.md ("Resource history").
`default_nettype none

module peak_detector #(
  parameter integer CODES = 9, WEIGHTED_W = 48, ENERGY_W = 41, ENERGY_SHIFT = 12,
  parameter integer SCORE_W = 16, FRAC_W = 8, DECIM = 20, TIME_W = 40,
  parameter integer HOLDOFF = 1000,
  parameter [SCORE_W-1:0] THRESHOLD = 16'h8000,
  parameter [ENERGY_W-1:0] MIN_NORM = 41'h00000000007,
  parameter integer CODE_W = 4
) (
  input  wire clk, rst,
  input  wire s_valid, output wire s_ready,
  // s_energy[ENERGY_SHIFT-1:0] is not needed (only norm = E >> ENERGY_SHIFT is used)
  input  wire [WEIGHTED_W-1:0] s_weighted, input wire s_last,
  /* verilator lint_off UNUSEDSIGNAL */
  input  wire [ENERGY_W-1:0] s_energy,
  /* verilator lint_on UNUSEDSIGNAL */
  input  wire [TIME_W-1:0] s_index,
  output wire m_valid, input wire m_ready,
  output wire [CODE_W-1:0]             m_code,
  output wire signed [TIME_W+FRAC_W:0] m_arrival,
  output wire [SCORE_W-1:0]            m_score, m_margin
);
  localparam integer QW    = WEIGHTED_W;
  localparam integer NW    = (ENERGY_W - ENERGY_SHIFT > 1) ? ENERGY_W - ENERGY_SHIFT : 1;  // norm bits
  localparam integer JB    = (CODES > 1) ? $clog2(CODES) : 1;     // code index bits
  localparam integer NA    = (QW + 15) / 16;                      // 16-bit digits of Q
  localparam integer NB    = (NW + 15) / 16;                      // 16-bit digits of norm
  localparam integer NK    = NA + NB - 1;                         // product columns
  localparam integer KW    = $clog2(NK + 1);
  localparam integer IW    = $clog2(NA + 1);
  localparam integer AW    = 36 + $clog2(NA + NB);                // MAC accumulator
  localparam integer ARR_W = TIME_W + FRAC_W + 1;
  localparam integer W0    = (QW + 3 > NW + 1) ? QW + 3 : NW + 1;
  localparam integer W1    = (W0 > ARR_W) ? W0 : ARR_W + 1;
  // the division step adder (see the datapath): the score steps' range, and half the
  // fraction's W+2 bits
  localparam integer DA0   = (QW - SCORE_W + 1 > NW + 2) ? QW - SCORE_W + 1 : NW + 2;
  localparam integer DA    = (DA0 > (W1 + 3) / 2) ? DA0 : (W1 + 3) / 2;
  localparam integer W     = (W1 > DA) ? W1 : DA + 1;             // divider registers (and arrival)
  localparam integer KM    = (SCORE_W + 1 > FRAC_W) ? SCORE_W + 1 : FRAC_W;  // quotient bits
  localparam integer CW    = $clog2(KM + 1);
  localparam integer FR_W  = FRAC_W + 2;                          // signed fraction
  // HOLDOFF as a TIME_W-bit constant (bit by bit: no unsized operand in a concatenation)
  function [TIME_W-1:0] holdoff_time;
    input integer v;
    integer b;
    begin
      holdoff_time = {TIME_W{1'b0}};
      for (b = 0; b < 32 && b < TIME_W; b = b + 1) holdoff_time[b] = v[b];
    end
  endfunction
  localparam [TIME_W-1:0] HOLD_T = holdoff_time(HOLDOFF);
  localparam [SCORE_W-1:0] CAP = {SCORE_W{1'b1}};
  localparam integer HALF_I = (FRAC_W > 0) ? (1 << (FRAC_W - 1)) : 0;
  localparam [FR_W-1:0] HALF = HALF_I[FR_W-1:0];
  localparam integer KS_I = SCORE_W + 1, KF_I = FRAC_W;
  localparam [CW-1:0] KS = KS_I[CW-1:0];
  localparam [CW-1:0] KF = KF_I[CW-1:0];
  localparam integer KF1 = (FRAC_W > 0) ? FRAC_W - 1 : 0;
  localparam [KW-1:0] KLAST = NK[KW-1:0] - 1'b1;
  localparam integer NB_I = NB, NA_I = NA;
  localparam [KW-1:0] NB_K = NB_I[KW-1:0];
  localparam [IW-1:0] NA_LAST = NA_I[IW-1:0] - 1'b1;

  localparam integer AB    = (JB > 2) ? JB : 2;                   // memory index bits
  localparam [3:0] S_IDLE = 4'd0, S_MAC = 4'd2, S_DECIDE = 4'd3,
                   S_P0 = 4'd4, S_P1 = 4'd5, S_DIV = 4'd6, S_NEXT = 4'd7, S_OUT = 4'd8,
                   S_CP = 4'd9, S_EA = 4'd10, S_EB = 4'd11, S_P2 = 4'd12, S_R2 = 4'd13, S_PS = 4'd14;
  reg [3:0] state;

  // ---------------------------------------------------------------- input beats and scan
  reg [NW-1:0]       nrm;            // norm = E >> ENERGY_SHIFT
  reg [TIME_W-1:0]   n_r;
  reg [JB-1:0]       j;
  reg [JB-1:0]       best, sidx;    // sidx: index of second (found by a re-read at capture)
  reg [QW-1:0]       best_q;         // running max: of the beats (scan), then of j != best
  reg                r_v, r_end, s_found;
  reg [JB-1:0]       r_j;
  reg                par, prev_ok;   // memory half of this group; a previous group exists
  wire [QW-1:0] head = s_weighted;
  wire take = s_valid && state == S_IDLE;   // a beat is accepted
  wire first = (j == {JB{1'b0}});
  localparam integer JLAST_I = CODES - 1;
  localparam [JB-1:0] JLAST = JLAST_I[JB-1:0];
  reg  [QW-1:0] p_rd;
  // The running max (scan: the beats; S_R2: the re-read words of j != best) decides word k a
  // clock after it arrives (h_*), from two compares made when it arrived: against best_q and
  // against word k-1 (h_q then). If word k-1 was being decided in that same clock (pend), the
  // one that applies is picked by that decision (won); so no compare sits between a memory
  // read and best_q's update, and no decision waits on a compare.
  reg            h_v, h_last, h_first, h_rv;
  reg [JB-1:0]   h_j, h_rj;
  reg [QW-1:0]   h_q;
  reg            ca_r, cb_r, pend_r, won_r;
  // selected by the state alone (not by take, which waits on the bank's output handshake); a
  // word that is not taken is never decided on (h_v, h_rv low next clock)
  wire [QW-1:0] cmp_src = (state == S_IDLE) ? head : p_rd;
  // a > b (the borrow of b - a) as a carry-select compare: the borrows of the low half and
  // of both versions of the high half (borrow in or not) come out of three carry chains side
  // by side and one LUT picks (half the chain; an equality tree after the chain was slower)
  localparam integer QH = QW / 2;
  function gt_split;
    input [QW-1:0] a, b;
    reg [QH:0]    lo;
    reg [QW-QH:0] h0, h1;
    begin
      lo = {1'b0, b[QH-1:0]} - {1'b0, a[QH-1:0]};
      h0 = {1'b0, b[QW-1:QH]} - {1'b0, a[QW-1:QH]};
      h1 = {1'b0, b[QW-1:QH]} + {1'b1, ~a[QW-1:QH]};       // b - a - 1
      gt_split = lo[QH] ? h1[QW-QH] : h0[QW-QH];
    end
  endfunction
  wire gt_best = (pend_r && won_r) ? cb_r : ca_r;   // word k > max of the words before it

  // ---------------------------------------------------------------- candidate
  reg                c_valid, c_has_next;
  reg [TIME_W-1:0]   c_n;
  reg [JB-1:0]       c_code;
  reg [CODE_W-1:0]   c_code1;        // c_code + 1 (m_code, a register for the consumer)
  reg [NW-1:0]       c_norm1;
  reg                cp_kind, qp_zero;   // copy program: 1 capture (Qp, Q, Q2), 0 Q_next
  reg [1:0]          cp;

  // One memory (EBR): this / previous group's Q vectors (ping-pong halves 0x, by group
  // parity) and the candidate's words Q_prev, Q, Q2, Q_next (region 10), copied there from
  // the halves through the read register after the tests (no candidate word in DFFs).
  reg [QW-1:0] pmem [0:(4 << AB)-1];
  /* verilator lint_off UNUSEDSIGNAL */
  wire [AB+JB-1:0] best_x = {{AB{1'b0}}, best};
  wire [AB+JB-1:0] sidx_x = {{AB{1'b0}}, sidx};
  wire [AB+JB-1:0] cc_x   = {{AB{1'b0}}, c_code};
  wire [AB+JB-1:0] j_x    = {{AB{1'b0}}, j};
  /* verilator lint_on UNUSEDSIGNAL */
  localparam [AB+1:0] C_QP = {2'b10, {(AB-2){1'b0}}, 2'd0}, C_Q  = {2'b10, {(AB-2){1'b0}}, 2'd1},
                      C_Q2 = {2'b10, {(AB-2){1'b0}}, 2'd2}, C_QN = {2'b10, {(AB-2){1'b0}}, 2'd3};
  // par was toggled in S_DECIDE: in S_CP the group just scanned is half ~par, its
  // predecessor half par
  reg [AB+1:0] raddr;
  always @* begin
    raddr = C_Q;                                  // S_MAC (rho^2 operand), S_P1, S_P2
    case (state)
      S_CP: if (!cp_kind)   raddr = {1'b0, ~par, cc_x[AB-1:0]};
            else if (cp == 2'd0) raddr = {1'b0, par, best_x[AB-1:0]};
            else if (cp == 2'd1) raddr = {1'b0, ~par, best_x[AB-1:0]};
            else            raddr = {1'b0, ~par, sidx_x[AB-1:0]};
      S_R2: raddr = {1'b0, ~par, j_x[AB-1:0]};
      S_EA, S_P0, S_P1: raddr = C_QN;
      S_EB: raddr = C_QP;
      S_DIV, S_NEXT: raddr = C_Q2;
      default: ;
    endcase
  end
  wire re = (state == S_MAC) || (state == S_R2) || (state == S_CP) || (state == S_EA) || (state == S_EB) ||
            (state == S_P0) || (state == S_P1) || (state == S_PS) || (dsel != 2'd0 && (state == S_DIV || state == S_NEXT));
  wire cp_we = (state == S_CP) && cp != 2'd0;
  wire [AB+1:0] waddr = take ? {1'b0, par, j_x[AB-1:0]}
                             : {2'b10, {(AB-2){1'b0}}, cp_kind ? cp - 1'b1 : 2'd3};
  wire [QW-1:0] wdata = take ? head : (p_rd & {QW{!(cp_kind && ((cp == 2'd1 && qp_zero) || (cp == 2'd3 && !s_found)))}});
  always @(posedge clk) begin
    if (take || cp_we) pmem[waddr] <= wdata;
    if (re) p_rd <= pmem[raddr];
  end
  wire cp_end = cp_kind ? (cp == 2'd3) : (cp == 2'd1);

  wire [NW-1:0] norm1 = {nrm[NW-1:1], nrm[0] | (nrm == {NW{1'b0}})};
  // norm >= MIN_NORM compared only on MIN_NORM's significant bits (no wide constant compare)
  function integer bitlen;
    input [ENERGY_W-1:0] v;
    integer b;
    begin
      bitlen = 0;
      for (b = 0; b < ENERGY_W; b = b + 1)
        if (v[b]) bitlen = b + 1;
    end
  endfunction
  localparam integer MB0 = bitlen(MIN_NORM);
  localparam integer MB  = (MB0 < 1) ? 1 : (MB0 > NW) ? NW : MB0;
  localparam [MB-1:0] MIN_LO = MIN_NORM[MB-1:0];
  wire min_ok = (MB0 <= NW) && (((nrm >> MB) != {NW{1'b0}}) || nrm[MB-1:0] >= MIN_LO);

  // ---------------------------------------------------------------- MAC: D = A1 B1 - A2 B2
  reg            m_run, m_mode;      // mode 0: gate, 1: rho^2 comparison
  reg            m_done, gate_r;
  reg [KW-1:0]   mk;                 // column
  reg [IW-1:0]   mi;                 // digit of A
  reg            mp;                 // 0: A1 B1 (+), 1: A2 B2 (-)
  reg [15:0]     ma, mb;
  reg [31:0]     prod;
  reg            v1, s1, e1, v2, s2, e2;   // valid / subtract / column end, per stage
  reg            fin1, fin2;
  reg signed [AW-1:0] acc;
  reg            acc_nz;

  // digit vectors, one spare top bit (never selected) so that no replication is zero-width
  /* verilator lint_off UNUSEDSIGNAL */
  wire [NA*16:0] a1_v = {{(NA*16-QW+1){1'b0}}, best_q};
  wire [NA*16:0] a2_v = m_mode ? {{(NA*16-QW+1){1'b0}}, p_rd}
                               : {{(NA*16-SCORE_W+1){1'b0}}, THRESHOLD};
  wire [NB*16:0] b1_v = m_mode ? {{(NB*16-NW+1){1'b0}}, c_norm1} : {{NB*16{1'b0}}, 1'b1};
  wire [NB*16:0] b2_v = {{(NB*16-NW+1){1'b0}}, norm1};
  /* verilator lint_on UNUSEDSIGNAL */
  // digit range of column k: i in [max(0, k-NB+1), min(k, NA-1)], j = k - i
  wire [KW-1:0] mk1   = mk + 1'b1;
  /* verilator lint_off UNUSEDSIGNAL */
  wire [KW-1:0] lo1_k = mk1 - NB_K + 1'b1;
  /* verilator lint_on UNUSEDSIGNAL */
  wire [IW-1:0] i_lo1 = (mk1 >= NB_K) ? lo1_k[IW-1:0] : {IW{1'b0}};
  wire [KW:0]   na_last_k = {{(KW-IW+1){1'b0}}, NA_LAST};
  wire [IW-1:0] i_hi  = ({1'b0, mk} > na_last_k) ? NA_LAST : mk[IW-1:0];
  /* verilator lint_off UNUSEDSIGNAL */
  wire [KW:0]   mj_x  = {1'b0, mk} - {{(KW-IW+1){1'b0}}, mi};
  /* verilator lint_on UNUSEDSIGNAL */
  wire [KW-1:0] mj    = mj_x[KW-1:0];
  wire [15:0] a_dig = mp ? a2_v[mi*16 +: 16] : a1_v[mi*16 +: 16];
  wire [15:0] b_dig = mp ? b2_v[mj*16 +: 16] : b1_v[mj*16 +: 16];
  wire signed [AW-1:0] prod_x = $signed({{(AW-32){1'b0}}, prod});
  // one adder: acc - prod = acc + ~prod + 1
  wire signed [AW-1:0] acc_sum = acc + (prod_x ^ {AW{s2}}) + {{(AW-1){1'b0}}, s2};
  wire d_ge0 = !acc[AW-1];
  // a MAC program starts: after the scan (gate) or after a passed gate with a candidate (rho^2)
  wire m_start = (h_v && h_last) ||
                 (state == S_MAC && m_done && !m_mode && d_ge0 && min_ok && c_valid);
  wire d_gt0 = d_ge0 && ((acc != 0) || acc_nz);

  // ---------------------------------------------------------------- event / divider
  reg [W-1:0]    dv_r, dv_d;
  reg [KM-1:0]   dv_q;
  reg [CW-1:0]   dv_cnt;
  reg [1:0]      dsel;               // 0: fraction, 1: score, 2: second score
  reg            ev_neg;
  reg [FR_W-1:0] fmag;
  reg [SCORE_W-1:0] sc1;
  // Non-restoring division step: the partial remainder r = {dv_rn, dv_r} is signed (W+1 bits,
  // in [-d, d)); the next one is 2r + bit - d when r >= 0 and 2r + bit + d when r < 0, chosen by
  // the register dv_rn (so the XOR is before the carry chain and nothing fans out after it).
  // The quotient bit is "the next remainder >= 0": the same bits as restoring division (a
  // negative r is the restoring remainder minus d), which the tests compare with the model.
  // One DA-bit adder does the steps (a third of the carry cells of a full-width carry-select
  // step and a chain of DA instead of W+2 bits):
  //   score (dsel 1, 2): one clock per step, on the low DA bits. In range, r is in [-norm1,
  //     norm1) and 2r + bit +- norm1 fits NW+2 signed bits; the first step's 2R + bit - norm1
  //     (R = Q >> (SCORE_W+1) < 2^(QW-SCORE_W-1)) fits QW-SCORE_W+1. After a first quotient bit
  //     1 the score is the cap and the later (possibly wrapped) bits are not used.
  //   fraction (dsel 0): two clocks per step (dv_ph): the low DA bits, their carry registered
  //     (dv_cl), then the high W+1-DA bits; dv_rn (the step's add / subtract) changes only after
  //     the high pass, and dv_rm keeps r[DA-1] (bit DA of 2r) that the low pass overwrote.
  //     The high pass sits at the top of the adder, above SH = 2 DA - 1 - W low bits that pass
  //     its carry-in dv_cl up (ones plus zeros plus dv_cl): the step's sign is st[DA-1] in
  //     every step, straight from the carry chain (no multiplexer after it).
  localparam integer SH = 2 * DA - 1 - W;
  if (SH < 1) begin : g_bad_sh
    initial $error("peak_detector: divider adder DA = %0d too narrow for W = %0d (2 DA - 1 - W = %0d < 1)", DA, W, SH);
  end
  reg          dv_rn, dv_ph, dv_cl, dv_rm;
  /* verilator lint_off UNUSEDSIGNAL */
  wire [DA+W+1:0] dv_sw = {{DA{dv_rn}}, dv_rn, dv_r, dv_q[KM-1]};   // 2r + bit, sign-extended
  wire [2*DA-1:0] dv_dw = {{(2*DA-W){1'b0}}, dv_d};
  /* verilator lint_on UNUSEDSIGNAL */
  wire [DA-1:0] st_a  = dv_ph ? {dv_sw[W:DA+1], dv_rm, {SH{1'b1}}} : dv_sw[DA-1:0];
  wire [DA-1:0] st_b  = dv_ph ? {dv_dw[W:DA] ^ {(W-DA+1){~dv_rn}}, {SH{1'b0}}}
                              : dv_dw[DA-1:0] ^ {DA{~dv_rn}};
  wire          st_ci = dv_ph ? dv_cl : ~dv_rn;
  wire [DA:0]   st    = {1'b0, st_a} + {1'b0, st_b} + {{DA{1'b0}}, st_ci};
  wire dv_sgn = st[DA-1];   // the sign of the step's result (score step or fraction high pass)
  wire dv_last = dv_ph || (dsel != 2'd0);      // the step's last clock
  // den = 4 Q - 2 (Q_prev + Q_next) (S_P2, mod 2^W) as a two-segment carry-select subtractor
  localparam integer EH = W / 2;
  wire [W-1:0]    den_a  = {{(W-QW){1'b0}}, p_rd} << 2;
  wire [W-1:0]    den_b  = dv_d << 1;
  wire [EH:0]     den_lo = {1'b0, den_a[EH-1:0]} - {1'b0, den_b[EH-1:0]};
  wire [W-EH-1:0] den_h0 = den_a[W-1:EH] - den_b[W-1:EH];
  wire [W-EH-1:0] den_h1 = den_a[W-1:EH] + ~den_b[W-1:EH];   // - 1
  wire [W-1:0]    den_cs = {den_lo[EH] ? den_h1 : den_h0, den_lo[EH-1:0]};
  // p_rd - dv_d on QW-bit operands (S_P0, S_P1: Q_prev - Q_next, Q_next - Q_prev), sign-extended
  // to W, as a two-segment carry-select subtractor (the low half's borrow picks the high half)
  localparam integer SB = (QW + 1) / 2;
  wire [SB:0]    sb_lo = {1'b0, p_rd[SB-1:0]} - {1'b0, dv_d[SB-1:0]};
  wire [QW-SB:0] sb_h0 = {1'b0, p_rd[QW-1:SB]} - {1'b0, dv_d[QW-1:SB]};
  wire [QW-SB:0] sb_h1 = {1'b0, p_rd[QW-1:SB]} + ~{1'b0, dv_d[QW-1:SB]};   // - 1
  wire [QW-SB:0] sb_hi = sb_lo[SB] ? sb_h1 : sb_h0;
  wire [W-1:0]   dq_sub = {{(W-QW-1){sb_hi[QW-SB]}}, sb_hi, sb_lo[SB-1:0]};
  // Q_prev + Q_next over two clocks (S_P1 the low SB bits and the carry ps_c, S_PS the rest)
  reg            ps_c;
  wire [SB:0]    ps_lo = {1'b0, p_rd[SB-1:0]} + {1'b0, dv_d[SB-1:0]};
  wire [W-SB-1:0] ps_hi = {{(W-QW){1'b0}}, p_rd[QW-1:SB]} + dv_d[W-1:SB] + {{(W-SB-1){1'b0}}, ps_c};
  wire [CW-1:0] dv_k = (dsel == 2'd0) ? KF : KS;
  wire [SCORE_W-1:0] score_now = dv_q[SCORE_W] ? CAP : dv_q[SCORE_W-1:0];
  // quotient of the fraction division: its low FRAC_W bits (< HALF when the top one is 0)
  /* verilator lint_off UNUSEDSIGNAL */
  wire [KM+FR_W-1:0] fq_x = {{FR_W{1'b0}}, dv_q};
  /* verilator lint_on UNUSEDSIGNAL */
  wire [FR_W-1:0] fq = fq_x[FR_W-1:0] & {{2{1'b0}}, {FRAC_W{1'b1}}};
  wire den_pos = !dv_d[W-1] && (dv_d != {W{1'b0}});
  // the dividend (Q in S_NEXT dsel 0, Q2 in S_NEXT dsel 1) is in the memory read register
  wire [QW:0] q_hi  = {1'b0, p_rd}  >> (SCORE_W + 1);
  // Q[SCORE_W:0] at the top of the KM-bit dividend register
  /* verilator lint_off UNUSEDSIGNAL */
  wire [KM+SCORE_W:0] q_lo_x  = {p_rd[SCORE_W:0],  {KM{1'b0}}};
  /* verilator lint_on UNUSEDSIGNAL */
  wire [KM-1:0] q_lo  = q_lo_x[KM+SCORE_W -: KM];

  /* verilator lint_off UNUSEDSIGNAL */
  wire [CODE_W+JB-1:0] best_x1 = {{CODE_W{1'b0}}, best} + 1'b1;
  /* verilator lint_on UNUSEDSIGNAL */
  // a candidate without Q_next takes it from this group (copied in S_CP), so it can emit now
  // since = n - c_n and the hold-off test are pipelined over two clocks (since, emit): n_r,
  // c_n and c_valid are stable through S_MAC (>= 2 NA NB + 3 clocks) before S_DECIDE reads emit
  localparam integer HB0 = $clog2(HOLDOFF + 1);            // significant bits of HOLDOFF
  localparam integer HB  = (HB0 < 1) ? 1 : HB0;
  localparam [HB-1:0] HOLD_LO = HOLD_T[HB-1:0];
  reg [TIME_W-1:0] since;
  reg emit;
  always @(posedge clk) begin
    since <= n_r - c_n;
    emit <= c_valid && (((since >> HB) != {TIME_W{1'b0}}) || since[HB-1:0] >= HOLD_LO);
  end

  // output: held in S_OUT (the registers it is computed from do not change there)
  localparam integer DECIM_I = DECIM;
  localparam integer DW = $clog2(DECIM + 1);
  localparam integer FD_W = FR_W + DW;                      // DECIM * frac, signed
  localparam [DW-1:0] DECIM_D = DECIM_I[DW-1:0];
  wire signed [FR_W-1:0] frac = ev_neg ? -$signed(fmag) : $signed(fmag);
  wire [FD_W-1:0] frac_x = {{DW{frac[FR_W-1]}}, frac};
  // DECIM * frac as shifts and adds of the constant's set bits (no multiplier cell), only as
  // wide as the product can be
  function [FD_W-1:0] times_decim;
    input [FD_W-1:0] v;
    integer b;
    begin
      times_decim = {FD_W{1'b0}};
      for (b = 0; b < DW; b = b + 1)
        if (DECIM_D[b]) times_decim = times_decim + (v << b);
    end
  endfunction
  // registered every clock: fmag and ev_neg are final in S_NEXT of the fraction's division, and
  // the arrival is read in S_NEXT of the second score's, a whole division later (keeps the
  // negate, the shift-adds and the arrival adder out of one clock)
  reg [FD_W-1:0] frac_d;
  always @(posedge clk) frac_d <= times_decim(frac_x);
  wire signed [ARR_W-1:0] arrival = $signed({1'b0, c_n, {FRAC_W{1'b0}}})
                                  + $signed({{(ARR_W-FD_W){frac_d[FD_W-1]}}, frac_d});

  assign s_ready = (state == S_IDLE);

  // MAC pipeline (datapath, no reset needed: m_run / v1 / v2 are controlled below)
`ifdef FORMAL_FREE_PRODUCT
  // Formal abstraction (formal/peak_detector.job): the product is any value in every clock, so
  // the control and output-bound properties are proven for every multiplier result (the
  // product's value is the equivalence benches' job); it keeps the solver off a 16x16 multiply.
  (* anyseq *) wire [31:0] f_prod;
`endif
  always @(posedge clk) begin
    ma <= a_dig;
    mb <= b_dig;
`ifdef FORMAL_FREE_PRODUCT
    prod <= f_prod;
`else
    prod <= ma * mb;
`endif
  end

  // ---------------------------------------------------------------- control (reset)
  always @(posedge clk) begin
    if (rst) begin
      state <= S_IDLE;
      j <= {JB{1'b0}};
      par <= 1'b0; prev_ok <= 1'b0;
      c_valid <= 1'b0; c_has_next <= 1'b0;
      m_run <= 1'b0; m_done <= 1'b0;
      v1 <= 1'b0; v2 <= 1'b0; fin1 <= 1'b0; fin2 <= 1'b0;
      h_v <= 1'b0;
    end else begin
      h_v <= take;
      v2 <= v1; fin2 <= fin1; m_done <= fin2;
      v1 <= m_run;
      fin1 <= 1'b0;
      if (m_run && mp && mi == i_hi && mk == KLAST) begin
        m_run <= 1'b0;
        fin1 <= 1'b1;
      end
      if (m_start) m_run <= 1'b1;
      case (state)
        // beats j = 0 .. CODES-1 (own counter, restarted by s_last)
        S_IDLE: if (s_valid) begin
          j <= s_last ? {JB{1'b0}} : j + 1'b1;
          if (s_last) state <= S_MAC;
        end
        S_MAC: if (m_done && !m_start) state <= S_DECIDE;
        S_DECIDE: begin
          par <= ~par;
          prev_ok <= 1'b1;
          state <= S_IDLE;
          // gate_r && m_mode: the rho^2 test ran (a candidate exists); its result is d_gt0.
          cp_kind <= 1'b1;
          if (gate_r && (!c_valid || d_gt0)) begin
            c_valid <= 1'b1;
            c_has_next <= 1'b0;
            state <= S_R2;
          end else if (emit) begin
            c_valid <= 1'b0;
            c_has_next <= 1'b0;
            cp_kind <= 1'b0;
            state <= c_has_next ? S_EA : S_CP;
          end else begin
            c_has_next <= c_valid;
            cp_kind <= 1'b0;
            if (c_valid && !c_has_next) state <= S_CP;
          end
        end
        // second = max_{j != best} Q_j re-read from the memory (pipelined: r_v, r_j)
        S_R2: if (r_end) begin
          state <= S_CP;
          j <= {JB{1'b0}};
        end else begin
          j <= (j == JLAST) ? {JB{1'b0}} : j + 1'b1;
        end
        S_CP: if (cp_end) state <= (cp_kind || c_valid) ? S_IDLE : S_EA;
        S_EA: state <= S_EB;
        S_EB: state <= S_P0;
        S_P0: state <= S_P1;
        S_P1: state <= S_PS;
        S_PS: state <= S_P2;
        S_P2: state <= (FRAC_W > 0) ? S_DIV : S_NEXT;
        S_DIV: if (dv_last && dv_cnt + 1'b1 == dv_k) state <= S_NEXT;
        S_NEXT: state <= (dsel == 2'd2) ? S_OUT : S_DIV;
        S_OUT: if (m_ready) state <= S_IDLE;
        default: state <= S_IDLE;
      endcase
    end
  end

  // ---------------------------------------------------------------- datapath (no reset)
  always @(posedge clk) begin
    // MAC program counters and accumulator (one write site per register)
    s2 <= s1; e2 <= e1;
    s1 <= mp; e1 <= mp && (mi == i_hi);
    if (m_start) begin
      mk <= {KW{1'b0}}; mi <= {IW{1'b0}}; mp <= 1'b0;
      m_mode <= !(h_v && h_last);
    end else if (m_run) begin
      mp <= ~mp;
      if (mp) begin
        if (mi == i_hi) begin
          mk <= mk1;
          mi <= i_lo1;
        end else begin
          mi <= mi + 1'b1;
        end
      end
    end
    if (m_start) begin
      acc <= {AW{1'b0}};
      acc_nz <= 1'b0;
    end else if (v2) begin
      acc <= e2 ? acc_sum >>> 16 : acc_sum;
      acc_nz <= acc_nz | (e2 && acc_sum[15:0] != 16'd0);
    end
    // scan, one beat per clock: strict > from the first beat on, lowest index on ties
    h_q <= cmp_src;
    ca_r <= gt_split(cmp_src, best_q);
    cb_r <= gt_split(cmp_src, h_q);
    pend_r <= h_v || h_rv;
    won_r <= (h_v && (gt_best || h_first)) || (h_rv && gt_best && h_rj != best);
    h_rv <= (state == S_R2) && r_v;
    h_rj <= r_j;
    if (take) begin
      h_j <= j;
      h_first <= first;
      h_last <= s_last;
      nrm <= s_energy[ENERGY_W-1 -: NW];
      n_r <= s_index;
    end
    if (h_v && (gt_best || h_first)) begin
      best_q <= h_q;
      best <= h_j;
    end
    if (state == S_DECIDE) begin
      best_q <= {QW{1'b0}};
      s_found <= 1'b0;
      r_v <= 1'b0;
      r_end <= 1'b0;
    end else if (state == S_R2) begin
      r_v <= 1'b1;
      r_j <= j;
      r_end <= (j == JLAST);
    end
    // the last re-read word is compared in S_CP's first clock; sidx is read at cp 2, s_found
    // at cp 3
    if (h_rv && gt_best && h_rj != best) begin
      best_q <= h_q;
      sidx <= h_rj;
      s_found <= 1'b1;
    end
    if (state == S_MAC && m_done && !m_mode) gate_r <= d_ge0 && min_ok;
    if (state == S_DECIDE && gate_r && (!c_valid || d_gt0)) begin
      c_n <= n_r;
      c_code <= best;
      c_code1 <= best_x1[CODE_W-1:0];
      c_norm1 <= norm1;
    end
    if (state == S_DECIDE) begin
      qp_zero <= !prev_ok;
      cp <= 2'd0;
    end else if (state == S_CP) cp <= cp + 1'b1;
    case (state)
      // |dQ| and the sign of dQ = Q_next - Q_prev with one subtractor (p_rd - dv_d) used
      // twice, no negation: Q_prev - Q_next, and Q_next - Q_prev if that was negative
      S_EB: dv_d <= {{(W-QW){1'b0}}, p_rd};     // Q_next
      S_P0: begin                               // p_rd = Q_prev
        dv_r <= dq_sub;
        dv_d <= {{(W-QW){1'b0}}, p_rd};
      end
      S_P1: begin                               // p_rd = Q_next; dQ = 0 gives frac 0 either way
        ev_neg <= !dv_r[W-1];
        if (dv_r[W-1]) dv_r <= dq_sub;
        dv_d[SB-1:0] <= ps_lo[SB-1:0];
        ps_c <= ps_lo[SB];
      end
      S_PS: dv_d[W-1:SB] <= ps_hi;              // p_rd = Q_next again
      // den = 4Q - 2(Q_prev + Q_next)
      S_P2: begin
        dv_d <= den_cs;
        dv_q <= {KM{1'b0}};
        dv_rn <= 1'b0;
        dv_ph <= 1'b0;
        dv_cnt <= {CW{1'b0}};
        dsel <= 2'd0;
        fmag <= {FR_W{1'b0}};
      end
      S_DIV: begin
        if (dv_ph) dv_r[W-1:DA] <= st[DA-2:SH];
        else begin
          dv_r[DA-1:0] <= st[DA-1:0];
          dv_rm <= dv_r[DA-1];
          dv_cl <= st[DA];
        end
        if (dsel == 2'd0) dv_ph <= ~dv_ph;
        if (dv_last) begin
          dv_rn <= dv_sgn;
          dv_q <= {dv_q[KM-2:0], !dv_sgn};
          dv_cnt <= dv_cnt + 1'b1;
        end
      end
      S_NEXT: begin
        dv_cnt <= {CW{1'b0}};
        // the last step: dv_d holds the event's arrival while it is presented (S_OUT)
        dv_d <= (dsel == 2'd2) ? {{(W-ARR_W){arrival[ARR_W-1]}}, arrival} : {{(W-NW){1'b0}}, c_norm1};
        if (dsel == 2'd0) begin
          if (FRAC_W > 0 && den_pos)
            fmag <= dv_q[KF1] ? HALF : fq;
          dsel <= 2'd1;
          dv_r <= {{(W-QW-1){1'b0}}, q_hi};
          dv_rn <= 1'b0;
          dv_q <= q_lo;
        end else if (dsel == 2'd1) begin
          sc1 <= score_now;
          dsel <= 2'd2;
          dv_r <= {{(W-QW-1){1'b0}}, q_hi};
          dv_rn <= 1'b0;
          dv_q <= q_lo;
        end
      end
      default: ;
    endcase
  end

  assign m_valid   = (state == S_OUT);
  assign m_code    = c_code1;
  assign m_arrival = dv_d[ARR_W-1:0];
  assign m_score   = sc1;
  assign m_margin  = sc1 - score_now;

`ifdef FORMAL
  // Formal properties (formal/run_formal.sh peak_detector). Assumed: reset first; the input
  // follows the AXI-Stream rules (valid held until ready, beat stable while waiting) and frames
  // groups of at most CODES beats (s_last on beat CODES-1 at the latest); m_ready free.
  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume(rst);
  always @(posedge clk)
    if (f_past_valid && !$past(rst) && $past(s_valid && !s_ready)) begin
      assume(s_valid);
      assume(s_weighted == $past(s_weighted) && s_last == $past(s_last) &&
             s_energy == $past(s_energy) && s_index == $past(s_index));
    end
  always @(*) if (s_valid && j == JLAST) assume(s_last);
  // f_ev: an event's fraction has been set up (S_P2) since reset (fmag and dsel have no reset)
  reg f_ev = 1'b0;
  always @(posedge clk)
    if (rst) f_ev <= 1'b0;
    else if (state == S_P2) f_ev <= 1'b1;
  // f_scan: a beat has been scanned since reset (best has no reset)
  reg f_scan = 1'b0;
  always @(posedge clk)
    if (rst) f_scan <= 1'b0;
    else if (h_v) f_scan <= 1'b1;
  // f_dec: a group has been decided since reset (s_found, r_v, r_end are cleared there)
  reg f_dec = 1'b0;
  always @(posedge clk)
    if (rst) f_dec <= 1'b0;
    else if (state == S_DECIDE) f_dec <= 1'b1;
  // f_cand: a candidate has been taken since reset (c_code, c_code1 have no reset)
  reg f_cand = 1'b0;
  always @(posedge clk)
    if (rst) f_cand <= 1'b0;
    else if (state == S_DECIDE && gate_r && (!c_valid || d_gt0)) f_cand <= 1'b1;
  /* verilator lint_off UNUSEDSIGNAL */
  wire [CODE_W+JB-1:0] f_cc1 = {{CODE_W{1'b0}}, c_code} + 1'b1;
  /* verilator lint_on UNUSEDSIGNAL */
  // Reset state: idle, ready for a beat, no event, no candidate, no MAC program.
  always @(posedge clk)
    if (f_past_valid && $past(rst))
      assert(state == S_IDLE && s_ready && !m_valid && !c_valid && !c_has_next && j == 0 &&
             !m_run && !m_done && !v1 && !v2 && !h_v);
  // The state is one of the machine's; the beat counter and the code indices stay below CODES.
  always @(*)
    if (f_past_valid && !rst) begin
      assert(state == S_IDLE || state == S_MAC || state == S_DECIDE || state == S_P0 ||
             state == S_P1 || state == S_DIV || state == S_NEXT || state == S_OUT ||
             state == S_CP || state == S_EA || state == S_EB || state == S_P2 ||
             state == S_R2 || state == S_PS);
      assert(j <= JLAST);
      if (h_v) assert(h_j <= JLAST);
      if (f_scan) assert(best <= JLAST);
      if (f_dec && s_found) assert(sidx <= JLAST);
      if (f_cand) assert(c_code <= JLAST && c_code1 == f_cc1[CODE_W-1:0]);
      if (c_valid || m_valid) assert(f_cand);
      // a pending Q_next only for a candidate
      if (c_has_next) assert(c_valid);
      // one ready at a time: never an input beat while an event is presented
      assert(!(s_ready && m_valid));
    end
  // Detector output bounds: the code is 1..CODES; the fraction is clamped to +-2^(FRAC_W-1), so
  // the arrival is within DECIM 2^(FRAC_W-1) of n 2^FRAC_W (mod 2^ARR_W); the margin is a difference of two
  // scores in SCORE_W bits (by construction).
  localparam integer F_SPAN = DECIM * HALF_I;
  // (the arrival is a time stamp: it wraps with the sample index, so the offset is taken mod
  // 2^ARR_W)
  wire signed [ARR_W-1:0] f_off = m_arrival - {1'b0, c_n, {FRAC_W{1'b0}}};
  always @(*)
    if (f_past_valid && !rst) begin
      if (f_ev) assert(fmag <= HALF);
      if (state == S_DIV || state == S_NEXT || state == S_OUT) assert(f_ev && dsel <= 2'd2);
      if (state == S_OUT) assert(dsel == 2'd2);
      if (m_valid) begin
        assert(m_code >= 1 && m_code <= CODES);
        assert(f_off >= -F_SPAN && f_off <= F_SPAN);
      end
      // the arrival's fraction term is current from the second score's division on
      if (f_ev && dsel == 2'd2 && (state == S_DIV || state == S_NEXT || state == S_OUT))
        assert(frac_d == times_decim(frac_x));
    end
  // The MAC accumulator is exact: acc +- prod never leaves AW signed bits (the sum one bit wider
  // equals its AW-bit value sign-extended).
  wire signed [AW:0] f_sum = {acc[AW-1], acc} + ({prod_x[AW-1], prod_x} ^ {(AW+1){s2}}) +
                             {{AW{1'b0}}, s2};
  always @(*)
    if (f_past_valid && !rst && v2) assert(f_sum[AW] == f_sum[AW-1]);
  // AXI-Stream master: m_valid stays up until m_ready, and the event is stable while it waits.
  always @(posedge clk)
    if (f_past_valid && !$past(rst) && !rst && $past(m_valid && !m_ready)) begin
      assert(m_valid);
      assert(m_code == $past(m_code) && m_arrival == $past(m_arrival) &&
             m_score == $past(m_score) && m_margin == $past(m_margin));
    end
`endif
endmodule

`default_nettype wire
