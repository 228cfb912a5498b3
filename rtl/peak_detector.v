// peak_detector: streaming peak picking on the correlator bank's outputs, bit-exact to
// PeakDetectorFixed (model/peak_detector.cpp).
//
// What it computes, per input beat {Q_j (CODES x WEIGHTED_W unsigned), E, n}:
//   best = argmax_j Q_j (lowest j on ties), second = max_{j != best} Q_j   (sequential scan)
//   norm = E >> ENERGY_SHIFT;  gate = Q_best >= THRESHOLD * max(norm,1) && norm >= MIN_NORM
//   a pending candidate whose right neighbour is unknown takes Q_next = Q_code(this beat)
//   if gate && (no candidate || Q_best * max(norm_cand,1) > Q_cand * max(norm,1)):
//       candidate := {n, best, Q_prev, Q, second, norm}   (the best rho^2 = Q / norm so far)
//   else if candidate && Q_next known && n - n_cand >= HOLDOFF: emit it
//   Q_prev := this beat's Q vector
// An event, computed with one sequential restoring divider (3 divisions):
//   score  = min(2^SCORE_W-1, floor(Q / max(norm,1))),  margin = score - min(cap, floor(Q2/..))
//   frac   = clamp(trunc((Q_next-Q_prev) 2^FRAC_W / (2 (2Q - Q_prev - Q_next))), +-2^(FRAC_W-1)),
//            0 when the denominator is <= 0; arrival = n 2^FRAC_W + DECIM frac (signed).
// Bit growth: THRESHOLD*norm SCORE_W+ENERGY_W (constant multiplier: shifts and adds);
// denominator WEIGHTED_W+3 signed; numerator WEIGHTED_W+1+FRAC_W signed; quotients exact
// (restoring division, truncation), then capped / clamped as above. No rounding elsewhere;
// nothing can overflow.
// Latency / throughput: a beat takes CODES+2 cycles (s_ready is low meanwhile): 11 cycles at
// CODES = 9, well within the DECIM*8 cycles between the bank's outputs. An event adds
// 3 divisions of DV_N = WEIGHTED_W+FRAC_W+1 cycles each (~170 cycles at the defaults) plus the
// time the output waits for m_ready; s_ready stays low until the event is in the output
// register, so the bank stalls and no beat or event is lost.
// Streams: valid/ready with AXI4-Stream rules (m_* stable while m_valid && !m_ready).
// Reset: synchronous, active high, clears the candidate, Q_prev and the output register.
`default_nettype none

module peak_detector #(
  parameter integer CODES = 9, WEIGHTED_W = 47, ENERGY_W = 41, ENERGY_SHIFT = 12,
  parameter integer SCORE_W = 16, FRAC_W = 8, DECIM = 5, TIME_W = 40,
  parameter integer HOLDOFF = 1005,
  parameter [SCORE_W-1:0] THRESHOLD = 0,
  parameter [ENERGY_W-1:0] MIN_NORM = 0,
  parameter integer CODE_W = 4
) (
  input  wire clk, rst,
  input  wire s_valid, output wire s_ready,
  input  wire [CODES*WEIGHTED_W-1:0] s_weighted, input wire [ENERGY_W-1:0] s_energy,
  input  wire [TIME_W-1:0] s_index,
  output wire m_valid, input wire m_ready,
  output wire [CODE_W-1:0]             m_code,
  output wire signed [TIME_W+FRAC_W:0] m_arrival,
  output wire [SCORE_W-1:0]            m_score, m_margin
);
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

  localparam integer QW     = WEIGHTED_W;
  localparam integer JI_W   = clog2(CODES + 1);
  localparam integer DV_N   = WEIGHTED_W + FRAC_W + 1;          // dividend bits
  localparam integer DV_D   = imax(ENERGY_W, WEIGHTED_W + 3);    // divisor bits
  localparam integer DC_W   = clog2(DV_N + 1);
  localparam integer THR_W  = SCORE_W + ENERGY_W;
  localparam integer CMP_W  = imax(THR_W, QW) + 1;              // gate comparison
  localparam integer ARR_W  = TIME_W + FRAC_W + 1;
  localparam integer FR_W   = FRAC_W + 2;                        // signed fraction
  localparam integer CODES_I = CODES;
  localparam [JI_W-1:0] CODES_N = CODES_I[JI_W-1:0];
  localparam integer HOLDOFF_I = HOLDOFF;
  localparam [TIME_W-1:0] HOLD_T = {{(TIME_W-32){1'b0}}, HOLDOFF_I[31:0]};  // TIME_W >= 32
  localparam [DC_W-1:0] DV_N_C = DV_N[DC_W-1:0];
  localparam [SCORE_W-1:0] CAP = {SCORE_W{1'b1}};
  localparam integer HALF_I = (FRAC_W > 0) ? (1 << (FRAC_W - 1)) : 0;
  localparam [DV_N-1:0] HALF = {{(DV_N-32){1'b0}}, HALF_I[31:0]};

  localparam [3:0] S_IDLE = 4'd0, S_SCAN = 4'd1, S_DECIDE = 4'd2, S_DIV = 4'd3,
                   S_NEXTDIV = 4'd4, S_OUT = 4'd5;
  reg [3:0] state;

  // input beat
  reg [CODES*WEIGHTED_W-1:0] q_r, prev;
  reg [ENERGY_W-1:0] e_r;
  reg [TIME_W-1:0]   n_r;
  // scan
  reg [JI_W-1:0]     j;
  reg [JI_W-1:0]     best;
  reg [QW-1:0]       best_q, second;
  // candidate
  reg                c_valid, c_has_next;
  reg [TIME_W-1:0]   c_n;
  reg [JI_W-1:0]     c_code;
  reg [QW-1:0]       c_qp, c_q, c_qn, c_q2;
  reg [ENERGY_W-1:0] c_norm;
  // event under computation
  reg [TIME_W-1:0]   ev_n;
  reg [JI_W-1:0]     ev_code;
  reg [QW-1:0]       ev_q2;
  reg                ev_neg, ev_den_pos;
  reg [DV_N-1:0]     ev_num_mag;
  reg [DV_D-1:0]     ev_den;
  reg [1:0]          div_no;         // 0: score, 1: second score, 2: fraction
  reg [SCORE_W-1:0]  sc1, sc2;
  // divider
  reg [DV_N-1:0]     dv_q;           // dividend shifting out / quotient shifting in
  reg [DV_D-1:0]     dv_r;           // remainder (< divisor)
  reg [DV_D-1:0]     dv_d;
  reg [DC_W-1:0]     dv_cnt;
  // output
  reg                m_valid_r;
  reg [CODE_W-1:0]   o_code;
  reg [ARR_W-1:0]    o_arrival;
  reg [SCORE_W-1:0]  o_score, o_margin;

  assign s_ready = (state == S_IDLE);

  wire [QW-1:0] q_j     = q_r[j*QW +: QW];
  wire [QW-1:0] q_cand  = q_r[c_code*QW +: QW];
  wire [QW-1:0] prev_b  = prev[best*QW +: QW];
  wire [ENERGY_W-1:0] norm  = e_r >> ENERGY_SHIFT;
  wire [ENERGY_W-1:0] norm1 = (norm == {ENERGY_W{1'b0}}) ? {{(ENERGY_W-1){1'b0}}, 1'b1} : norm;
  wire [CMP_W-1:0] thr_norm = {{(CMP_W-SCORE_W){1'b0}}, THRESHOLD} * {{(CMP_W-ENERGY_W){1'b0}}, norm1};
  wire gate = ({{(CMP_W-QW){1'b0}}, best_q} >= thr_norm) && (norm >= MIN_NORM);
  wire hn_now = c_valid && !c_has_next;               // candidate takes Q_next this beat
  wire hn     = c_has_next || hn_now;
  wire [QW-1:0] qn = hn_now ? q_cand : c_qn;
  wire [TIME_W-1:0] since = n_r - c_n;
  // rho^2 of the best code beats the candidate's: Q / norm > Q_c / norm_c, cross-multiplied.
  wire [ENERGY_W-1:0] c_norm1 = (c_norm == {ENERGY_W{1'b0}}) ? {{(ENERGY_W-1){1'b0}}, 1'b1} : c_norm;
  wire [QW+ENERGY_W-1:0] better_lhs = {{ENERGY_W{1'b0}}, best_q} * {{QW{1'b0}}, c_norm1};
  wire [QW+ENERGY_W-1:0] better_rhs = {{ENERGY_W{1'b0}}, c_q} * {{QW{1'b0}}, norm1};
  wire better = better_lhs > better_rhs;

  // Fraction operands of the candidate being emitted (computed in DECIDE from c_* and qn).
  wire signed [QW+2:0] den_s = ({3'b0, c_q} <<< 2) - ({3'b0, c_qp} <<< 1) - ({3'b0, qn} <<< 1);
  wire signed [QW+1:0] dnum  = {2'b0, qn} - {2'b0, c_qp};
  // |Q_next - Q_prev| < 2^QW: the top two bits of the magnitude are zero.
  /* verilator lint_off UNUSEDSIGNAL */
  wire [QW+1:0] dnum_mag = dnum[QW+1] ? -dnum : dnum;
  /* verilator lint_on UNUSEDSIGNAL */

  // One restoring-division step.
  wire [DV_D:0] dv_sh  = {dv_r[DV_D-1:0], dv_q[DV_N-1]};
  wire [DV_D:0] dv_sub = dv_sh - {1'b0, dv_d};
  wire dv_ge = !dv_sub[DV_D];

  // Results of the finished division (quotient in dv_q).
  wire [SCORE_W-1:0] score_now = (|(dv_q >> SCORE_W)) ? CAP : dv_q[SCORE_W-1:0];
  // frac_mag <= HALF: only its low FR_W bits can be non-zero.
  /* verilator lint_off UNUSEDSIGNAL */
  wire [DV_N-1:0] frac_mag = (!ev_den_pos) ? {DV_N{1'b0}} : (dv_q > HALF ? HALF : dv_q);
  /* verilator lint_on UNUSEDSIGNAL */
  wire signed [FR_W-1:0] frac = ev_neg ? -$signed(frac_mag[FR_W-1:0]) : $signed(frac_mag[FR_W-1:0]);
  localparam integer DECIM_I = DECIM;
  localparam signed [ARR_W-1:0] DECIM_A = {{(ARR_W-32){1'b0}}, DECIM_I[31:0]};
  wire signed [ARR_W-1:0] frac_x = {{(ARR_W-FR_W){frac[FR_W-1]}}, frac};
  wire signed [ARR_W-1:0] arrival = $signed({1'b0, ev_n, {FRAC_W{1'b0}}}) + frac_x * DECIM_A;

  always @(posedge clk) begin
    if (rst) begin
      state <= S_IDLE;
      q_r <= 0; prev <= 0; e_r <= 0; n_r <= 0;
      j <= 0; best <= 0; best_q <= 0; second <= 0;
      c_valid <= 1'b0; c_has_next <= 1'b0; c_n <= 0; c_code <= 0;
      c_qp <= 0; c_q <= 0; c_qn <= 0; c_q2 <= 0; c_norm <= 0;
      ev_n <= 0; ev_code <= 0; ev_q2 <= 0;
      ev_neg <= 1'b0; ev_den_pos <= 1'b0; ev_num_mag <= 0; ev_den <= 0;
      div_no <= 0; sc1 <= 0; sc2 <= 0;
      dv_q <= 0; dv_r <= 0; dv_d <= 0; dv_cnt <= 0;
      m_valid_r <= 1'b0; o_code <= 0; o_arrival <= 0; o_score <= 0; o_margin <= 0;
    end else begin
      if (m_valid_r && m_ready) m_valid_r <= 1'b0;
      case (state)
        S_IDLE: if (s_valid) begin
          q_r <= s_weighted;
          e_r <= s_energy;
          n_r <= s_index;
          best <= 0;
          best_q <= s_weighted[QW-1:0];
          second <= 0;
          j <= 1;
          state <= (CODES > 1) ? S_SCAN : S_DECIDE;
        end
        S_SCAN: begin
          if (q_j > best_q) begin
            second <= best_q;
            best_q <= q_j;
            best <= j;
          end else if (q_j > second) begin
            second <= q_j;
          end
          j <= j + 1'b1;
          if (j + 1'b1 == CODES_N) state <= S_DECIDE;
        end
        S_DECIDE: begin
          prev <= q_r;
          state <= S_IDLE;
          if (gate && (!c_valid || better)) begin
            c_valid <= 1'b1;
            c_has_next <= 1'b0;
            c_n <= n_r;
            c_code <= best;
            c_qp <= prev_b;
            c_q <= best_q;
            c_qn <= 0;
            c_q2 <= second;
            c_norm <= norm;
          end else if (c_valid && hn && since >= HOLD_T) begin
            c_valid <= 1'b0;
            c_has_next <= 1'b0;
            ev_n <= c_n;
            ev_code <= c_code;
            ev_q2 <= c_q2;
            ev_den_pos <= !den_s[QW+2] && (den_s != 0);
            ev_den <= den_s[DV_D-1:0];
            ev_neg <= dnum[QW+1];
            ev_num_mag <= {1'b0, dnum_mag[QW-1:0], {FRAC_W{1'b0}}};  // |Q_next - Q_prev| < 2^QW
            div_no <= 0;
            // division 0: Q / max(norm, 1)
            dv_q <= {{(DV_N-QW){1'b0}}, c_q};
            dv_d <= {{(DV_D-ENERGY_W){1'b0}}, (c_norm == {ENERGY_W{1'b0}}) ? {{(ENERGY_W-1){1'b0}}, 1'b1} : c_norm};
            dv_r <= 0;
            dv_cnt <= 0;
            state <= S_DIV;
          end else begin
            c_has_next <= hn;
            c_qn <= qn;
          end
        end
        S_DIV: begin
          dv_r <= dv_ge ? dv_sub[DV_D-1:0] : dv_sh[DV_D-1:0];
          dv_q <= {dv_q[DV_N-2:0], dv_ge};
          dv_cnt <= dv_cnt + 1'b1;
          if (dv_cnt + 1'b1 == DV_N_C) state <= S_NEXTDIV;
        end
        S_NEXTDIV: begin
          dv_r <= 0;
          dv_cnt <= 0;
          if (div_no == 2'd0) begin
            sc1 <= score_now;
            div_no <= 2'd1;
            dv_q <= {{(DV_N-QW){1'b0}}, ev_q2};
            state <= S_DIV;
          end else if (div_no == 2'd1) begin
            sc2 <= score_now;
            div_no <= 2'd2;
            dv_q <= ev_num_mag;
            dv_d <= ev_den;
            state <= S_DIV;
          end else begin
            state <= S_OUT;
          end
        end
        S_OUT: if (!m_valid_r) begin
          m_valid_r <= 1'b1;
          o_code <= ev_code + 1'b1;
          o_arrival <= arrival;
          o_score <= sc1;
          o_margin <= sc1 - sc2;
          state <= S_IDLE;
        end
        default: state <= S_IDLE;
      endcase
    end
  end

  assign m_valid   = m_valid_r;
  assign m_code    = o_code;
  assign m_arrival = o_arrival;
  assign m_score   = o_score;
  assign m_margin  = o_margin;
endmodule

`default_nettype wire
