////////////////////////////////////////////////////////////////////////////////
//
// Filename:  rtl/bandpass_sos.v
//
// Project:   ranging -- coded ultrasonic ranging receiver
//
// Purpose:   The receiver's bandpass filter: a cascade of SECTIONS second-order
//            sections, bit-exact with the golden model BandpassFixed
//            (model/bandpass_filter.cpp). Section k computes, Direct Form I,
//
//              acc = b0*x[n] + b1*x[n-1] + b2*x[n-2] - a1*y[n-1] - a2*y[n-2]
//              y[n] = quantize(acc)
//
//            and y of section k is x of section k+1. The cascade input s_data
//            (signed, IN_W bits, IN_W-1 fraction bits) is aligned to DATA_FRAC
//            fraction bits by a left shift of DATA_FRAC-(IN_W-1) (wiring, exact).
//
// Architecture: time multiplexed, ONE multiplier per section (SECTIONS in all),
//            sections pipelined. Each section feeds its products one per clock
//            through a registered-operand, registered-product signed multiply
//            (COEF_W x DW bits, DW = max(DATA_W, DATA_FRAC+1): 16x16 for the
//            default configuration, so Yosys synth_ice40 -dsp maps it to one
//            SB_MAC16) into an ACC_W-bit adder/subtractor in logic, in the order
//            b0*x0, b2*x2, [b1*x1], a2*y2, a1*y1. The b1 product exists only if
//            b1 != 0: the check is made at elaboration on the COEFS parameter
//            (localparam P below), so a zero b1 (bandpass g*[1,0,-1]
//            numerators) costs neither a cycle nor a multiplexer input.
//
// Throughput: P cycles per sample, P = 4 (b1 == 0 in every section) or 5
//            (some b1 != 0): with the default configuration 4 cycles per
//            sample, i.e. 5 MS/s needs a 20 MHz clock (40-48 MHz leaves 2x
//            margin).
//
// Latency:   sum over sections of (P_k + 3), plus SECTIONS - 1, clock cycles
//            from the clock edge that accepts a sample (s_valid && s_ready) to
//            the edge after which m_valid shows it, when nothing stalls (39
//            cycles for the default 5 sections with P = 4). Per section: P
//            cycles of operand select, 1 multiply, 1 accumulate, 1 quantize into
//            the output register; 1 more to hand over to the next section.
//
// Bit growth: products COEF_W + DW bits; accumulator ACC_W bits, which the
//            model (validate / bandpass_min_acc_bits) proves holds
//            sum |b_i| max|x| + sum |a_i| max|y| of every section, so no product
//            and no partial sum can overflow it. Section outputs DATA_W bits,
//            DATA_FRAC fraction bits; the accumulator has COEF_FRAC + DATA_FRAC.
//
// Rounding:  acc -> y drops COEF_FRAC fraction bits, exactly as fx_quantize:
//              ROUNDING 0: truncate (arithmetic shift right: floor);
//              ROUNDING 1: round half up (add 2^(COEF_FRAC-1), then shift);
//              ROUNDING 2: convergent (round to nearest, ties to even: add
//                          2^(COEF_FRAC-1) - 1 + bit COEF_FRAC of acc, then shift).
// Overflow:  after rounding (quantize first, then overflow): SATURATE 1 clamps
//            to the most negative / most positive DATA_W code, SATURATE 0 keeps
//            the low DATA_W bits (wrap).
//
// Handshake: AXI4-Stream rules on both ports. m_valid never waits for m_ready;
//            m_data/m_sections are stable while m_valid && !m_ready. Every
//            section has one output register; a section whose finished sum
//            finds its output register still full freezes (all its registers
//            hold) until the next stage takes it, so back-pressure stalls the
//            pipeline back to s_ready without losing or duplicating a sample.
//            The stall decision uses only registered state, so there is NO
//            combinational path from m_ready to s_ready (nor between sections):
//            s_ready is a function of section 0's registers. The price is one
//            idle cycle when a full output register is drained in the very
//            cycle its successor finishes, which never happens at full rate
//            with m_ready held high.
//
// m_sections: section k's output for the sample on m_data at
//            [k*DATA_W +: DATA_W] (debug tap; m_data is the last word). The
//            taps travel with the sample through the pipeline (registers that
//            synthesis removes when the port is left unconnected).
//
// Reset:     synchronous, active high; clears all filter state (x and y
//            histories to zero), the pipeline and the output registers.
//
////////////////////////////////////////////////////////////////////////////////
`default_nettype none

module bandpass_sos #(
  parameter integer SECTIONS  = 5,
  parameter integer IN_W      = 12,  // input: signed, IN_W-1 fraction bits
  parameter integer DATA_W    = 16,  // section outputs: signed, DATA_FRAC fraction bits
  parameter integer DATA_FRAC = 14,
  parameter integer COEF_W    = 16,  // coefficients: signed, COEF_FRAC fraction bits
  parameter integer COEF_FRAC = 14,
  parameter integer ACC_W     = 40,  // accumulator (validated by the model to hold the worst case)
  parameter integer ROUNDING  = 1,   // 0 truncate, 1 round half up, 2 convergent
  parameter integer SATURATE  = 1,   // 1 saturate, 0 wrap
  parameter [SECTIONS*5*COEF_W-1:0] COEFS = 0  // section k coefficient i (b0,b1,b2,a1,a2) at [(5*k+i)*COEF_W +: COEF_W]
) (
  input  wire clk, rst,
  input  wire signed [IN_W-1:0]   s_data,  input wire s_valid, output wire s_ready,
  output wire signed [DATA_W-1:0] m_data,  output wire m_valid, input wire m_ready,
  output wire [SECTIONS*DATA_W-1:0] m_sections  // every section's output for this sample (debug tap)
);

  // Multiplier data operand: section outputs (DATA_W) and the aligned input
  // (DATA_FRAC+1 bits: |x| <= 2^DATA_FRAC) both fit.
  localparam integer DW = (DATA_W > DATA_FRAC + 1) ? DATA_W : DATA_FRAC + 1;
  localparam integer PW = COEF_W + DW;                       // exact product
  localparam integer SW = (ACC_W > PW) ? ACC_W : PW;         // accumulate width (mod 2^ACC_W)
  localparam integer SHIFT = COEF_FRAC;                      // fraction bits dropped by the quantizer
  localparam integer IN_SHIFT = DATA_FRAC - (IN_W - 1);      // input alignment (>= 0, model-validated)
  // Rounding headroom: acc + 2^(SHIFT-1) can never overflow RW bits.
  localparam integer RW = ((ACC_W > SHIFT + 1) ? ACC_W : SHIFT + 1) + 1;
  localparam integer QW = RW - SHIFT;                        // rounded value
  localparam integer TW = SECTIONS * DATA_W;                 // taps bus

  // Link k is the input of section k: link 0 is the s port, link SECTIONS the m port.
  wire [SECTIONS:0]        link_valid;
  wire [SECTIONS:1]        link_take;   // link k's beat moves this cycle (link 0: s_valid && s_ready)
  wire [(SECTIONS+1)*DW-1:0] link_data;
  wire [(SECTIONS+1)*TW-1:0] link_taps; // outputs of the sections before k for this sample

  // ---- input port ----------------------------------------------------------
  assign link_valid[0] = s_valid;
  assign link_taps[0 +: TW] = {TW{1'b0}};
  generate
    if (IN_SHIFT == 0) begin : g_align0
      assign link_data[0 +: DW] = {{(DW - IN_W + 1){s_data[IN_W-1]}}, s_data[IN_W-2:0]};
    end else begin : g_align
      assign link_data[0 +: DW] = {{(DW - IN_W - IN_SHIFT + 1){s_data[IN_W-1]}},
                                   s_data[IN_W-2:0], {IN_SHIFT{1'b0}}};
    end
  endgenerate

  // ---- sections ------------------------------------------------------------
  genvar k;
  generate
    for (k = 0; k < SECTIONS; k = k + 1) begin : g_sec
      localparam [COEF_W-1:0] B0 = COEFS[(5*k+0)*COEF_W +: COEF_W];
      localparam [COEF_W-1:0] B1 = COEFS[(5*k+1)*COEF_W +: COEF_W];
      localparam [COEF_W-1:0] B2 = COEFS[(5*k+2)*COEF_W +: COEF_W];
      localparam [COEF_W-1:0] A1 = COEFS[(5*k+3)*COEF_W +: COEF_W];
      localparam [COEF_W-1:0] A2 = COEFS[(5*k+4)*COEF_W +: COEF_W];
      // Elaboration-time check: the b1 product (and its cycle) only if b1 != 0.
      localparam integer P = (B1 != {COEF_W{1'b0}}) ? 5 : 4;
      localparam [2:0] STEP_B2 = 3'd1;
      localparam [2:0] STEP_A2 = (P == 5) ? 3'd3 : 3'd2;
      localparam [2:0] STEP_A1 = (P == 5) ? 3'd4 : 3'd3;

      // Filter state. x0 is the sample being computed; x1, x2 the two before.
      reg signed [DW-1:0]     x0, x1, x2;
      reg signed [DATA_W-1:0] y1, y2;      // the two most recent outputs written
      // Accepted samples whose output is not yet in y1 (0..2). When the a2
      // product of sample n is selected, sample n-1 may still be in flight
      // (pend == 2): then y[n-2] is still in y1, else in y2. The a1 product
      // is selected P-1 >= 3 cycles after the a2 one of the sample before,
      // which is after that sample's output was written (select, multiply,
      // accumulate, write: 3 cycles), so y1 is always y[n-1] there.
      reg [1:0]               pend;
      reg                     active;      // sequencer busy with x0
      reg [2:0]               step;        // product index 0..P-1
      // Multiplier pipeline: operands, product, accumulator, with their tags.
      reg signed [COEF_W-1:0] mul_a;
      reg signed [DW-1:0]     mul_b;
      reg                     t1_v, t1_first, t1_neg, t1_last;
      reg signed [PW-1:0]     prod;
      reg                     t2_v, t2_first, t2_neg, t2_last;
      reg signed [ACC_W-1:0]  acc;
      reg                     done;        // acc holds a finished sum
      reg [TW-1:0]            taps_in, taps_hold;
      reg                     out_valid;
      reg [TW-1:0]            out_taps;    // word k is this section's output

      wire ce = !(done && out_valid);                 // freeze: result cannot be written
      wire can_take = ce && (!active || step == STEP_A1);
      wire fire = link_valid[k] && can_take;
      wire write = ce && done;

      // ---- quantizer: acc (SHIFT more fraction bits) -> DATA_W -----------------
      wire signed [RW-1:0] acc_r = {{(RW - ACC_W + 1){acc[ACC_W-1]}}, acc[ACC_W-2:0]};
      wire signed [QW-1:0] q;
      wire signed [DATA_W-1:0] y_new;
      if (SHIFT == 0) begin : g_noround
        assign q = acc_r;
      end else begin : g_round
        wire [RW-1:0] rnd;
        if (ROUNDING == 0) begin : g_trn
          assign rnd = {RW{1'b0}};
        end else if (ROUNDING == 1) begin : g_rnd
          assign rnd = {{(RW - SHIFT){1'b0}}, 1'b1, {(SHIFT - 1){1'b0}}};
        end else begin : g_conv
          // 2^(SHIFT-1) - 1 + lsb of the truncated result: a tie rounds up only
          // to an even result, every other remainder like round-half-up.
          assign rnd = {{(RW - SHIFT){1'b0}}, 1'b0, {(SHIFT - 1){1'b1}}}
                     + {{(RW - 1){1'b0}}, acc_r[SHIFT]};
        end
        wire [RW-1:0] sum = acc_r + rnd;
        assign q = sum[RW-1:SHIFT];
        // The dropped fraction bits only matter through the carry into q.
        wire unused_round_bits = &{1'b0, sum[SHIFT-1:0]};
      end
      if (QW > DATA_W) begin : g_ovf
        wire fits = &q[QW-1:DATA_W-1] || ~|q[QW-1:DATA_W-1];
        if (SATURATE != 0) begin : g_sat
          assign y_new = fits ? q[DATA_W-1:0]
                       : (q[QW-1] ? {1'b1, {(DATA_W-1){1'b0}}} : {1'b0, {(DATA_W-1){1'b1}}});
        end else begin : g_wrap
          assign y_new = q[DATA_W-1:0];
          wire unused_fits = fits;
        end
      end else begin : g_noovf
        assign y_new = {{(DATA_W - QW + 1){q[QW-1]}}, q[QW-2:0]};
      end

      // Sign extension of the y history to the multiplier operand width.
      wire signed [DW-1:0] y1_x = {{(DW - DATA_W + 1){y1[DATA_W-1]}}, y1[DATA_W-2:0]};
      wire signed [DW-1:0] y2_x = {{(DW - DATA_W + 1){y2[DATA_W-1]}}, y2[DATA_W-2:0]};
      wire signed [SW-1:0] prod_x = {{(SW - PW + 1){prod[PW-1]}}, prod[PW-2:0]};
      wire signed [SW-1:0] acc_x = {{(SW - ACC_W + 1){acc[ACC_W-1]}}, acc[ACC_W-2:0]};
      wire signed [SW-1:0] acc_base = t2_first ? {SW{1'b0}} : acc_x;
      wire signed [SW-1:0] acc_next = t2_neg ? acc_base - prod_x : acc_base + prod_x;
      if (SW > ACC_W) begin : g_acc_top
        // Products wider than the accumulator: the sum is kept mod 2^ACC_W, exact
        // because every product and partial sum fits ACC_W (model-proven).
        wire unused_acc_top = &{1'b0, acc_next[SW-1:ACC_W]};
      end

      always @(posedge clk) begin
        if (rst) begin
          x0 <= 0; x1 <= 0; x2 <= 0; y1 <= 0; y2 <= 0;
          pend <= 2'd0; active <= 1'b0; step <= 3'd0;
          mul_a <= 0; mul_b <= 0;
          t1_v <= 1'b0; t1_first <= 1'b0; t1_neg <= 1'b0; t1_last <= 1'b0;
          prod <= 0;
          t2_v <= 1'b0; t2_first <= 1'b0; t2_neg <= 1'b0; t2_last <= 1'b0;
          acc <= 0; done <= 1'b0;
          taps_in <= {TW{1'b0}}; taps_hold <= {TW{1'b0}};
          out_valid <= 1'b0; out_taps <= {TW{1'b0}};
        end else begin
          if (ce) begin
            // Sequencer: a new sample may start in the cycle after the last step.
            if (fire) begin
              x0 <= link_data[k*DW +: DW];
              x1 <= x0;
              x2 <= x1;
              taps_in <= link_taps[k*TW +: TW];
              active <= 1'b1;
              step <= 3'd0;
            end else if (active && step == STEP_A1) begin
              active <= 1'b0;
            end else if (active) begin
              step <= step + 3'd1;
            end
            // Operand select (registered multiplier inputs).
            t1_v <= active;
            t1_first <= (step == 3'd0);
            t1_neg <= (step == STEP_A2) || (step == STEP_A1);
            t1_last <= (step == STEP_A1);
            if (step == 3'd0) begin
              mul_a <= B0; mul_b <= x0;
            end else if (step == STEP_B2) begin
              mul_a <= B2; mul_b <= x2;
            end else if (step == STEP_A2) begin
              mul_a <= A2; mul_b <= (pend == 2'd2) ? y1_x : y2_x;
            end else if (step == STEP_A1) begin
              mul_a <= A1; mul_b <= y1_x;
            end else begin  // step 2, only reachable when b1 != 0
              mul_a <= B1; mul_b <= x1;
            end
            if (active && step == STEP_A1) taps_hold <= taps_in;
            // Multiply.
            t2_v <= t1_v; t2_first <= t1_first; t2_neg <= t1_neg; t2_last <= t1_last;
            prod <= mul_a * mul_b;
            // Accumulate (exact: the model proves every partial sum fits ACC_W).
            if (t2_v) acc <= acc_next[ACC_W-1:0];
            done <= t2_v && t2_last;
            // Pending outputs.
            if (fire && !write) pend <= pend + 2'd1;
            else if (!fire && write) pend <= pend - 2'd1;
          end
          // Quantize the finished sum into the history and the output register.
          if (write) begin
            y1 <= y_new;
            y2 <= y1;
            out_taps <= taps_hold;
            out_taps[k*DATA_W +: DATA_W] <= y_new;
            out_valid <= 1'b1;
          end else if (link_take[k+1]) begin
            out_valid <= 1'b0;
          end
        end
      end

      if (k == 0) begin : g_s
        assign s_ready = can_take;     // registered state only: no path from m_ready
      end else begin : g_take
        assign link_take[k] = fire;
      end
      assign link_valid[k+1] = out_valid;
      assign link_data[(k+1)*DW +: DW] = {{(DW - DATA_W + 1){out_taps[k*DATA_W + DATA_W - 1]}},
                                          out_taps[k*DATA_W +: DATA_W-1]};
      assign link_taps[(k+1)*TW +: TW] = out_taps;
    end
  endgenerate

  // ---- output port ---------------------------------------------------------
  assign link_take[SECTIONS] = link_valid[SECTIONS] && m_ready;
  assign m_valid = link_valid[SECTIONS];
  assign m_sections = link_taps[SECTIONS*TW +: TW];
  assign m_data = link_taps[SECTIONS*TW + (SECTIONS-1)*DATA_W +: DATA_W];
  // The link data of the last section has no consumer (m_data comes from the taps).
  wire unused_last_link = &{1'b0, link_data[SECTIONS*DW +: DW]};

endmodule

`default_nettype wire
