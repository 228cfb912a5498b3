// correlator_bank: the baseband matched-filter bank, bit-exact to CorrelatorBankFixed
// (model/correlator_bank.cpp, docs/architecture.md).
//
// What it computes, per full-rate input y[n] (signed DATA_W, DATA_FRAC fraction bits):
//   B[n]   = q_mix(y[n] * LO_COS[n mod P]), q_mix(-(y[n] * LO_SIN[n mod P]))   (mixer)
//   acc    = sum_{i<P} B[n-i]             moving sum over one carrier cycle, DEC_W, exact
//   E[n]   = sum_{i<WINDOW} y[n-i]^2      running energy, ENERGY_W unsigned, exact
// and after every DECIM-th input (one output beat):
//   Bd[k]  = acc                          (decimation)
//   F[k]   = q_chip(sum_{i<TAPS} g[i] Bd[k-i])            chip filter, FIR_W exact accumulator
//   C_j[k] = sum_{m<CHIPS} s_j(m) F[k - (CHIPS-1-m) CHIP_STEP]   combiner, exact, per code j
//   Cq_j   = q_corr(C_j),  P_j = Re(Cq_j)^2 + Im(Cq_j)^2,  Q_j = P_j * WEIGHTS[j]
// Quantizers q_mix / q_chip / q_corr: round half up (add half an LSB, arithmetic shift right
// by MIX_SHIFT / CHIP_SHIFT / CORR_SHIFT), then saturate to MIX_W / CHIP_W / CORR_W. They
// cannot saturate for in-range data (the model sizes them so) but saturate exactly like it.
// Every other node is exact (no rounding, no overflow):
//   y*lo: DATA_W+LO_W;  acc: DEC_W = MIX_W+ceil(log2 P);  g*Bd: TAP_W+DEC_W;  FIR acc: FIR_W;
//   C: COMB_W = CHIP_W+ceil(log2 CHIPS);  Cq^2: 2 CORR_W;  P: kept in 2*CORR_W bits (the
//   model's POWER_W = 2 CORR_W-1 is one bit short when Re = Im = -2^(CORR_W-1); it computes in
//   64 bits, so this module does too);  Q: 2 CORR_W + WEIGHT_W product whose top bits are
//   provably zero (2^(2 CORR_W-1) (2^WEIGHT_W-1) < 2^WEIGHTED_W): the low WEIGHTED_W are kept;
//   y^2: 2 DATA_W;  E: ENERGY_W = 2 DATA_W-1+ceil(log2 WINDOW) (E + y^2 is formed in one
//   expression with E - y_old^2, never stored above the bound).
//
// Architecture (two decoupled engines and a one-entry handoff register):
//   front end: one multiplier (DATA_W x max(LO_W,DATA_W), registered operands and product)
//     does y*cos, y*sin, y*y and y_old*y_old: 6 cycles per input sample (7 at a decimation
//     point if the back end is still busy with the previous output it waits here).
//   back end, per decimated output: chip FIR on two lanes (re, im; one tap per cycle),
//     TAPS + 4 cycles; F quantize/store 1; combiner CHIPS + 2 (reads the shared F taps, updates
//     all 2*CODES accumulators in parallel with adders); power + weight pipelined over the
//     codes, CODES + 5 cycles (|Cq|^2 reuses the two FIR lanes; P*w is a third multiplier);
//     1 cycle to publish. Total about TAPS + CHIPS + CODES + 14 = 111 cycles per output at the
//     default parameters, overlapped with the front end of the next DECIM samples.
//   Throughput: max(6 DECIM + 1, TAPS + CHIPS + CODES + 14) / DECIM cycles per input sample =
//     22.2 at the defaults (needs ~111 MHz for 5 MS/s). To reach the 8-9 cycles/sample target
//     the FIR needs 4 lanes (e.g. Bd split over 4 EBR banks by address mod 4: 81 taps in 21
//     cycles per lane pair) and the power/weight loop must overlap the next FIR; that is the
//     follow-up tuning issue. Latency: last input of a decimation group to m_valid =
//     ~1 + TAPS + CHIPS + CODES + 14 cycles.
//   Multipliers (plain signed/unsigned `*`, registered operands, registered product, so
//   synth_ice40 -dsp can map them): front 16x16 (1 SB_MAC16); FIR lanes max(DEC_W,CORR_W) x
//   max(TAP_W,CORR_W) = 23x16 (wider than 16x16: Yosys mul2dsp splits each into 2 SB_MAC16);
//   weight 2 CORR_W x WEIGHT_W = 32x16 unsigned (split, 2-3 SB_MAC16). As written ~7 SB_MAC16:
//   with the bandpass's 5 this exceeds the UP5K's 8; fitting needs the Bd word cut to 16 bits
//   (or the FIR lanes in LUT shift-add) and P*w on a 16x16 DSP in two passes.
//   Memories (synchronous read, no reset, inferable as EBR): B history PERIOD x 2 MIX_W,
//   y history WINDOW x DATA_W (y, not y^2: y_old^2 is recomputed), Bd history TAPS x 2 DEC_W,
//   F history ((CHIPS-1) CHIP_STEP + 1) x 2 CHIP_W. Histories are cleared lazily: a fill
//   flag/counter per history masks entries not written since reset to zero, so after reset
//   the outputs equal a fresh model's without a clearing pass.
//
// Streams: s_* one beat per input sample (s_ready high only when the front end is idle);
// m_* one beat per decimated output; data stable while m_valid && !m_ready; the back end
// waits (and the front end then stalls) while the output is not taken: no output is lost.
// Reset: synchronous, active high; clears every register, counter, phase and fill flag.
`default_nettype none

// DATA_FRAC, MIX_FRAC and POWER_W are part of the documented interface (formats of the
// streams) but the arithmetic only needs the shifts and widths derived from them.
/* verilator lint_off UNUSEDPARAM */
module correlator_bank #(
  parameter integer DATA_W = 16, DATA_FRAC = 14,
  parameter integer PERIOD = 25,
  parameter integer LO_W = 16,
  parameter integer MIX_W = 18, MIX_FRAC = 16, MIX_SHIFT = 13,
  parameter integer DECIM = 5,
  parameter integer DEC_W = 23,
  parameter integer TAPS = 81, TAP_W = 16,
  parameter integer FIR_W = 44,
  parameter integer CHIP_W = 20, CHIP_SHIFT = 22,
  parameter integer CHIPS = 7, CODES = 9,
  parameter integer CHIP_STEP = 20,
  parameter integer COMB_W = 23, CORR_W = 16, CORR_SHIFT = 6,
  parameter integer POWER_W = 31, WEIGHT_W = 16, WEIGHTED_W = 47,
  parameter integer WINDOW = 1005,
  parameter integer ENERGY_W = 41,
  parameter integer TIME_W = 40,
  parameter [PERIOD*LO_W-1:0]     LO_COS = 0,
  parameter [PERIOD*LO_W-1:0]     LO_SIN = 0,
  parameter [TAPS*TAP_W-1:0]      TAP_VALUES = 0,
  parameter [CODES*CHIPS-1:0]     CODE_BITS = 0,
  parameter [CODES*WEIGHT_W-1:0]  WEIGHTS = 0
) (
  /* verilator lint_on UNUSEDPARAM */
  input  wire clk, rst,
  input  wire signed [DATA_W-1:0] s_data, input wire s_valid, output wire s_ready,
  output wire m_valid, input wire m_ready,
  output wire [CODES*WEIGHTED_W-1:0] m_weighted,
  output wire [ENERGY_W-1:0]         m_energy,
  output wire [TIME_W-1:0]           m_index,
  output wire signed [CHIP_W-1:0]    m_chip_re, m_chip_im,
  output wire [CODES*CORR_W-1:0]     m_corr_re, m_corr_im
);
  // ---------------------------------------------------------------- helpers
  function integer clog2;
    input integer v;
    integer r;
    begin
      r = 0;
      while ((1 << r) < v) r = r + 1;
      clog2 = (r < 1) ? 1 : r;
    end
  endfunction
  function integer imax;
    input integer a, b;
    begin
      imax = (a > b) ? a : b;
    end
  endfunction

  // Round half up by `shift`, then saturate to `outw` bits (signed). Computed in QW bits,
  // wide enough for every node (the model limits FIR_W to 63).
  localparam integer QW = 72;
  function [QW-1:0] rnd_sat;
    input [QW-1:0] x;  // sign-extended value
    input integer shift, outw;
    reg signed [QW-1:0] t, mx, mn, one;
    begin
      one = {{(QW-1){1'b0}}, 1'b1};
      t = x;
      if (shift > 0) t = (t + (one <<< (shift - 1))) >>> shift;
      mx = (one <<< (outw - 1)) - one;
      mn = -mx - one;
      if (t > mx) t = mx;
      else if (t < mn) t = mn;
      rnd_sat = t;
    end
  endfunction

  localparam integer FN      = (CHIPS - 1) * CHIP_STEP + 1;  // F history depth
  localparam integer PA_W    = clog2(PERIOD);
  localparam integer YA_W    = clog2(WINDOW);
  localparam integer BA_W    = clog2(TAPS);
  localparam integer FA_W    = clog2(FN);
  localparam integer FB_W    = imax(LO_W, DATA_W);
  localparam integer FP_W    = DATA_W + FB_W;               // front-end product
  localparam integer MA_W    = imax(DEC_W, CORR_W);         // lane operand a (Bd | Cq)
  localparam integer MB_W    = imax(TAP_W, CORR_W);         // lane operand b (g | Cq)
  localparam integer LP_W    = MA_W + MB_W;                 // lane product
  localparam integer FACC_W  = imax(FIR_W, LP_W);
  localparam integer CA_W    = (CHIPS == 1) ? CHIP_W + 1 : COMB_W;  // -F must fit
  localparam integer PW_W    = 2 * CORR_W;                  // exact |Cq|^2
  localparam integer WP_W    = PW_W + WEIGHT_W;             // P*w product
  localparam integer TI_W    = clog2(TAPS + 1);
  localparam integer CI_W    = clog2(CHIPS + 1);
  localparam integer JI_W    = clog2(CODES + 1);
  localparam integer DP_W    = clog2(DECIM);
  localparam integer DIST_W  = clog2(FN + 1);
  localparam integer EX_W    = imax(ENERGY_W, FP_W);        // energy update width
  // Sized constants (keep every comparison at its operand's width).
  localparam integer P_LAST_I = PERIOD - 1;
  localparam [PA_W-1:0] P_LAST = P_LAST_I[PA_W-1:0];
  localparam integer Y_LAST_I = WINDOW - 1;
  localparam [YA_W-1:0] Y_LAST = Y_LAST_I[YA_W-1:0];
  localparam integer D_LAST_I = DECIM - 1;
  localparam [DP_W-1:0] D_LAST = D_LAST_I[DP_W-1:0];
  localparam integer BD_LAST_I = TAPS - 1;
  localparam [BA_W-1:0] BD_LAST = BD_LAST_I[BA_W-1:0];
  localparam integer TAPS_N_I = TAPS;
  localparam [TI_W-1:0] TAPS_N = TAPS_N_I[TI_W-1:0];
  localparam integer F_LAST_I = FN - 1;
  localparam [FA_W-1:0] F_LAST = F_LAST_I[FA_W-1:0];
  localparam integer FN_N_I = FN;
  localparam [DIST_W-1:0] FN_N = FN_N_I[DIST_W-1:0];
  localparam integer DIST0_I = FN - 1;
  localparam [DIST_W-1:0] DIST0 = DIST0_I[DIST_W-1:0];
  localparam integer STEP_D_I = CHIP_STEP;
  localparam [DIST_W-1:0] STEP_D = STEP_D_I[DIST_W-1:0];
  localparam integer STEP_A_I = CHIP_STEP;
  localparam [FA_W:0] STEP_A = STEP_A_I[FA_W:0];
  localparam integer FN_A_I = FN;
  localparam [FA_W:0] FN_A = FN_A_I[FA_W:0];
  localparam integer CHIPS_N_I = CHIPS;
  localparam [CI_W-1:0] CHIPS_N = CHIPS_N_I[CI_W-1:0];
  localparam integer CODES_N_I = CODES;
  localparam [JI_W-1:0] CODES_N = CODES_N_I[JI_W-1:0];

  // ---------------------------------------------------------------- front end
  localparam [2:0] FE_IDLE = 3'd0, FE_M1 = 3'd1, FE_M2 = 3'd2, FE_M3 = 3'd3,
                   FE_M4 = 3'd4, FE_M5 = 3'd5, FE_HAND = 3'd6;
  reg [2:0] fe_state;
  reg signed [DATA_W-1:0] y_r, y_old;
  reg signed [DATA_W-1:0] fa;
  reg signed [FB_W-1:0]   fb;
  reg signed [FP_W-1:0]   fp;
  reg [FP_W-1:0]          y2_r;
  reg signed [MIX_W-1:0]  mix_re, mix_im, b_old_re, b_old_im;
  reg signed [DEC_W-1:0]  acc_re, acc_im;
  reg [ENERGY_W-1:0]      energy;
  reg [PA_W-1:0]          phase, b_ptr;
  reg                     b_full, y_full;
  reg [YA_W-1:0]          y_ptr;
  reg [DP_W-1:0]          dphase;
  reg [TIME_W-1:0]        n_cnt;
  // handoff to the back end
  reg                     dec_valid;
  reg signed [DEC_W-1:0]  dec_re, dec_im;
  reg [ENERGY_W-1:0]      dec_energy;
  reg [TIME_W-1:0]        dec_index;
  wire                    dec_take;  // back end takes the handoff this cycle

  // B history (PERIOD x {re, im}) and y history (WINDOW x y): synchronous-read memories.
  reg [2*MIX_W-1:0] b_mem [0:PERIOD-1];
  reg [2*MIX_W-1:0] b_rd;
  reg [DATA_W-1:0]  y_mem [0:WINDOW-1];
  reg [DATA_W-1:0]  y_rd;
  wire fe_write = (fe_state == FE_M4);
  always @(posedge clk) begin
    if (fe_write) begin
      b_mem[b_ptr] <= {mix_re, mix_im};
      y_mem[y_ptr] <= y_r;
    end
    b_rd <= b_mem[b_ptr];
    y_rd <= y_mem[y_ptr];
  end

  assign s_ready = (fe_state == FE_IDLE);
  wire accept = s_valid && s_ready;
  wire [YA_W-1:0] y_ptr_next = (y_ptr == Y_LAST) ? {YA_W{1'b0}} : y_ptr + 1'b1;

  // Quantized mixer outputs of the two products (im: the negated product, as the model).
  // Only the low MIX_W / CHIP_W / CORR_W bits of a saturated rnd_sat result are meaningful.
  /* verilator lint_off UNUSEDSIGNAL */
  wire [QW-1:0] q_mix_re = rnd_sat({{(QW-FP_W){fp[FP_W-1]}}, fp}, MIX_SHIFT, MIX_W);
  /* verilator lint_on UNUSEDSIGNAL */
  wire signed [FP_W:0] fp_neg = -{fp[FP_W-1], fp};
  /* verilator lint_off UNUSEDSIGNAL */
  wire [QW-1:0] q_mix_im = rnd_sat({{(QW-FP_W-1){fp_neg[FP_W]}}, fp_neg}, MIX_SHIFT, MIX_W);
  /* verilator lint_on UNUSEDSIGNAL */

  // E + y^2 - y_old^2 (y^2 and y_old^2 are non-negative, below 2^(2 DATA_W-2) + 1).
  wire [EX_W-1:0] energy_next = {{(EX_W-ENERGY_W){1'b0}}, energy}
                              + {{(EX_W-FP_W){1'b0}}, y2_r} - {{(EX_W-FP_W){1'b0}}, fp};

  always @(posedge clk) begin
    if (rst) begin
      fe_state <= FE_IDLE;
      y_r <= 0; y_old <= 0; fa <= 0; fb <= 0; fp <= 0; y2_r <= 0;
      mix_re <= 0; mix_im <= 0; b_old_re <= 0; b_old_im <= 0;
      acc_re <= 0; acc_im <= 0; energy <= 0;
      phase <= 0; b_ptr <= 0; b_full <= 1'b0; y_full <= 1'b0;
      y_ptr <= Y_LAST;  // the model pre-increments the window index
      dphase <= 0; n_cnt <= 0;
      dec_valid <= 1'b0; dec_re <= 0; dec_im <= 0; dec_energy <= 0; dec_index <= 0;
    end else begin
      if (dec_take) dec_valid <= 1'b0;
      case (fe_state)
        FE_IDLE: if (accept) begin
          y_r <= s_data;
          fa <= s_data;
          fb <= {{(FB_W-LO_W){LO_COS[phase*LO_W+LO_W-1]}}, LO_COS[phase*LO_W +: LO_W]};
          y_ptr <= y_ptr_next;  // y_rd holds y_mem[y_ptr] from FE_M2 on
          fe_state <= FE_M1;
        end
        FE_M1: begin
          fp <= fa * fb;  // y cos
          fb <= {{(FB_W-LO_W){LO_SIN[phase*LO_W+LO_W-1]}}, LO_SIN[phase*LO_W +: LO_W]};
          fe_state <= FE_M2;
        end
        FE_M2: begin
          fp <= fa * fb;  // y sin
          mix_re <= q_mix_re[MIX_W-1:0];
          y_old <= y_full ? y_rd : {DATA_W{1'b0}};
          b_old_re <= b_full ? b_rd[2*MIX_W-1:MIX_W] : {MIX_W{1'b0}};
          b_old_im <= b_full ? b_rd[MIX_W-1:0] : {MIX_W{1'b0}};
          fb <= {{(FB_W-DATA_W){y_r[DATA_W-1]}}, y_r};
          fe_state <= FE_M3;
        end
        FE_M3: begin
          fp <= fa * fb;  // y^2
          mix_im <= q_mix_im[MIX_W-1:0];
          fa <= y_old;
          fb <= {{(FB_W-DATA_W){y_old[DATA_W-1]}}, y_old};
          fe_state <= FE_M4;
        end
        FE_M4: begin  // memories written this cycle (fe_write)
          fp <= fa * fb;  // y_old^2
          y2_r <= fp;
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
          fe_state <= FE_M5;
        end
        FE_M5: begin
          energy <= energy_next[ENERGY_W-1:0];
          n_cnt <= n_cnt + 1'b1;
          if (dphase == D_LAST) begin
            dphase <= 0;
            fe_state <= FE_HAND;
          end else begin
            dphase <= dphase + 1'b1;
            fe_state <= FE_IDLE;
          end
        end
        FE_HAND: if (!dec_valid) begin
          dec_valid <= 1'b1;
          dec_re <= acc_re;
          dec_im <= acc_im;
          dec_energy <= energy;
          dec_index <= n_cnt - 1'b1;
          fe_state <= FE_IDLE;
        end
        default: fe_state <= FE_IDLE;
      endcase
    end
  end

  // ---------------------------------------------------------------- back end
  localparam [2:0] BE_IDLE = 3'd0, BE_FIR = 3'd1, BE_FQ = 3'd2, BE_COMB = 3'd3,
                   BE_PWR = 3'd4, BE_DONE = 3'd5;
  reg [2:0] be_state;
  reg       m_valid_r;
  assign dec_take = (be_state == BE_IDLE) && dec_valid && !m_valid_r;

  // Bd history
  reg [2*DEC_W-1:0] bd_mem [0:TAPS-1];
  reg [2*DEC_W-1:0] bd_rd;
  reg [BA_W-1:0]    bd_wptr, bd_rptr;
  reg [FA_W-1:0]    f_wptr, f_rptr;
  wire [BA_W-1:0] bd_wptr_next = (bd_wptr == BD_LAST) ? {BA_W{1'b0}} : bd_wptr + 1'b1;
  wire [FA_W-1:0] f_wptr_next  = (f_wptr == F_LAST) ? {FA_W{1'b0}} : f_wptr + 1'b1;
  reg [TI_W-1:0]    bd_cnt, fir_i;
  always @(posedge clk) begin
    // Bd[k] is written when the handoff is taken, so the first FIR read sees it.
    if (dec_take) bd_mem[bd_wptr_next] <= {dec_re, dec_im};
    bd_rd <= bd_mem[bd_rptr];
  end
  // F history
  reg [2*CHIP_W-1:0] f_mem [0:FN-1];
  reg [2*CHIP_W-1:0] f_rd;
  reg [DIST_W-1:0]   f_cnt, f_dist;
  /* verilator lint_off UNUSEDSIGNAL */
  wire [QW-1:0] q_chip_re, q_chip_im;  // low CHIP_W bits used
  /* verilator lint_on UNUSEDSIGNAL */
  always @(posedge clk) begin
    if (be_state == BE_FQ) f_mem[f_wptr_next] <= {q_chip_re[CHIP_W-1:0], q_chip_im[CHIP_W-1:0]};
    f_rd <= f_mem[f_rptr];
  end

  // FIR / power lanes
  reg signed [TAP_W-1:0]  tap_r;
  reg signed [MA_W-1:0]   ma_re, ma_im;
  reg signed [MB_W-1:0]   mb_re, mb_im;
  reg signed [LP_W-1:0]   lp_re, lp_im;
  reg signed [FACC_W-1:0] facc_re, facc_im;
  reg                     iss1, iss2, iss3, iss4, iss5;  // pipeline stage valid
  reg                     dv1, dv2, dv3;                  // data valid (history filled)
  reg [JI_W-1:0]          j1, j2, j3, j4, j5;          // code index tags (power loop)
  reg [CI_W-1:0]          comb_c, c1;
  reg [JI_W-1:0]          pw_j;
  reg [CA_W*CODES-1:0]    cacc_re, cacc_im;
  reg signed [CORR_W-1:0] cq_re, cq_im;
  reg [PW_W-1:0]          pw;
  reg [WEIGHT_W-1:0]      wgt;
  /* verilator lint_off UNUSEDSIGNAL */
  reg [WP_W-1:0]          wp;  // top WP_W-WEIGHTED_W bits are provably zero (header)
  /* verilator lint_on UNUSEDSIGNAL */
  reg [ENERGY_W-1:0]      out_energy;
  reg [TIME_W-1:0]        out_index;
  reg signed [CHIP_W-1:0] out_chip_re, out_chip_im;
  reg [CODES*CORR_W-1:0]  out_corr_re, out_corr_im;
  reg [CODES*WEIGHTED_W-1:0] out_weighted;

  assign q_chip_re = rnd_sat({{(QW-FACC_W){facc_re[FACC_W-1]}}, facc_re}, CHIP_SHIFT, CHIP_W);
  assign q_chip_im = rnd_sat({{(QW-FACC_W){facc_im[FACC_W-1]}}, facc_im}, CHIP_SHIFT, CHIP_W);
  wire signed [CA_W-1:0] cacc_re_j = cacc_re[pw_j*CA_W +: CA_W];
  wire signed [CA_W-1:0] cacc_im_j = cacc_im[pw_j*CA_W +: CA_W];
  /* verilator lint_off UNUSEDSIGNAL */
  wire [QW-1:0] q_corr_re = rnd_sat({{(QW-CA_W){cacc_re_j[CA_W-1]}}, cacc_re_j}, CORR_SHIFT, CORR_W);
  wire [QW-1:0] q_corr_im = rnd_sat({{(QW-CA_W){cacc_im_j[CA_W-1]}}, cacc_im_j}, CORR_SHIFT, CORR_W);
  /* verilator lint_on UNUSEDSIGNAL */
  wire signed [DEC_W-1:0]  bd_rd_re = bd_rd[2*DEC_W-1:DEC_W];
  wire signed [DEC_W-1:0]  bd_rd_im = bd_rd[DEC_W-1:0];
  wire signed [CHIP_W-1:0] f_rd_re = f_rd[2*CHIP_W-1:CHIP_W];
  wire signed [CHIP_W-1:0] f_rd_im = f_rd[CHIP_W-1:0];
  wire signed [CA_W-1:0]   f_re_x = {{(CA_W-CHIP_W){f_rd_re[CHIP_W-1]}}, f_rd_re};
  wire signed [CA_W-1:0]   f_im_x = {{(CA_W-CHIP_W){f_rd_im[CHIP_W-1]}}, f_rd_im};
  wire [FA_W:0]   f_rptr_step  = {1'b0, f_rptr} + STEP_A;
  /* verilator lint_off UNUSEDSIGNAL */
  wire [FA_W:0]   f_rptr_wrap  = f_rptr_step - FN_A;  // used only when >= 0: top bit is 0
  /* verilator lint_on UNUSEDSIGNAL */
  wire [FA_W-1:0] f_rptr_nx    = f_rptr_wrap[FA_W-1:0];

  integer j;
  always @(posedge clk) begin
    if (rst) begin
      be_state <= BE_IDLE; m_valid_r <= 1'b0;
      bd_wptr <= BD_LAST; bd_rptr <= 0; bd_cnt <= 0; fir_i <= 0; 
      f_wptr <= F_LAST; f_rptr <= 0; f_cnt <= 0; f_dist <= 0; 
      tap_r <= 0; ma_re <= 0; ma_im <= 0; mb_re <= 0; mb_im <= 0; lp_re <= 0; lp_im <= 0;
      facc_re <= 0; facc_im <= 0;
      iss1 <= 1'b0; iss2 <= 1'b0; iss3 <= 1'b0; iss4 <= 1'b0; iss5 <= 1'b0;
      dv1 <= 1'b0; dv2 <= 1'b0; dv3 <= 1'b0;
      j1 <= 0; j2 <= 0; j3 <= 0; j4 <= 0; j5 <= 0;
      comb_c <= 0; c1 <= 0; pw_j <= 0;
      cacc_re <= 0; cacc_im <= 0; cq_re <= 0; cq_im <= 0; pw <= 0; wgt <= 0; wp <= 0;
      out_energy <= 0; out_index <= 0; out_chip_re <= 0; out_chip_im <= 0;
      out_corr_re <= 0; out_corr_im <= 0; out_weighted <= 0;
    end else begin
      if (m_valid_r && m_ready) m_valid_r <= 1'b0;
      case (be_state)
        BE_IDLE: if (dec_take) begin
          bd_wptr <= bd_wptr_next;
          bd_rptr <= bd_wptr_next;
          if (bd_cnt != TAPS_N) bd_cnt <= bd_cnt + 1'b1;
          out_energy <= dec_energy;
          out_index <= dec_index;
          fir_i <= 0;
          facc_re <= 0; facc_im <= 0;
          be_state <= BE_FIR;
        end
        BE_FIR: begin
          // stage 0: read Bd[k-i] (write of Bd[k] landed last cycle) and tap g[i]
          iss1 <= 1'b0;
          if (fir_i != TAPS_N) begin
            iss1 <= 1'b1;
            dv1 <= (fir_i < bd_cnt);
            tap_r <= TAP_VALUES[fir_i*TAP_W +: TAP_W];
            bd_rptr <= (bd_rptr == {BA_W{1'b0}}) ? BD_LAST : bd_rptr - 1'b1;
            fir_i <= fir_i + 1'b1;
          end
          // stage 1: operands
          iss2 <= iss1; dv2 <= dv1;
          ma_re <= {{(MA_W-DEC_W){bd_rd_re[DEC_W-1]}}, bd_rd_re};
          ma_im <= {{(MA_W-DEC_W){bd_rd_im[DEC_W-1]}}, bd_rd_im};
          mb_re <= {{(MB_W-TAP_W){tap_r[TAP_W-1]}}, tap_r};
          mb_im <= {{(MB_W-TAP_W){tap_r[TAP_W-1]}}, tap_r};
          // stage 2: products
          iss3 <= iss2; dv3 <= dv2;
          lp_re <= ma_re * mb_re;
          lp_im <= ma_im * mb_im;
          // stage 3: accumulate (entries not written since reset read as zero)
          if (iss3 && dv3) begin
            facc_re <= facc_re + {{(FACC_W-LP_W){lp_re[LP_W-1]}}, lp_re};
            facc_im <= facc_im + {{(FACC_W-LP_W){lp_im[LP_W-1]}}, lp_im};
          end
          if (fir_i == TAPS_N && !iss1 && !iss2 && !iss3) be_state <= BE_FQ;
        end
        BE_FQ: begin
          out_chip_re <= q_chip_re[CHIP_W-1:0];
          out_chip_im <= q_chip_im[CHIP_W-1:0];
          f_wptr <= f_wptr_next;
          // oldest combiner tap: k - (CHIPS-1) CHIP_STEP = k + 1 (mod FN)
          f_rptr <= (f_wptr_next == F_LAST) ? {FA_W{1'b0}} : f_wptr_next + 1'b1;
          f_dist <= DIST0;
          if (f_cnt != FN_N) f_cnt <= f_cnt + 1'b1;
          comb_c <= 0;
          cacc_re <= 0; cacc_im <= 0;
          be_state <= BE_COMB;
        end
        BE_COMB: begin
          iss1 <= 1'b0;
          if (comb_c != CHIPS_N) begin
            iss1 <= 1'b1;
            dv1 <= (f_dist < f_cnt);
            c1 <= comb_c;
            comb_c <= comb_c + 1'b1;
            f_rptr <= (f_rptr_step >= FN_A) ? f_rptr_nx : f_rptr_step[FA_W-1:0];
            f_dist <= f_dist - STEP_D;
          end
          if (iss1 && dv1) begin
            for (j = 0; j < CODES; j = j + 1) begin
              if (CODE_BITS[j*CHIPS + {{(32-CI_W){1'b0}}, c1}]) begin
                cacc_re[j*CA_W +: CA_W] <= cacc_re[j*CA_W +: CA_W] + f_re_x;
                cacc_im[j*CA_W +: CA_W] <= cacc_im[j*CA_W +: CA_W] + f_im_x;
              end else begin
                cacc_re[j*CA_W +: CA_W] <= cacc_re[j*CA_W +: CA_W] - f_re_x;
                cacc_im[j*CA_W +: CA_W] <= cacc_im[j*CA_W +: CA_W] - f_im_x;
              end
            end
          end
          if (comb_c == CHIPS_N && !iss1) begin
            pw_j <= 0;
            be_state <= BE_PWR;
          end
        end
        BE_PWR: begin
          // stage 0: quantize C_j
          iss1 <= 1'b0;
          if (pw_j != CODES_N) begin
            iss1 <= 1'b1;
            j1 <= pw_j;
            cq_re <= q_corr_re[CORR_W-1:0];
            cq_im <= q_corr_im[CORR_W-1:0];
            pw_j <= pw_j + 1'b1;
          end
          // stage 1: publish Cq_j, operands of the squares
          iss2 <= iss1; j2 <= j1;
          if (iss1) begin
            out_corr_re[j1*CORR_W +: CORR_W] <= cq_re;
            out_corr_im[j1*CORR_W +: CORR_W] <= cq_im;
          end
          ma_re <= {{(MA_W-CORR_W){cq_re[CORR_W-1]}}, cq_re};
          mb_re <= {{(MB_W-CORR_W){cq_re[CORR_W-1]}}, cq_re};
          ma_im <= {{(MA_W-CORR_W){cq_im[CORR_W-1]}}, cq_im};
          mb_im <= {{(MB_W-CORR_W){cq_im[CORR_W-1]}}, cq_im};
          // stage 2: squares
          iss3 <= iss2; j3 <= j2;
          lp_re <= ma_re * mb_re;
          lp_im <= ma_im * mb_im;
          // stage 3: power and weight operand
          iss4 <= iss3; j4 <= j3;
          pw <= lp_re[PW_W-1:0] + lp_im[PW_W-1:0];
          wgt <= WEIGHTS[j3*WEIGHT_W +: WEIGHT_W];
          // stage 4: weighted power
          iss5 <= iss4; j5 <= j4;
          wp <= pw * wgt;
          // stage 5: publish Q_j
          if (iss5) out_weighted[j5*WEIGHTED_W +: WEIGHTED_W] <= wp[WEIGHTED_W-1:0];
          if (pw_j == CODES_N && !iss1 && !iss2 && !iss3 && !iss4 && !iss5) be_state <= BE_DONE;
        end
        BE_DONE: begin
          m_valid_r <= 1'b1;
          be_state <= BE_IDLE;
        end
        default: be_state <= BE_IDLE;
      endcase
    end
  end

  assign m_valid    = m_valid_r;
  assign m_weighted = out_weighted;
  assign m_energy   = out_energy;
  assign m_index    = out_index;
  assign m_chip_re  = out_chip_re;
  assign m_chip_im  = out_chip_im;
  assign m_corr_re  = out_corr_re;
  assign m_corr_im  = out_corr_im;
endmodule

`default_nettype wire
