// correlator_bank: the baseband matched-filter bank, bit-exact to CorrelatorBankFixed
// (model/dsp/correlator_bank.cpp, docs/architecture.md).
//
// What it computes, per full-rate input y[n] (signed DATA_W, DATA_FRAC fraction bits):
//   B[n]   = q_mix(y[n] * LO_COS[n mod P]), q_mix(y[n] * -LO_SIN[n mod P])   (mixer)
//   acc    = sum_{i<P} B[n-i]             moving sum over one carrier cycle, DEC_W, exact
//   E[n]   = sum_{i<WINDOW} y[n-i]^2      running energy, ENERGY_W unsigned, exact
// and after every DECIM-th input (one output group of CODES beats, j = 0 .. CODES-1):
//   Bd[k]  = acc                          (decimation)
//   F[k]   = q_chip(sum_{i<TAPS} g[i] Bd[k-i])            chip filter, FIR_W exact accumulator
//   C_j[k] = sum_{m<CHIPS} s_j(m) F[k - (CHIPS-1-m) CHIP_STEP]   combiner, exact, per code j
//   Cq_j   = q_corr(C_j),  P_j = Re(Cq_j)^2 + Im(Cq_j)^2,  Q_j = P_j * WEIGHTS[j]
// Quantizers q_mix / q_chip / q_corr: round half up (add half an LSB, arithmetic shift right
// by MIX_SHIFT / CHIP_SHIFT / CORR_SHIFT), then saturate to MIX_W / CHIP_W / CORR_W; each is
// computed one bit wider than the wider of its input and output (no 64-bit logic). They
// cannot saturate for in-range data (the model sizes them so) but saturate exactly like it.
// -LO_SIN is a table negated at elaboration (|LO_SIN| <= 2^(LO_W-1)-1, so it fits), so
// y * -sin = -(y * sin) exactly, as the model.
// Every other node is exact (no rounding, no overflow):
//   y*lo: DATA_W+LO_W;  acc: DEC_W = MIX_W+ceil(log2 P);  FIR acc: FIR_W (the model's bound of
//   sum |g||Bd|, so every partial sum fits too);  C: COMB_W = CHIP_W+ceil(log2 CHIPS);
//   P: 2 CORR_W bits unsigned (holds 2^(2 CORR_W-1));  Q: the low WEIGHTED_W bits of the
//   2 CORR_W + WEIGHT_W product (its top bits are provably zero);  y^2: 2 DATA_W;
//   E: ENERGY_W = 2 DATA_W-1+ceil(log2 WINDOW) (E + y^2 <= (WINDOW+1) 2^(2 DATA_W-2) fits,
//   so E is updated in two steps, + y^2 then - y_old^2).
//
// Architecture: a front end and a back end with three engines sharing one multiplier.
//   Front end (6 clocks per input sample): one signed DATA_W x max(LO_W,DATA_W) multiplier
//     (registered operands and product) does y*y, y*cos, y*-sin and y_old*y_old in that
//     order, cos / -sin from a ROM (its read address one clock ahead); the B and y
//     histories are memories; E += y^2 and E -= y_old^2 share one adder. After the last
//     input of a decimation group, the hand-off clock (which also accepts the next input,
//     so it costs no extra cycle unless the back end is more than one output behind or
//     three outputs' E are unread; then the front end waits) writes Bd = acc into the Bd
//     history and pushes E into the energy ring (a 4-word memory, at most 3 entries).
//   Back end: ONE unsigned 16x16 multiplier (registered limb operands, registered product)
//     in sign-magnitude: every wide operand is split into 16-bit limbs of its magnitude, the
//     limb product is shifted by 16 (la+lb) and added or subtracted (one adder: the product
//     is inverted and the carry-in set when negative). Exact integer arithmetic,
//     so the order of the partial products does not change any result. Three clients, in
//     priority order W > SQ > FIR, each issuing one limb product per clock:
//     FIR (stage A): per output, lane re then lane im, TAPS taps, ceil(DEC_W/16) x
//       ceil(TAP_W/16) limb products per tap, from the Bd history (TAPS+1 deep, so the next
//       Bd can be written while a FIR runs) into one FIR_W accumulator; F_re is quantized
//       while the first im product is accumulated, F_im after the last. The history is read
//       one tap ahead: the tap being multiplied is a registered magnitude and sign (no
//       negation between the memory and the multiplier), which costs one priming clock per
//       output.
//     Combiner (no multiplier): per output, one round per code; each round reads the CHIPS
//       taps F[k - (CHIPS-1-m) CHIP_STEP] from the F history (one per clock; the read
//       address steps from a register holding the next address, mod FN) into two
//       COMB_W accumulators (re, im; C +- F on one adder each), then quantizes them into
//       the Cq registers (and code j's word of the group buffer's Cq memory) and clears
//       them: CHIPS + 2 clocks per round, (CHIPS + 2) CODES per output (81 at the
//       defaults, within the 120).
//     SQ: Re^2 + Im^2 per code (2 ceil(CORR_W/16)^2 limb products) into P (one register,
//       read by W: a code's SQ starts only when W has issued the previous code's products).
//     W: P * w_j (ceil(2 CORR_W/16) x ceil(WEIGHT_W/16) limb products), the last sum
//       written from the Q accumulator into code j's word of the group buffer's Q memory.
//     The FIR of output k+1 runs in the clocks the SQ/W engines of output k leave free.
//   Output: a ping-pong group buffer, two synchronous-read memories (Q: WEIGHTED_W, Cq:
//     2 CORR_W wide) of 2 banks x 2^ceil(log2 CODES) words, address {bank, j}. The back end
//     writes one bank while the consumer reads the other; a finished group is presented
//     beat by beat, the read address looking one beat ahead (the address of the beat
//     shown next clock), so m_weighted / m_corr are the memories' output registers and do
//     not change while a beat waits. The back end starts a new group only when a bank is
//     free (not while two finished groups are unread). E of each group waits in the energy
//     ring (a memory read one group ahead: m_energy is its output register) from the
//     hand-off until the consumer takes the group's last beat; n is a
//     counter advanced by DECIM at that beat; F (debug) is one register pair per bank.
//     The memories are marked no_rw_check: a read of the word being written can only
//     happen on a word the consumer does not look at (a bank with no finished group, or a
//     history entry outside the window in use), so yosys need not emulate read-old-data
//     (it cost a registered copy of the write data and a bypass mux per memory).
//   Limb products per output at the defaults (DEC_W 23, TAP_W 16, CORR_W 16, TAPS 20,
//     CODES 9): FIR 2*20*2 = 80 (+ 1 priming clock), SQ 9*2 = 18, W 9*2 = 18: 117 <= 120 = 6
//     DECIM clocks.
// Throughput: 6 clocks per input sample when the back end keeps up, i.e. when both its
//   multiplier, 2 TAPS ceil(DEC_W/16) ceil(TAP_W/16) + CODES (2 ceil(CORR_W/16)^2 +
//   ceil(2 CORR_W/16) ceil(WEIGHT_W/16)), and its combiner, (CHIPS + 2) CODES, take
//   <= 6 DECIM clocks per output (plus a few clocks of pipeline slack; model/hw/realtime.hpp);
//   otherwise the back end sets the pace (the front end waits at a decimation point). 6
//   clocks at the defaults (117 and 81 <= 120; tested: one input every 6 clocks is never
//   refused). A 15-chip family of 15 codes needs 255 combiner clocks per output: DECIM >= 50
//   at 6 clocks per sample (`ranging verify` checks the rule against the paced RTL).
// Latency: last input of a decimation group to the group's first beat: about 2 TAPS
//   ceil(DEC_W/16) ceil(TAP_W/16) + 5 (FIR) + (CHIPS+2) CODES + 8 clocks when idle (~175
//   at the defaults), more when the previous output's SQ/W work overlaps; the last beat
//   CODES-1 clocks later when the consumer takes one beat per clock. Two finished groups
//   are buffered, so a consumer that takes up to about 6 DECIM clocks per group on average
//   does not slow the front end; tested at the defaults: one input every 6 clocks is never
//   refused while the consumer takes a group's beats one per clock and then is busy 91
//   clocks (100 clocks per group; measured outside the tests: still none refused at 119
//   clocks per group, 120 refused of 8700 at 122).
// Multipliers (synth_ice40 -dsp): 2 SB_MAC16 at the defaults (front 16x16 signed, back 16x16
//   unsigned). Memories (synchronous read, no reset, EBR): B history PERIOD x 2 MIX_W,
//   y history WINDOW x DATA_W (y, not y^2: y_old^2 is recomputed), Bd history (TAPS+1) x
//   2 DEC_W, F history ((CHIPS-1) CHIP_STEP + 1) x 2 CHIP_W, group buffer Q and Cq (above),
//   energy ring 4 x ENERGY_W, LO ROM 2 PERIOD x max(LO_W,DATA_W).
//   Histories are cleared lazily: a fill flag/counter per history masks entries not
//   written since reset to zero, so after reset the outputs equal a fresh model's without a
//   clearing pass. The group buffer is not cleared: its words are undefined while m_valid
//   is low (AXI-Stream allows it).
// Resources (yosys synth_ice40 -dsp, default parameters, standalone with every port
//   connected, nextpnr-ice40 --up5k --pack-only): 2 SB_MAC16, 20 SB_RAM40_4K, 1795 logic
//   cells. How it got there: docs/bitstream.md ("Resource history").
//
// Streams (AXI4-Stream rules, data stable while valid && !ready):
//   s_*: one beat per input sample (s_ready high only when the front end is idle).
//   m_*: one group of CODES beats per decimated output, beat j carrying code j:
//     m_weighted = Q_j, m_code = j, m_last = (j == CODES-1), m_corr_re/im = Cq_j (debug);
//     m_energy = E, m_index = n (the input sample index of the output), m_chip_re/im = F_q
//     (debug) are the group's and equal on all its beats. A group is presented only when
//     complete; the next one follows without a gap when it is finished too. No output is
//     lost: with both banks full the back end waits (the FIR of the next output may run;
//     then the front end waits).
// Reset: synchronous, active high; clears every control register, counter, phase, fill flag
//   and accumulator whose value carries over (acc, E); datapath registers that are always
//   loaded before they are read (multiplier operands, quantized words, accumulators started
//   by a first product) are not reset.
`default_nettype none

// DATA_FRAC, MIX_FRAC, COMB_W and POWER_W are part of the documented interface (formats of
// the streams) but the arithmetic only needs the shifts and widths derived from them.
/* verilator lint_off UNUSEDPARAM */
module correlator_bank #(
  parameter integer DATA_W = 16, DATA_FRAC = 14,
  parameter integer PERIOD = 25,
  parameter integer LO_W = 16,
  parameter integer MIX_W = 18, MIX_FRAC = 16, MIX_SHIFT = 13,
  parameter integer DECIM = 20,
  parameter integer DEC_W = 23,
  parameter integer TAPS = 20, TAP_W = 16,
  parameter integer FIR_W = 42,
  parameter integer CHIP_W = 20, CHIP_SHIFT = 20,
  parameter integer CHIPS = 7, CODES = 9,
  parameter integer CHIP_STEP = 5,
  parameter integer COMB_W = 23, CORR_W = 16, CORR_SHIFT = 7,
  parameter integer POWER_W = 32, WEIGHT_W = 16, WEIGHTED_W = 48,
  parameter integer WINDOW = 1000,
  parameter integer ENERGY_W = 41,
  parameter integer TIME_W = 40,
  parameter integer CODE_W = 4,  // width of m_code, >= $clog2(CODES) (the detector's CODE_W)
  parameter [PERIOD*LO_W-1:0]     LO_COS = 400'h7bfa702a5d4e4495278e0809e804c980ae6a987388fe8103810388fe9873ae6ac980e8040809278e44955d4e702a7bfa7fff,
  parameter [PERIOD*LO_W-1:0]     LO_SIN = 400'he02bc256a86193ee8645804282458c309d61b4c4d0e2eff5100b2f1e4b3c629f73d07dbb7fbe79bb6c12579f3daa1fd50000,
  parameter [TAPS*TAP_W-1:0]      TAP_VALUES = 320'h0000003c030e0aca22003b1a58e6748c7ffe7fff755f655052d446bc37782d8c23d61b4716330f48,
  parameter [CODES*CHIPS-1:0]     CODE_BITS = 63'h6a42d8c44fa3ee53,
  parameter [CODES*WEIGHT_W-1:0]  WEIGHTS = 144'hd6be5bc4b762504964e54068378365789e12
) (
  /* verilator lint_on UNUSEDPARAM */
  input  wire clk, rst,
  input  wire signed [DATA_W-1:0] s_data, input wire s_valid, output wire s_ready,
  output wire m_valid, input wire m_ready,
  output wire [WEIGHTED_W-1:0]       m_weighted,
  output wire [CODE_W-1:0]           m_code,
  output wire                        m_last,
  output wire [ENERGY_W-1:0]         m_energy,
  output wire [TIME_W-1:0]           m_index,
  output wire signed [CHIP_W-1:0]    m_chip_re, m_chip_im,
  output wire signed [CORR_W-1:0]    m_corr_re, m_corr_im
);
  // ---------------------------------------------------------------- helpers
  function integer imax;
    input integer a, b;
    begin
      imax = (a > b) ? a : b;
    end
  endfunction
  function integer wbits;  // width of a counter/index holding 0..v-1 (at least 1)
    input integer v;
    begin
      wbits = (v <= 2) ? 1 : $clog2(v);
    end
  endfunction
  function integer nlimbs;  // 16-bit limbs of a w-bit unsigned magnitude
    input integer w;
    begin
      nlimbs = (w + 15) / 16;
    end
  endfunction

  localparam integer LW      = 16;                          // back-end limb width
  localparam integer FN      = (CHIPS - 1) * CHIP_STEP + 1;  // F history depth
  localparam integer BDN     = TAPS + 1;                    // Bd history depth
  localparam integer PA_W    = wbits(PERIOD);
  localparam integer YA_W    = wbits(WINDOW);
  localparam integer BA_W    = wbits(BDN);
  localparam integer FA_W    = wbits(FN);
  localparam integer FB_W    = imax(LO_W, DATA_W);
  localparam integer FP_W    = DATA_W + FB_W;               // front-end product
  localparam integer DP_W    = wbits(DECIM);
  localparam integer EX_W    = imax(ENERGY_W, FP_W) + 1;    // energy update width
  localparam integer CA_W    = (CHIPS == 1) ? CHIP_W + 1 : COMB_W;  // -F must fit
  localparam integer PW_W    = 2 * CORR_W;                  // exact |Cq|^2 sum
  // limb counts
  localparam integer NBA     = nlimbs(DEC_W);               // |Bd| <= 2^(DEC_W-1)
  localparam integer NTB     = nlimbs(TAP_W);
  localparam integer NC      = nlimbs(CORR_W);
  localparam integer NP      = nlimbs(PW_W);
  localparam integer NW      = nlimbs(WEIGHT_W);
  localparam integer SHMAX   = imax(imax(NBA + NTB - 2, 2 * NC - 2), NP + NW - 2);
  localparam integer SH_W    = wbits(SHMAX + 1);
  localparam integer XW      = imax(imax(FIR_W, PW_W), imax(WEIGHTED_W, 2 * LW)) + 1;
  localparam integer TAPM_W  = NTB * LW;
  localparam integer WTP_W   = NW * LW;
  // index widths
  localparam integer TI_W    = wbits(TAPS + 1);
  localparam integer CI_W    = wbits(CHIPS);
  localparam integer JI_W    = wbits(CODES);
  localparam integer DIST_W  = wbits(FN + 1);
  localparam integer LBA_W   = wbits(NBA);
  localparam integer LTB_W   = wbits(NTB);
  localparam integer LC_W    = wbits(NC);
  localparam integer LP_W    = wbits(NP);
  localparam integer LWT_W   = wbits(NW);

  // Sized constants (keep every comparison at its operand's width).
  localparam integer P_LAST_I = PERIOD - 1;
  localparam [PA_W-1:0] P_LAST = P_LAST_I[PA_W-1:0];
  localparam integer Y_LAST_I = WINDOW - 1;
  localparam [YA_W-1:0] Y_LAST = Y_LAST_I[YA_W-1:0];
  localparam integer D_LAST_I = DECIM - 1;
  localparam [DP_W-1:0] D_LAST = D_LAST_I[DP_W-1:0];
  localparam integer BD_LAST_I = BDN - 1;
  localparam [BA_W-1:0] BD_LAST = BD_LAST_I[BA_W-1:0];
  localparam integer TAPS_N_I = TAPS;
  localparam [TI_W-1:0] TAPS_N = TAPS_N_I[TI_W-1:0];
  localparam integer T_LAST_I = TAPS - 1;
  localparam [TI_W-1:0] T_LAST = T_LAST_I[TI_W-1:0];
  localparam integer F_LAST_I = FN - 1;
  localparam [FA_W-1:0] F_LAST = F_LAST_I[FA_W-1:0];
  localparam integer FN_N_I = FN;
  localparam [DIST_W-1:0] FN_N = FN_N_I[DIST_W-1:0];
  localparam integer DIST0_I = FN - 1;
  localparam [DIST_W-1:0] DIST0 = DIST0_I[DIST_W-1:0];
  localparam integer STEP_D_I = CHIP_STEP;
  localparam [DIST_W-1:0] STEP_D = STEP_D_I[DIST_W-1:0];
  localparam [FA_W:0] STEP_A = STEP_D_I[FA_W:0];
  localparam [FA_W:0] FN_A = FN_N_I[FA_W:0];
  localparam integer C_LAST_I = CHIPS - 1;
  localparam [CI_W-1:0] C_LAST = C_LAST_I[CI_W-1:0];
  localparam integer J_LAST_I = CODES - 1;
  localparam [JI_W-1:0] J_LAST = J_LAST_I[JI_W-1:0];
  localparam integer NBA_L_I = NBA - 1;
  localparam [LBA_W-1:0] NBA_L = NBA_L_I[LBA_W-1:0];
  localparam integer NTB_L_I = NTB - 1;
  localparam [LTB_W-1:0] NTB_L = NTB_L_I[LTB_W-1:0];
  localparam integer NC_L_I = NC - 1;
  localparam [LC_W-1:0] NC_L = NC_L_I[LC_W-1:0];
  localparam integer NP_L_I = NP - 1;
  localparam [LP_W-1:0] NP_L = NP_L_I[LP_W-1:0];
  localparam integer NW_L_I = NW - 1;
  localparam [LWT_W-1:0] NW_L = NW_L_I[LWT_W-1:0];
  localparam [SH_W-1:0] SH_ZERO = {SH_W{1'b0}};
  // DECIM as a TIME_W-bit constant (bit by bit: no unsized operand in a concatenation)
  function [TIME_W-1:0] decim_time;
    input integer v;
    integer b;
    begin
      decim_time = {TIME_W{1'b0}};
      for (b = 0; b < 32 && b < TIME_W; b = b + 1) decim_time[b] = v[b];
    end
  endfunction
  localparam [TIME_W-1:0] DECIM_T = decim_time(DECIM);

  // Elaboration-time tables: |g| per tap (padded to whole limbs), -LO_SIN, padded weights.
  function [TAPS*TAPM_W-1:0] tap_abs_all;
    input [TAPS*TAP_W-1:0] v;
    integer t;
    reg [TAP_W-1:0] x;
    begin
      tap_abs_all = 0;
      for (t = 0; t < TAPS; t = t + 1) begin
        x = v[t*TAP_W +: TAP_W];
        if (x[TAP_W-1]) x = -x;
        tap_abs_all[t*TAPM_W +: TAP_W] = x;
      end
    end
  endfunction
  function [PERIOD*FB_W-1:0] lo_neg_all;
    input [PERIOD*LO_W-1:0] v;
    integer t;
    reg [FB_W-1:0] x;
    begin
      for (t = 0; t < PERIOD; t = t + 1) begin
        x = {{(FB_W-LO_W){v[t*LO_W+LO_W-1]}}, v[t*LO_W +: LO_W]};
        lo_neg_all[t*FB_W +: FB_W] = -x;
      end
    end
  endfunction
  function [PERIOD*FB_W-1:0] lo_ext_all;
    input [PERIOD*LO_W-1:0] v;
    integer t;
    begin
      for (t = 0; t < PERIOD; t = t + 1)
        lo_ext_all[t*FB_W +: FB_W] = {{(FB_W-LO_W){v[t*LO_W+LO_W-1]}}, v[t*LO_W +: LO_W]};
    end
  endfunction
  function [CODES*WTP_W-1:0] wt_pad_all;
    input [CODES*WEIGHT_W-1:0] v;
    integer t;
    begin
      wt_pad_all = 0;
      for (t = 0; t < CODES; t = t + 1) wt_pad_all[t*WTP_W +: WEIGHT_W] = v[t*WEIGHT_W +: WEIGHT_W];
    end
  endfunction
  localparam [TAPS*TAPM_W-1:0] TAP_ABS = tap_abs_all(TAP_VALUES);
  localparam [PERIOD*FB_W-1:0] LO_C = lo_ext_all(LO_COS);
  localparam [PERIOD*FB_W-1:0] LO_NS = lo_neg_all(LO_SIN);
  localparam [CODES*WTP_W-1:0] WT_PAD = wt_pad_all(WEIGHTS);

  // Constant tables read with a variable index: written as compare loops so synthesis sees a
  // small truth table of the index bits instead of a shifter over the whole parameter.
  function [TAPM_W:0] tap_rom;  // {sign of g, |g|}
    input [TI_W-1:0] i;
    integer t;
    begin
      tap_rom = 0;
      for (t = 0; t < TAPS; t = t + 1)
        if (i == t[TI_W-1:0]) tap_rom = {TAP_VALUES[t*TAP_W + TAP_W - 1], TAP_ABS[t*TAPM_W +: TAPM_W]};
    end
  endfunction
  function [WTP_W-1:0] wt_rom;
    input [JI_W-1:0] i;
    integer t;
    begin
      wt_rom = 0;
      for (t = 0; t < CODES; t = t + 1) if (i == t[JI_W-1:0]) wt_rom = WT_PAD[t*WTP_W +: WTP_W];
    end
  endfunction
  function code_rom;  // chip m of code j is a 1
    input [JI_W-1:0] j;
    input [CI_W-1:0] m;
    integer t, u;
    begin
      code_rom = 1'b1;
      for (t = 0; t < CODES; t = t + 1)
        for (u = 0; u < CHIPS; u = u + 1)
          if (j == t[JI_W-1:0] && m == u[CI_W-1:0]) code_rom = CODE_BITS[t*CHIPS + u];
    end
  endfunction

  // Quantizers q_mix / q_chip / q_corr: round half up by SHIFT, saturate to the output width
  // (rtl/fx_quantize.v, instanced beside the node each one closes).

  // ================================================================ front end
  localparam [2:0] FE_IDLE = 3'd0, FE_M1 = 3'd1, FE_M2 = 3'd2, FE_M3 = 3'd3,
                   FE_M4 = 3'd4, FE_M5 = 3'd5, FE_HAND = 3'd6;
  reg [2:0] fe_state;
  reg signed [DATA_W-1:0] fa;
  reg signed [FB_W-1:0]   fb;
  reg signed [FP_W-1:0]   fp;
  reg signed [MIX_W-1:0]  mix_re, mix_im;
  reg signed [DEC_W-1:0]  acc_re, acc_im;
  reg [ENERGY_W-1:0]      energy;
  reg [PA_W-1:0]          phase, b_ptr;
  reg                     b_full, y_full;
  reg [YA_W-1:0]          y_ptr;
  reg [DP_W-1:0]          dphase;
  // hand-off: Bd history write pointer/fill, one pending Bd, 2-entry energy queue
  reg [BA_W-1:0]          bd_wptr;
  reg [TI_W-1:0]          bd_cnt;
  reg                     bd_pend;
  reg [1:0]               eq_n, eq_w, eq_r;  // ring of group energies (up to 3 in e_mem)
  wire                    e_pop;   // consumer took the oldest ring entry's last beat
  wire                    a_start; // FIR takes the pending Bd

  // B history (PERIOD x {re, im}) and y history (WINDOW x y): synchronous-read memories.
  (* no_rw_check *) reg [2*MIX_W-1:0] b_mem [0:PERIOD-1];
  reg [2*MIX_W-1:0] b_rd;
  (* no_rw_check *) reg [DATA_W-1:0]  y_mem [0:WINDOW-1];
  reg [DATA_W-1:0]  y_rd;
  // y is written from fa in FE_M3 (its last clock as an operand; y_rd is not used after FE_M3)
  always @(posedge clk) begin
    if (fe_state == FE_M5) b_mem[b_ptr] <= {mix_re, mix_im};
    if (fe_state == FE_M3) y_mem[y_ptr] <= fa;
    b_rd <= b_mem[b_ptr];
    y_rd <= y_mem[y_ptr];
  end
  // Energy ring: 4-word synchronous-read memory (EBR) holding at most 3 group energies; the
  // read address looks one group ahead, so e_rd is E of the group presented and stays put.
  // A write never hits the word read for a presented group (at most 3 of 4 words are live).
  (* ram_style = "block", no_rw_check *) reg [ENERGY_W-1:0] e_mem [0:3];
  reg [ENERGY_W-1:0] e_rd;
  wire [1:0] eq_r_nx = eq_r + {1'b0, e_pop};
  always @(posedge clk) begin
    if (hand) e_mem[eq_w] <= energy_new;
    e_rd <= e_mem[eq_r_nx];
  end
  // LO table ROM (EBR): word 2p = cos[p], 2p+1 = -sin[p]; the address looks one clock ahead
  // (cos while idle / accepting, -sin in FE_M1), phase changes only in FE_M5.
  (* ram_style = "block" *) reg [FB_W-1:0] lo_mem [0:2*PERIOD-1];
  reg [FB_W-1:0] lo_rd;
  integer lo_t;
  initial begin
    for (lo_t = 0; lo_t < PERIOD; lo_t = lo_t + 1) begin
      lo_mem[2*lo_t]     = LO_C[lo_t*FB_W +: FB_W];
      lo_mem[2*lo_t + 1] = LO_NS[lo_t*FB_W +: FB_W];
    end
  end
  always @(posedge clk) lo_rd <= lo_mem[{phase, fe_state == FE_M1}];
  // Bd history: written by the front end at a hand-off, read by the FIR.
  (* no_rw_check *) reg [2*DEC_W-1:0] bd_mem [0:BDN-1];
  reg [2*DEC_W-1:0] bd_rd;
  reg [BA_W-1:0]    a_addr_nx;
  wire [BA_W-1:0] bd_wptr_next = (bd_wptr == BD_LAST) ? {BA_W{1'b0}} : bd_wptr + 1'b1;
  wire hand_ok = !bd_pend && (eq_n != 2'd3);
  wire hand = hand_ok && (fe_state == FE_HAND);
  always @(posedge clk) begin
    if (hand) bd_mem[bd_wptr_next] <= {acc_re, acc_im};
    bd_rd <= bd_mem[a_addr_nx];
  end

  // FE_HAND (after the last sample of a group) accepts the next sample when the hand-off happens
  assign s_ready = (fe_state == FE_IDLE) || hand;
  wire accept = s_valid && s_ready;
  wire [YA_W-1:0] y_ptr_next = (y_ptr == Y_LAST) ? {YA_W{1'b0}} : y_ptr + 1'b1;
  wire [MIX_W-1:0] q_mix_fp;
  wire unused_mix_fits;
  fx_quantize #(.IN_W(FP_W), .OUT_W(MIX_W), .SHIFT(MIX_SHIFT), .ROUNDING(1), .SATURATE(1))
    u_q_mix (.x(fp), .y(q_mix_fp), .fits(unused_mix_fits));
  wire signed [DATA_W-1:0] y_old = y_full ? y_rd : {DATA_W{1'b0}};
  wire signed [MIX_W-1:0]  b_old_re = b_full ? b_rd[2*MIX_W-1:MIX_W] : {MIX_W{1'b0}};
  wire signed [MIX_W-1:0]  b_old_im = b_full ? b_rd[MIX_W-1:0] : {MIX_W{1'b0}};
  // y^2 and y_old^2 are non-negative and below 2^(2 DATA_W-2) + 1.
  // E + y^2 (FE_M4) and E - y_old^2 (FE_M5) on one adder: E + (fp ^ -sub) + sub
  wire e_sub = (fe_state == FE_M5);
  /* verilator lint_off UNUSEDSIGNAL */
  wire [EX_W:0] energy_s = {{(EX_W-ENERGY_W){1'b0}}, energy, 1'b1} +
                           {{{(EX_W-FP_W){1'b0}}, fp} ^ {EX_W{e_sub}}, e_sub};
  /* verilator lint_on UNUSEDSIGNAL */
  wire [ENERGY_W-1:0] energy_new = energy;  // final in FE_HAND

  always @(posedge clk) begin
    if (rst) begin
      fe_state <= FE_IDLE;
      acc_re <= 0; acc_im <= 0; energy <= 0;
      phase <= 0; b_ptr <= 0; b_full <= 1'b0; y_full <= 1'b0;
      y_ptr <= Y_LAST;  // the model pre-increments the window index
      dphase <= 0;
      bd_wptr <= BD_LAST; bd_cnt <= 0; bd_pend <= 1'b0;
      eq_n <= 2'd0; eq_w <= 2'd0; eq_r <= 2'd0;
    end else begin
      if (a_start) bd_pend <= 1'b0;
      // energy ring (E of the groups handed off and not yet read): push at a hand-off, pop
      // when the consumer takes a group's last beat (both may happen at once)
      if (hand) eq_w <= eq_w + 1'b1;
      eq_r <= eq_r_nx;
      if (hand && !e_pop) eq_n <= eq_n + 1'b1;
      else if (e_pop && !hand) eq_n <= eq_n - 1'b1;
      if (hand) begin
        bd_wptr <= bd_wptr_next;
        if (bd_cnt != TAPS_N) bd_cnt <= bd_cnt + 1'b1;
        bd_pend <= 1'b1;
      end
      case (fe_state)
        FE_IDLE, FE_HAND: if (accept) begin
          fa <= s_data;
          fb <= {{(FB_W-DATA_W){s_data[DATA_W-1]}}, s_data};
          y_ptr <= y_ptr_next;  // y_rd holds y_mem[y_ptr] from FE_M2 on
          fe_state <= FE_M1;
        end else if (hand) begin
          fe_state <= FE_IDLE;
        end
        FE_M1: begin
          fp <= fa * fb;  // y^2
          fb <= lo_rd;    // cos
          fe_state <= FE_M2;
        end
        FE_M2: begin
          fp <= fa * fb;  // y cos
          energy <= energy_s[ENERGY_W:1];  // E + y^2
          fb <= lo_rd;    // -sin
          fe_state <= FE_M3;
        end
        FE_M3: begin    // y_mem written this cycle (from fa)
          fp <= fa * fb;  // y (-sin)
          mix_im <= q_mix_fp;  // re word; moves to mix_re next clock (one LUT fanout)
          fa <= y_old;
          fb <= {{(FB_W-DATA_W){y_old[DATA_W-1]}}, y_old};
          fe_state <= FE_M4;
        end
        FE_M4: begin
          fp <= fa * fb;  // y_old^2
          mix_re <= mix_im;
          mix_im <= q_mix_fp;
          fe_state <= FE_M5;
        end
        FE_M5: begin  // b_mem written this cycle
          energy <= energy_s[ENERGY_W:1];  // E - y_old^2
          acc_re <= acc_re + {{(DEC_W-MIX_W){mix_re[MIX_W-1]}}, mix_re}
                           - {{(DEC_W-MIX_W){b_old_re[MIX_W-1]}}, b_old_re};
          acc_im <= acc_im + {{(DEC_W-MIX_W){mix_im[MIX_W-1]}}, mix_im}
                           - {{(DEC_W-MIX_W){b_old_im[MIX_W-1]}}, b_old_im};
          if (b_ptr == P_LAST) begin
            b_ptr <= 0;
            b_full <= 1'b1;
          end else begin
            b_ptr <= b_ptr + 1'b1;
          end
          if (y_ptr == Y_LAST) y_full <= 1'b1;
          phase <= (phase == P_LAST) ? {PA_W{1'b0}} : phase + 1'b1;
          if (dphase == D_LAST) begin
            dphase <= 0;
            fe_state <= FE_HAND;
          end else begin
            dphase <= dphase + 1'b1;
            fe_state <= FE_IDLE;
          end
        end
        default: fe_state <= FE_IDLE;
      endcase
    end
  end

  // ================================================================ back end
  // ---- shared multiplier pipeline: issue (operands, tag s1) -> product (tag s2) -> land
  localparam [1:0] CL_A = 2'd0, CL_SQ = 2'd1, CL_W = 2'd2;
  reg [LW-1:0]    ma, mb;
  reg [2*LW-1:0]  mp;
  reg             s1_v, s2_v;
  reg [1:0]       s1_cl, s2_cl;
  reg             s1_first, s2_first, s1_last, s2_last, s1_neg, s2_neg, s1_lane, s2_lane;
  reg [SH_W-1:0]  s1_sh, s2_sh;
  reg [JI_W-1:0]  s1_j, s2_j;
`ifdef FORMAL_NARROW_PRODUCT
  // Formal abstraction (formal/correlator_bank.job): the limb product of the low F_MA_W x F_MB_W
  // operand bits only, the widest any client presents (its FORMAL block asserts the upper bits
  // are zero for every product issued, so the products are the same): a 16x16 multiplier with
  // free upper bits is too slow for the solver at the job's small widths.
  localparam integer F_MA_W = (imax(imax(DEC_W, CORR_W), 2 * CORR_W) < LW) ? imax(imax(DEC_W, CORR_W), 2 * CORR_W) : LW;
  localparam integer F_MB_W = (imax(imax(TAP_W, CORR_W), WEIGHT_W) < LW) ? imax(imax(TAP_W, CORR_W), WEIGHT_W) : LW;
  wire [F_MA_W+F_MB_W-1:0] f_mp = ma[F_MA_W-1:0] * mb[F_MB_W-1:0];
  always @(posedge clk) mp <= {{(2*LW-F_MA_W-F_MB_W){1'b0}}, f_mp};
`else
  always @(posedge clk) mp <= ma * mb;
`endif
  /* verilator lint_off UNUSEDSIGNAL */
  wire [XW-1:0] psh = {{(XW-2*LW){1'b0}}, mp} << {s2_sh, 4'b0000};
  /* verilator lint_on UNUSEDSIGNAL */

  // ---- stage A: chip FIR
  reg             a_busy, a_lane, a_prime, r_lane;
  reg [BA_W-1:0]  a_base, a_addr;
  reg [TI_W-1:0]  a_cnt, a_i, r_i;
  wire            a_iss;          // a FIR product issues this clock
  reg [LBA_W-1:0] a_la;
  reg [LTB_W-1:0] a_lb;
  reg [FIR_W-1:0] facc;
  wire [CHIP_W-1:0] q_chip_facc;
  wire unused_chip_fits;
  fx_quantize #(.IN_W(FIR_W), .OUT_W(CHIP_W), .SHIFT(CHIP_SHIFT), .ROUNDING(1), .SATURATE(1))
    u_q_chip (.x(facc), .y(q_chip_facc), .fits(unused_chip_fits));
  reg             fq_pend, fq_lane;
  reg [CHIP_W-1:0] fres_re, fres_im;
  reg             fres_valid;
  wire a_tap_end  = (a_la == NBA_L) && (a_lb == NTB_L);
  wire a_first    = (a_i == {TI_W{1'b0}}) && (a_la == {LBA_W{1'b0}}) && (a_lb == {LTB_W{1'b0}});
  wire a_last     = (a_i == T_LAST) && a_tap_end;
  wire [BA_W-1:0] a_addr_dec = (a_addr == {BA_W{1'b0}}) ? BD_LAST : a_addr - 1'b1;
  // The FIR reads one tap ahead: bd_rd holds the word of the tap after the one being
  // multiplied (a_addr, index r_i in lane r_lane), and the magnitude and sign of the tap being
  // multiplied are registers (bd_mag_r, bd_sgn_r), loaded from bd_rd when that tap's last
  // product issues (and once at the start, a_prime). So no negation sits between the memory
  // read and the multiplier's operand; the FIR costs one priming clock per output.
  wire a_adv = a_iss && a_tap_end;
  wire signed [DEC_W-1:0] bd_lane = r_lane ? bd_rd[DEC_W-1:0] : bd_rd[2*DEC_W-1:DEC_W];
  reg  [DEC_W-1:0] bd_mag_r;
  reg              bd_sgn_r;
  always @(posedge clk)
    if (a_prime || a_adv) begin
      bd_mag_r <= bd_lane[DEC_W-1] ? -bd_lane : bd_lane;
      bd_sgn_r <= bd_lane[DEC_W-1];
    end
  wire [NBA*LW-1:0] bd_mag_p = {{(NBA*LW-DEC_W){1'b0}}, bd_mag_r};
  wire a_ok = (a_i < a_cnt);  // Bd entry written since reset (else it reads as zero)
  wire [LW-1:0] a_opa = a_ok ? bd_mag_p[a_la*LW +: LW] : {LW{1'b0}};
  wire [TAPM_W:0] tap_sm = tap_rom(a_i);
  wire [TAPM_W-1:0] tap_mag = tap_sm[TAPM_W-1:0];
  wire [LW-1:0] a_opb = tap_mag[a_lb*LW +: LW];
  wire a_neg = a_ok && (bd_sgn_r ^ tap_sm[TAPM_W]);

  // ---- combiner
  localparam [1:0] C_IDLE = 2'd0, C_RUN = 2'd1, C_DRAIN = 2'd2, C_Q = 2'd3;
  reg [1:0]        c_state;
  reg [CI_W-1:0]   c_m;
  reg              c_iss1, c_dv1, c_neg;   // c_neg: chip c_m of code c_j is -1, a clock later
  reg [JI_W-1:0]   c_j;
  reg [FA_W-1:0]   f_wptr, f_rptr, f_old;
  reg [DIST_W-1:0] f_cnt, f_dist;
  reg [CA_W-1:0]   ca_re, ca_im;
  (* no_rw_check *) reg [2*CHIP_W-1:0] f_mem [0:FN-1];
  reg [2*CHIP_W-1:0] f_rd;
  wire [FA_W-1:0] f_wptr_next = (f_wptr == F_LAST) ? {FA_W{1'b0}} : f_wptr + 1'b1;
  wire [FA_W-1:0] f_oldest    = (f_wptr_next == F_LAST) ? {FA_W{1'b0}} : f_wptr_next + 1'b1;
  // One chip step back in the F ring: v + CHIP_STEP, less FN when that is >= FN.
  function [FA_W-1:0] f_adv;
    input [FA_W-1:0] v;
    /* verilator lint_off UNUSEDSIGNAL */
    reg   [FA_W:0]   s, w;
    /* verilator lint_on UNUSEDSIGNAL */
    begin
      s = {1'b0, v} + STEP_A;
      w = s - FN_A;  // used only when s >= FN: its top bit is 0
      f_adv = (s >= FN_A) ? w[FA_W-1:0] : s[FA_W-1:0];
    end
  endfunction
  // f_rnx = f_adv(f_rptr), loaded beside f_rptr: f_rptr drives the memory's read address and
  // takes f_rnx in C_RUN, so the step's adder and compare sit on f_rnx's own loop and not
  // between the read-address register (placed by the EBR) and its input.
  reg [FA_W-1:0]  f_rnx;
  // f_adv(f_oldest) = (f_wptr + 2 + CHIP_STEP) mod FN as one modular add of a constant (with
  // CHIPS >= 2, FN > CHIP_STEP), not three chained modular steps after f_wptr.
  localparam integer K2_I = (CHIPS >= 2) ? (2 + CHIP_STEP) % FN : 0;
  localparam [FA_W:0] K2_A = K2_I[FA_W:0];
  wire [FA_W-1:0] f_oldest_adv;
  if (CHIPS >= 2) begin : g_oldest_adv
    /* verilator lint_off UNUSEDSIGNAL */
    wire [FA_W:0] s2 = {1'b0, f_wptr} + K2_A;
    wire [FA_W:0] w2 = s2 - FN_A;  // used only when s2 >= FN: its top bit is 0
    /* verilator lint_on UNUSEDSIGNAL */
    assign f_oldest_adv = (s2 >= FN_A) ? w2[FA_W-1:0] : s2[FA_W-1:0];
  end else begin : g_oldest_adv1
    assign f_oldest_adv = f_adv(f_oldest);
  end
  wire signed [CHIP_W-1:0] f_rd_re = f_rd[2*CHIP_W-1:CHIP_W];
  wire signed [CHIP_W-1:0] f_rd_im = f_rd[CHIP_W-1:0];
  wire signed [CA_W-1:0] f_re_x = {{(CA_W-CHIP_W){f_rd_re[CHIP_W-1]}}, f_rd_re};
  wire signed [CA_W-1:0] f_im_x = {{(CA_W-CHIP_W){f_rd_im[CHIP_W-1]}}, f_rd_im};
  // C += s F as one adder: C + (F ^ -neg) + neg, the carry-in entering as a low bit;
  // an entry not written since reset reads as zero.
  wire [CA_W-1:0] f_re_m = (c_dv1 ? f_re_x : {CA_W{1'b0}}) ^ {CA_W{c_neg}};
  wire [CA_W-1:0] f_im_m = (c_dv1 ? f_im_x : {CA_W{1'b0}}) ^ {CA_W{c_neg}};
  /* verilator lint_off UNUSEDSIGNAL */
  wire [CA_W:0] ca_re_s = {ca_re, 1'b1} + {f_re_m, c_neg};
  wire [CA_W:0] ca_im_s = {ca_im, 1'b1} + {f_im_m, c_neg};
  /* verilator lint_on UNUSEDSIGNAL */
  wire [CORR_W-1:0] cq_re_n, cq_im_n;
  wire unused_corr_re_fits, unused_corr_im_fits;
  fx_quantize #(.IN_W(CA_W), .OUT_W(CORR_W), .SHIFT(CORR_SHIFT), .ROUNDING(1), .SATURATE(1))
    u_q_corr_re (.x(ca_re), .y(cq_re_n), .fits(unused_corr_re_fits));
  fx_quantize #(.IN_W(CA_W), .OUT_W(CORR_W), .SHIFT(CORR_SHIFT), .ROUNDING(1), .SATURATE(1))
    u_q_corr_im (.x(ca_im), .y(cq_im_n), .fits(unused_corr_im_fits));
  wire b_start;
  wire f_write = b_start;
  always @(posedge clk) begin
    if (f_write) f_mem[f_wptr_next] <= {fres_re, fres_im};
    f_rd <= f_mem[f_rptr];
  end

  // ---- SQ and W engines
  reg [CORR_W-1:0] cq_re, cq_im;
  reg              cq_valid;
  reg [JI_W-1:0]   cq_j;
  reg              sq_p;
  reg [LC_W-1:0]   sq_la, sq_lb;
  reg [PW_W-1:0]   p_w;
  reg              pw_valid;
  reg [JI_W-1:0]   pw_j;
  reg [LP_W-1:0]   w_la;
  reg [LWT_W-1:0]  w_lb;
  reg [WEIGHTED_W-1:0] q_acc;
  wire [CORR_W-1:0] sq_val = sq_p ? cq_im : cq_re;
  wire [CORR_W-1:0] sq_mag = sq_val[CORR_W-1] ? -sq_val : sq_val;
  wire [NC*LW-1:0]  sq_mag_p = {{(NC*LW-CORR_W){1'b0}}, sq_mag};
  wire sq_first = !sq_p && (sq_la == {LC_W{1'b0}}) && (sq_lb == {LC_W{1'b0}});
  wire sq_last  = sq_p && (sq_la == NC_L) && (sq_lb == NC_L);
  // SQ accumulates P in P_w, which the W engine reads while pw_valid: a code's first SQ
  // product issues only when no SQ product is in flight (so P_w of the previous code is
  // complete and pw_valid set) and pw_valid is low (W has issued all its products).
  wire sq_idle = !(s1_v && s1_cl == CL_SQ) && !(s2_v && s2_cl == CL_SQ);
  wire [NP*LW-1:0]  pw_p = {{(NP*LW-PW_W){1'b0}}, p_w};
  wire [WTP_W-1:0]  wt = wt_rom(pw_j);
  wire w_last = (w_la == NP_L) && (w_lb == NW_L);

  wire w_iss  = pw_valid;
  wire sq_iss = !pw_valid && cq_valid && (!sq_first || sq_idle);
  // F_re is written 2 clocks after the last re product issues: only when fres is free.
  assign a_iss = !w_iss && !sq_iss && a_busy && !a_prime && !(!a_lane && a_last && fres_valid);

  // ---- output: ping-pong group buffer (2 banks x 2^JI_W codes) of Q_j and {Cq_re, Cq_im}_j
  // in synchronous-read memories; the back end writes bank wr_bank, the consumer reads beat
  // rd_j of bank rd_bank; g_full counts banks holding a finished group not yet fully read.
  localparam integer GA_W = JI_W + 1;
  reg                     b_busy, wr_bank, rd_bank;
  reg [1:0]               g_full;
  reg [JI_W-1:0]          rd_j;
  reg [TIME_W-1:0]        out_index;
  reg signed [CHIP_W-1:0] chip_re0, chip_im0, chip_re1, chip_im1;  // F per bank (debug)
  (* no_rw_check *) reg [WEIGHTED_W-1:0]    q_mem [0:(1 << GA_W)-1];
  (* no_rw_check *) reg [2*CORR_W-1:0]      c_mem [0:(1 << GA_W)-1];
  reg [WEIGHTED_W-1:0]    q_rd;
  reg [2*CORR_W-1:0]      c_rd;
  wire b_tags = (s1_v && s1_cl != CL_A) || (s2_v && s2_cl != CL_A);
  wire b_done = b_busy && (c_state == C_IDLE) && !cq_valid && !pw_valid && !b_tags && !q_we;
  assign b_start = !b_busy && fres_valid && (g_full != 2'd2);
  wire m_last_w = (rd_j == J_LAST);
  wire m_take   = (g_full != 2'd0) && m_ready;
  wire g_taken  = m_take && m_last_w;
  assign e_pop = g_taken;
  assign a_start = !a_busy && bd_pend;
  // Read address look-ahead: the beat presented next clock, so q_rd/c_rd are the current
  // beat's words and stay put while it is not taken.
  wire [JI_W-1:0] rd_j_nx    = !m_take ? rd_j : (m_last_w ? {JI_W{1'b0}} : rd_j + 1'b1);
  wire            rd_bank_nx = rd_bank ^ g_taken;
  reg              q_we;   // q_acc holds the finished Q of code q_wj (written to q_mem)
  reg [JI_W-1:0]   q_wj;
  wire c_we = (c_state == C_Q) && !cq_valid;

  // FIR read address: the Bd entry of the op presented next clock.
  always @(*) begin
    if (a_start) a_addr_nx = bd_wptr;
    else if (a_prime || a_adv) a_addr_nx = (r_i == T_LAST) ? a_base : a_addr_dec;
    else a_addr_nx = a_addr;
  end

  wire [WEIGHTED_W-1:0] q_sum = (s2_first ? {WEIGHTED_W{1'b0}} : q_acc) + psh[WEIGHTED_W-1:0];
  always @(posedge clk) begin
    if (q_we) q_mem[{wr_bank, q_wj}] <= q_acc;
    if (c_we) c_mem[{wr_bank, c_j}] <= {cq_re_n, cq_im_n};
    q_rd <= q_mem[{rd_bank_nx, rd_j_nx}];
    c_rd <= c_mem[{rd_bank_nx, rd_j_nx}];
  end
  wire [FIR_W-1:0] facc_base = s2_first ? {FIR_W{1'b0}} : facc;
  // +-|product| as one adder: base + (p ^ -neg) + neg, the carry-in entering as a low bit
  /* verilator lint_off UNUSEDSIGNAL */
  wire [FIR_W:0] facc_s = {facc_base, 1'b1} + {psh[FIR_W-1:0] ^ {FIR_W{s2_neg}}, s2_neg};
  /* verilator lint_on UNUSEDSIGNAL */

  always @(posedge clk) begin
    if (rst) begin
      s1_v <= 1'b0; s2_v <= 1'b0; s1_cl <= CL_A; s2_cl <= CL_A;
      s1_first <= 1'b0; s2_first <= 1'b0; s1_last <= 1'b0; s2_last <= 1'b0;
      s1_neg <= 1'b0; s2_neg <= 1'b0; s1_lane <= 1'b0; s2_lane <= 1'b0;
      s1_sh <= 0; s2_sh <= 0; s1_j <= 0; s2_j <= 0;
      a_busy <= 1'b0; a_lane <= 1'b0; a_prime <= 1'b0; a_base <= 0; a_addr <= 0; a_cnt <= 0;
      a_i <= 0; r_i <= 0; r_lane <= 1'b0;
      a_la <= 0; a_lb <= 0; fq_pend <= 1'b0; fq_lane <= 1'b0;
      fres_valid <= 1'b0;
      c_state <= C_IDLE; c_m <= 0; c_neg <= 1'b0; c_iss1 <= 1'b0; c_dv1 <= 1'b0;
      c_j <= 0; f_wptr <= F_LAST; f_rptr <= 0; f_rnx <= f_adv({FA_W{1'b0}}); f_old <= 0; f_cnt <= 0; f_dist <= 0;
      ca_re <= 0; ca_im <= 0;
      cq_valid <= 1'b0;
      cq_j <= 0; sq_p <= 1'b0; sq_la <= 0; sq_lb <= 0;
      pw_valid <= 1'b0; pw_j <= 0; w_la <= 0; w_lb <= 0;
      q_we <= 1'b0; q_wj <= 0;
      b_busy <= 1'b0; wr_bank <= 1'b0; rd_bank <= 1'b0; g_full <= 2'd0; rd_j <= 0;
      out_index <= DECIM_T - 1'b1;
    end else begin
      rd_j <= rd_j_nx;
      rd_bank <= rd_bank_nx;
      if (g_taken) out_index <= out_index + DECIM_T;
      if (b_done && !g_taken) g_full <= g_full + 1'b1;
      else if (g_taken && !b_done) g_full <= g_full - 1'b1;
      a_addr <= a_addr_nx;
      a_prime <= a_start;
      if (a_start) begin
        r_i <= 0;
        r_lane <= 1'b0;
      end else if (a_prime || a_adv) begin
        r_i <= (r_i == T_LAST) ? {TI_W{1'b0}} : r_i + 1'b1;
        if (r_i == T_LAST) r_lane <= !r_lane;
      end

      // ---------------- issue (one limb product per clock)
      s1_v <= w_iss || sq_iss || a_iss;
      if (w_iss) begin
        ma <= pw_p[w_la*LW +: LW];
        mb <= wt[w_lb*LW +: LW];
        s1_cl <= CL_W; s1_first <= (w_la == {LP_W{1'b0}}) && (w_lb == {LWT_W{1'b0}});
        s1_last <= w_last; s1_neg <= 1'b0;
        s1_sh <= SH_ZERO + w_la + w_lb; s1_j <= pw_j;
        if (w_lb == NW_L) begin
          w_lb <= 0;
          w_la <= (w_la == NP_L) ? {LP_W{1'b0}} : w_la + 1'b1;
        end else begin
          w_lb <= w_lb + 1'b1;
        end
        if (w_last) pw_valid <= 1'b0;
      end else if (sq_iss) begin
        ma <= sq_mag_p[sq_la*LW +: LW];
        mb <= sq_mag_p[sq_lb*LW +: LW];
        s1_cl <= CL_SQ; s1_first <= sq_first; s1_last <= sq_last; s1_neg <= 1'b0;
        s1_sh <= SH_ZERO + sq_la + sq_lb; s1_j <= cq_j;
        if (sq_lb == NC_L) begin
          sq_lb <= 0;
          if (sq_la == NC_L) begin
            sq_la <= 0;
            sq_p <= !sq_p;
            if (sq_p) cq_valid <= 1'b0;
          end else begin
            sq_la <= sq_la + 1'b1;
          end
        end else begin
          sq_lb <= sq_lb + 1'b1;
        end
      end else begin
        ma <= a_opa;
        mb <= a_opb;
        s1_cl <= CL_A; s1_first <= a_first; s1_last <= a_last; s1_neg <= a_neg;
        s1_sh <= SH_ZERO + a_la + a_lb; s1_lane <= a_lane;
      end
      if (a_iss) begin
        if (a_lb == NTB_L) begin
          a_lb <= 0;
          if (a_la == NBA_L) begin
            a_la <= 0;
            if (a_i == T_LAST) begin
              a_i <= 0;
              a_lane <= !a_lane;
              if (a_lane) a_busy <= 1'b0;
            end else begin
              a_i <= a_i + 1'b1;
            end
          end else begin
            a_la <= a_la + 1'b1;
          end
        end else begin
          a_lb <= a_lb + 1'b1;
        end
      end
      if (a_start) begin
        a_busy <= 1'b1;
        a_lane <= 1'b0; a_i <= 0; a_la <= 0; a_lb <= 0;
        a_base <= bd_wptr;
        a_cnt <= bd_cnt;
      end

      // ---------------- product stage
      s2_v <= s1_v; s2_cl <= s1_cl; s2_first <= s1_first; s2_last <= s1_last;
      s2_neg <= s1_neg; s2_sh <= s1_sh; s2_j <= s1_j; s2_lane <= s1_lane;
      q_we <= s2_v && (s2_cl == CL_W) && s2_last;
      q_wj <= s2_j;

      // ---------------- land
      if (fq_pend) begin
        fq_pend <= 1'b0;
        fres_im <= q_chip_facc;  // re word first, moved to fres_re with the im word
        if (fq_lane) begin
          fres_re <= fres_im;
          fres_valid <= 1'b1;
        end
      end
      if (s2_v) begin
        case (s2_cl)
          CL_A: begin
            facc <= facc_s[FIR_W:1];
            if (s2_last) begin
              fq_pend <= 1'b1;
              fq_lane <= s2_lane;
            end
          end
          CL_SQ: begin
            p_w <= (s2_first ? {PW_W{1'b0}} : p_w) + psh[PW_W-1:0];
            if (s2_last) begin
              pw_valid <= 1'b1;
              pw_j <= s2_j;
            end
          end
          default: q_acc <= q_sum;
        endcase
      end

      // ---------------- combiner
      c_iss1 <= 1'b0;
      if (c_iss1) begin
        ca_re <= ca_re_s[CA_W:1];
        ca_im <= ca_im_s[CA_W:1];
      end
      case (c_state)
        C_RUN: begin
          c_iss1 <= 1'b1;
          c_neg <= !code_rom(c_j, c_m);   // c_j does not change before the chip is added
          c_dv1 <= (f_dist < f_cnt);
          f_rptr <= f_rnx;
          f_rnx <= f_adv(f_rnx);
          f_dist <= f_dist - STEP_D;
          if (c_m == C_LAST) c_state <= C_DRAIN;
          c_m <= c_m + 1'b1;
        end
        C_DRAIN: c_state <= C_Q;  // the last tap is accumulated this clock
        C_Q: if (!cq_valid) begin
          // quantize code c_j, clear the accumulators for the next code
          cq_re <= cq_re_n;
          cq_im <= cq_im_n;
          ca_re <= {CA_W{1'b0}};
          ca_im <= {CA_W{1'b0}};  // {cq_re_n, cq_im_n} -> c_mem (c_we)
          cq_valid <= 1'b1;
          cq_j <= c_j;
          sq_p <= 1'b0; sq_la <= 0; sq_lb <= 0;
          if (c_j == J_LAST) begin
            c_state <= C_IDLE;
          end else begin
            c_j <= c_j + 1'b1;
            c_m <= 0;
            f_rptr <= f_old;
            f_rnx <= f_adv(f_old);
            f_dist <= DIST0;
            c_state <= C_RUN;
          end
        end
        default: ;
      endcase

      // ---------------- output start / end
      if (b_start) begin
        b_busy <= 1'b1;
        fres_valid <= 1'b0;
        if (wr_bank) begin
          chip_re1 <= fres_re; chip_im1 <= fres_im;
        end else begin
          chip_re0 <= fres_re; chip_im0 <= fres_im;
        end
        f_wptr <= f_wptr_next;
        if (f_cnt != FN_N) f_cnt <= f_cnt + 1'b1;
        // oldest combiner tap: k - (CHIPS-1) CHIP_STEP = k + 1 (mod FN)
        f_rptr <= f_oldest;
        f_rnx <= f_oldest_adv;
        f_old <= f_oldest;
        f_dist <= DIST0;
        c_m <= 0;
        c_j <= 0;
        c_state <= C_RUN;
      end
      if (b_done) begin
        b_busy <= 1'b0;
        wr_bank <= !wr_bank;
      end
    end
  end

  /* verilator lint_off UNUSEDSIGNAL */
  wire [CODE_W+JI_W-1:0] code_x = {{CODE_W{1'b0}}, rd_j};
  /* verilator lint_on UNUSEDSIGNAL */
  assign m_valid    = (g_full != 2'd0);
  assign m_weighted = q_rd;
  assign m_code     = code_x[CODE_W-1:0];
  assign m_last     = m_last_w;
  assign m_energy   = e_rd;
  assign m_index    = out_index;
  assign m_chip_re  = rd_bank ? chip_re1 : chip_re0;
  assign m_chip_im  = rd_bank ? chip_im1 : chip_im0;
  assign m_corr_re  = c_rd[2*CORR_W-1:CORR_W];
  assign m_corr_im  = c_rd[CORR_W-1:0];

`ifdef FORMAL
  // Formal properties (formal/run_formal.sh correlator_bank). Assumed: reset first; the input
  // follows the AXI-Stream rules (valid held until ready, data stable while waiting); m_ready
  // free. Proven: the reset state, the output stream rules, no overflow on the exact nodes
  // (acc, E, the chip FIR accumulator, C, P, Q: each sum computed wider here must fit its
  // register), index/counter bounds and the group/energy-ring bookkeeping.
  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume(rst);
  always @(posedge clk)
    if (f_past_valid && !$past(rst) && $past(s_valid && !s_ready)) begin
      assume(s_valid);
      assume(s_data == $past(s_data));
    end

  // Reset state: front end idle and ready, sums and rings empty, back end and output idle.
  always @(posedge clk)
    if (f_past_valid && $past(rst))
      assert(fe_state == FE_IDLE && s_ready && !m_valid && acc_re == 0 && acc_im == 0 &&
             energy == 0 && phase == 0 && b_ptr == 0 && !b_full && !y_full && y_ptr == Y_LAST &&
             dphase == 0 && bd_wptr == BD_LAST && bd_cnt == 0 && !bd_pend && eq_n == 0 &&
             eq_w == 0 && eq_r == 0 && !s1_v && !s2_v && !a_busy && !a_prime && !fq_pend &&
             !fres_valid && c_state == C_IDLE && !c_iss1 && f_cnt == 0 && ca_re == 0 &&
             ca_im == 0 && !cq_valid && !pw_valid && !q_we && !b_busy && g_full == 0 &&
             rd_j == 0 && m_index == DECIM_T - 1'b1);

  // AXI-Stream master: m_valid stays up until m_ready, every m_* output is stable meanwhile.
  always @(posedge clk)
    if (f_past_valid && !$past(rst) && $past(m_valid && !m_ready)) begin
      assert(m_valid);
      assert(m_weighted == $past(m_weighted) && m_code == $past(m_code) &&
             m_last == $past(m_last) && m_energy == $past(m_energy) &&
             m_index == $past(m_index) && m_chip_re == $past(m_chip_re) &&
             m_chip_im == $past(m_chip_im) && m_corr_re == $past(m_corr_re) &&
             m_corr_im == $past(m_corr_im));
    end

  // Groups in flight, each holding one energy-ring entry from its hand-off until its last beat
  // is taken: pending Bd, FIR running or its last product / quantization in flight, F waiting,
  // back end busy, finished groups.
  wire f_a_tail1 = s1_v && s1_cl == CL_A && s1_last && s1_lane;
  wire f_a_tail2 = s2_v && s2_cl == CL_A && s2_last && s2_lane;
  wire [3:0] f_groups = bd_pend + a_busy + f_a_tail1 + f_a_tail2 + (fq_pend && fq_lane) +
                        fres_valid + b_busy + g_full;
  // Index and counter bounds, and the bookkeeping they rest on.
  always @(*)
    if (f_past_valid && !rst) begin
      assert(fe_state <= FE_HAND);
      assert(phase <= P_LAST && b_ptr == phase);
      assert(y_ptr <= Y_LAST && dphase <= D_LAST);
      assert(bd_wptr <= BD_LAST && bd_cnt <= TAPS_N);
      assert(a_i <= T_LAST && r_i <= T_LAST && a_cnt <= TAPS_N);
      assert(a_base <= BD_LAST && a_addr <= BD_LAST);
      assert(c_j <= J_LAST && rd_j <= J_LAST);
      assert(a_la <= NBA_L && a_lb <= NTB_L && sq_la <= NC_L && sq_lb <= NC_L &&
             w_la <= NP_L && w_lb <= NW_L);
      if (c_state == C_RUN) assert(c_m <= C_LAST);
      assert(f_wptr <= F_LAST && f_rptr <= F_LAST && f_old <= F_LAST && f_cnt <= FN_N);
      assert(f_rnx == f_adv(f_rptr));
      if (cq_valid) assert(cq_j <= J_LAST);
      if (pw_valid) assert(pw_j <= J_LAST);
      if (q_we) assert(q_wj <= J_LAST);
      assert(g_full <= 2'd2 && eq_n <= 2'd3 && eq_w == eq_r + eq_n);
      assert(f_groups == {2'b00, eq_n});
      // banks: the back end writes the bank after the unread ones
      assert((wr_bank ^ rd_bank) == (g_full == 2'd1));
      if (g_full == 2'd2) assert(!b_busy);
      if (!b_busy) assert(c_state == C_IDLE && !cq_valid && !pw_valid && !q_we && !b_tags);
      // the presented beat's words are the memories' words at the read address
      if (m_valid)
        assert(q_rd == q_mem[{rd_bank, rd_j}] && c_rd == c_mem[{rd_bank, rd_j}] &&
               e_rd == e_mem[eq_r]);
    end

  // ---- no overflow: acc (moving sum of the B history)
  localparam integer F_AW = DEC_W + 2;
  reg signed [F_AW-1:0] f_bsum_re, f_bsum_im;
  reg [2*MIX_W-1:0] f_bw;
  integer f_i;
  always @(*) begin
    f_bsum_re = 0;
    f_bsum_im = 0;
    for (f_i = 0; f_i < PERIOD; f_i = f_i + 1) begin
      f_bw = b_mem[f_i];
      if (b_full || f_i < b_ptr) begin
        f_bsum_re = f_bsum_re + $signed(f_bw[2*MIX_W-1:MIX_W]);
        f_bsum_im = f_bsum_im + $signed(f_bw[MIX_W-1:0]);
      end
    end
  end
  wire signed [F_AW-1:0] f_acc_re_x = acc_re + mix_re - b_old_re;
  wire signed [F_AW-1:0] f_acc_im_x = acc_im + mix_im - b_old_im;
  always @(*)
    if (f_past_valid && !rst) begin
      // acc is the sum of the entries written since reset (computed wide: it fits)
      assert(acc_re == f_bsum_re && acc_im == f_bsum_im);
      if (fe_state == FE_M5) begin
        assert(b_rd == b_mem[b_ptr]);
        assert(f_acc_re_x[F_AW-1:DEC_W-1] == {(F_AW-DEC_W+1){f_acc_re_x[DEC_W-1]}});
        assert(f_acc_im_x[F_AW-1:DEC_W-1] == {(F_AW-DEC_W+1){f_acc_im_x[DEC_W-1]}});
      end
    end

  // ---- no overflow: E (running energy over the y history)
  reg [WINDOW-1:0] f_yw;  // y history slot written since reset
  always @(posedge clk)
    if (rst) f_yw <= {WINDOW{1'b0}};
    else if (fe_state == FE_M3) f_yw[y_ptr] <= 1'b1;
  reg [EX_W-1:0] f_esum;
  reg [WINDOW-1:0] f_ylt, f_yle;
  reg signed [DATA_W-1:0] f_yv;
  reg [2*DATA_W-1:0] f_ysq;
  always @(*) begin
    f_esum = {EX_W{1'b0}};
    for (f_i = 0; f_i < WINDOW; f_i = f_i + 1) begin
      f_yv = y_mem[f_i];
      f_ysq = f_yv * f_yv;
      if (f_yw[f_i]) f_esum = f_esum + f_ysq;
      f_ylt[f_i] = (f_i < y_ptr);
      f_yle[f_i] = (f_i <= y_ptr);
    end
  end
  wire [2*DATA_W-1:0] f_fa2 = fa * fa;
  wire signed [FB_W-1:0] f_fa_x = {{(FB_W-DATA_W){fa[DATA_W-1]}}, fa};
  always @(*)
    if (f_past_valid && !rst) begin
      // the slots written: all once y_full, else those before the write pointer
      if (y_full) assert(&f_yw);
      else if (fe_state == FE_M1 || fe_state == FE_M2 || fe_state == FE_M3) assert(f_yw == f_ylt);
      else if (fe_state == FE_M4 || fe_state == FE_M5) assert(f_yw == f_yle);
      else assert(f_yw == ((y_ptr == Y_LAST) ? {WINDOW{1'b0}} : f_yle));
      // E is the window's sum of y^2, plus the square in flight
      if (fe_state == FE_M3 || fe_state == FE_M4 || fe_state == FE_M5)
        assert(energy == f_esum + f_fa2);
      else
        assert(energy == f_esum);
      if (fe_state == FE_M1 || fe_state == FE_M4) assert(fb == f_fa_x);
      if (fe_state == FE_M2 || fe_state == FE_M5) assert(fp == f_fa2);
      if (fe_state == FE_M3) assert(y_rd == y_mem[y_ptr]);
      // E + y^2 and E - y_old^2 fit ENERGY_W bits unsigned (no overflow, no underflow)
      if (fe_state == FE_M2 || fe_state == FE_M5) assert(energy_s[EX_W:ENERGY_W+1] == 0);
    end

`ifdef FORMAL_NARROW_PRODUCT
  // the narrowed multiplier computes every issued product exactly
  always @(*)
    if (f_past_valid && !rst && s1_v) assert((ma >> F_MA_W) == 0 && (mb >> F_MB_W) == 0);
`endif
  // ---- no overflow: chip FIR accumulator, |Cq|^2 sum P, weighted Q (back-end adder)
  localparam integer F_XW = XW + 2;
  wire signed [F_XW-1:0] f_psh = {2'b00, psh};
  wire signed [F_XW-1:0] f_fir_x = $signed(facc_base) + (s2_neg ? -f_psh : f_psh);
  wire [F_XW-1:0] f_p_x = {{(F_XW-PW_W){1'b0}}, (s2_first ? {PW_W{1'b0}} : p_w)} + f_psh;
  wire [F_XW-1:0] f_q_x = {{(F_XW-WEIGHTED_W){1'b0}}, (s2_first ? {WEIGHTED_W{1'b0}} : q_acc)} + f_psh;
  always @(*)
    if (f_past_valid && !rst && s2_v) begin
      if (s2_cl == CL_A) assert(f_fir_x[F_XW-1:FIR_W-1] == {(F_XW-FIR_W+1){f_fir_x[FIR_W-1]}});
      if (s2_cl == CL_SQ) assert(f_p_x[F_XW-1:PW_W] == 0);
      if (s2_cl == CL_W) assert(f_q_x[F_XW-1:WEIGHTED_W] == 0);
    end

  // ---- no overflow: combiner accumulators C (f_cn: chips added in this round)
  localparam integer F_CW = CA_W + 2;
  reg [CI_W+1:0] f_cn;
  always @(posedge clk)
    if (rst || b_start || (c_state == C_Q && !cq_valid)) f_cn <= 0;
    else if (c_iss1) f_cn <= f_cn + 1'b1;
  wire signed [F_CW-1:0] f_fre = c_dv1 ? (c_neg ? -f_rd_re : f_rd_re) : 0;
  wire signed [F_CW-1:0] f_fim = c_dv1 ? (c_neg ? -f_rd_im : f_rd_im) : 0;
  wire signed [F_CW-1:0] f_ca_re_x = ca_re + f_fre;
  wire signed [F_CW-1:0] f_ca_im_x = ca_im + f_fim;
  wire signed [F_CW-1:0] f_clim = $signed({1'b0, f_cn}) <<< (CHIP_W - 1);
  always @(*)
    if (f_past_valid && !rst) begin
      assert(f_cn <= CHIPS);
      if (c_state == C_RUN) assert(f_cn + c_iss1 == c_m && (c_iss1 || c_m == 0));
      if (c_state == C_DRAIN) assert(c_iss1 && f_cn == CHIPS - 1);
      if (c_state == C_Q) assert(!c_iss1 && f_cn == CHIPS);
      if (c_state == C_IDLE) assert(!c_iss1 && f_cn == 0);
      assert($signed(ca_re) <= f_clim && $signed(ca_re) >= -f_clim);
      assert($signed(ca_im) <= f_clim && $signed(ca_im) >= -f_clim);
      if (c_iss1) begin
        assert(f_ca_re_x[F_CW-1:CA_W-1] == {(F_CW-CA_W+1){f_ca_re_x[CA_W-1]}});
        assert(f_ca_im_x[F_CW-1:CA_W-1] == {(F_CW-CA_W+1){f_ca_im_x[CA_W-1]}});
      end
    end
`endif
endmodule

`default_nettype wire
