////////////////////////////////////////////////////////////////////////////////
//
// Filename:  rtl/bandpass_sos.v
//
// Project:   ranging -- coded ultrasonic ranging receiver
//
// Purpose:   The receiver's bandpass filter: a cascade of SECTIONS second-order
//            sections, bit-exact with the golden model BandpassFixed
//            (model/dsp/bandpass_filter.cpp). Section k computes, Direct Form I,
//
//              acc = b0*x[n] + b1*x[n-1] + b2*x[n-2] - a1*y[n-1] - a2*y[n-2]
//              y[n] = quantize(acc)
//
//            and y of section k is x of section k+1. The cascade input s_data
//            (signed, IN_W bits, IN_W-1 fraction bits) is aligned to DATA_FRAC
//            fraction bits by a left shift of DATA_FRAC-(IN_W-1) (wiring, exact).
//
// Architecture: chosen at elaboration from COEFS.
//   Shared (every section b1 == 0, b2 == -b0, 2*b0 / -a1 / -a2 fit COEF_W,
//   SAMPLE_CYCLES >= 6; the default Butterworth g*[1,0,-1] filter): 3 products
//   per section, (2*b0)*floor((x0-x2)/2), (-a2)*y2, (-a1)*y1, plus b0 when
//   x0-x2 is odd (the section's initial partial sum, a constant chosen by one
//   bit), which equals b0*x0 + b2*x2 - a1*y1 - a2*y2 exactly and keeps every
//   multiply DW x COEF_W (16x16 default) although x0-x2 has DW+1 bits. Two
//   consecutive sections share one registered-operand/registered-product
//   multiplier (SB_MAC16), one accumulator and one quantizer: 6 product
//   slots per sample, ceil(SECTIONS/2) multipliers (3 for 5 sections). The
//   sections are pipelined at the sample level: section j's b0 product of a
//   sample is selected at D_j = 2 + 13*(j/2) + 9*(j%2) clocks after section 0
//   takes it, its a2, a1 products the 2 clocks before, its output written 4
//   clocks after D_j. The cascade state is one output history per section
//   (depth 2-3), plus 3 input words; a period without input is a bubble that
//   writes nothing, and every read sits between writes so that depths are
//   fixed. The multiplier operands read the histories of a pair's two
//   sections from one small EBR per pair (16 words: a 4-word ring per
//   section and a zero word; two synchronous read ports, so yosys uses two
//   SB_RAM40_4K, one for a lone last section), each read issued the clock
//   before its slot; words not written since reset read the zero word (the
//   EBR is never cleared). Only the newest word of every section is also a
//   register (the next pair reads its x0 the clock after it is written; and
//   m_data). The m_sections taps keep register shift histories that exist
//   only when the port is connected: a tap's depth counts the valid samples
//   written since. With ROUNDING 0/1 the rounding constant is part of the
//   initial sum (no quantizer adder).
//   The accumulator keeps only the bits the COEFS bound needs: the final
//   sum (plus the folded rounding constant) fits, so partial sums may wrap
//   mod 2^bits (32 for the default filter, <= ACC_W + 1).
//   Otherwise (general numerators): one multiplier per section, each section
//   feeding its products b0*x0, b2*x2, [b1*x1], a2*y2, a1*y1 one per clock
//   (b1 only if b1 != 0) into an ACC_W-bit adder/subtractor, sections
//   pipelined with one output register each.
//
// Throughput: shared: 6 clocks per sample (5 MS/s at 30 MHz), whatever
//            SAMPLE_CYCLES >= 6 says. Otherwise P = 4 (b1 == 0 in every
//            section) or 5 clocks per sample.
//
// Latency:   shared: 2 + D_(SECTIONS-1) clocks from the edge that accepts a
//            sample into an idle filter to the edge after which m_valid shows
//            it (30 for 5 sections), up to 5 more when it waits for the input
//            slot. Otherwise sum over sections of (P_k + 3), plus SECTIONS - 1
//            (39 for 5 sections with P = 4).
//
// Resources (default configuration, shared): 3 SB_MAC16, 5 SB_RAM40_4K (one
//            per EBR read port), 715 logic cells with m_sections unconnected
//            (yosys synth_ice40 -dsp -flatten, nextpnr-ice40 --pack-only; 849
//            with register histories).
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
//            m_data/m_sections are stable while m_valid && !m_ready. Shared:
//            s_ready is "input register empty" (registered); an output not
//            taken freezes the whole schedule (m_ready -> clock enables, never
//            -> s_ready), so nothing is lost or duplicated. Otherwise every
//            section has one output register and freezes while it is full;
//            s_ready is a function of section 0's registers.
//
// m_sections: section k's output for the sample on m_data at
//            [k*DATA_W +: DATA_W] (debug tap; m_data is the last word).
//
// Reset:     synchronous, active high; clears all filter state (x and y
//            histories read as zero: the EBR words count as unwritten), the
//            pipeline and the output registers.
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
  parameter integer SAMPLE_CYCLES = 6,  // clocks available per input sample (shared multipliers need >= 6)
  parameter [SECTIONS*5*COEF_W-1:0] COEFS = 400'h3e0f842afa5c000005a43cd2894ffcf10000030f3a7a8822fc18000003e838838c68fbd80000042838088b82fc04000003fc  // section k coefficient i (b0,b1,b2,a1,a2) at [(5*k+i)*COEF_W +: COEF_W]
) (
  input  wire clk, rst,
  input  wire signed [IN_W-1:0]   s_data,  input wire s_valid, output wire s_ready,
  output wire signed [DATA_W-1:0] m_data,  output wire m_valid, input wire m_ready,
  output wire [SECTIONS*DATA_W-1:0] m_sections  // every section's output for this sample (debug tap)
);

`ifdef FORMAL_FREE_PRODUCT
  // Formal abstraction (formal/bandpass_sos*.job): every product is any value in every clock,
  // so the handshake properties are proven for every multiplier result (the values are the
  // equivalence benches' job).
  (* anyseq *) wire signed [COEF_W+((DATA_W > DATA_FRAC + 1) ? DATA_W : DATA_FRAC + 1)-1:0] f_prod;
`endif
  // Multiplier data operand: section outputs (DATA_W) and the aligned input
  // (DATA_FRAC+1 bits: |x| <= 2^DATA_FRAC) both fit.
  localparam integer DW = (DATA_W > DATA_FRAC + 1) ? DATA_W : DATA_FRAC + 1;
  localparam integer PW = COEF_W + DW;                       // exact product
  localparam integer SW = (ACC_W > PW) ? ACC_W : PW;         // accumulate width (mod 2^ACC_W)
  localparam integer SHIFT = COEF_FRAC;                      // fraction bits dropped by the quantizer
  localparam integer IN_SHIFT = DATA_FRAC - (IN_W - 1);      // input alignment (>= 0, model-validated)
  localparam integer TW = SECTIONS * DATA_W;                 // taps bus

  // ---- elaboration-time choice of the architecture -------------------------
  // Shared multipliers need every section to be a bandpass g*[1,0,-1] numerator
  // (b1 == 0, b2 == -b0) with 2*b0, -a1 and -a2 representable in COEF_W bits;
  // then b0*x0 + b2*x2 == (2*b0)*floor((x0-x2)/2) + b0*((x0-x2) mod 2) exactly
  // (3 products per section), and two sections share one 6-slot multiplier.
  function shared_ok;
    input integer dummy;
    integer k;
    reg [COEF_W-1:0] b0, b1, b2, a1, a2, mn, sum02;
    begin
      shared_ok = (SAMPLE_CYCLES >= 6) && (COEF_W >= 2) && (dummy == 0);
      mn = {1'b1, {(COEF_W-1){1'b0}}};
      for (k = 0; k < SECTIONS; k = k + 1) begin
        b0 = COEFS[(5*k+0)*COEF_W +: COEF_W];
        b1 = COEFS[(5*k+1)*COEF_W +: COEF_W];
        b2 = COEFS[(5*k+2)*COEF_W +: COEF_W];
        a1 = COEFS[(5*k+3)*COEF_W +: COEF_W];
        a2 = COEFS[(5*k+4)*COEF_W +: COEF_W];
        sum02 = b0 + b2;
        if (b1 != 0 || sum02 != 0 || b0[COEF_W-1] != b0[COEF_W-2] || a1 == mn || a2 == mn)
          shared_ok = 1'b0;
      end
    end
  endfunction
  localparam SHARED = shared_ok(0);

  // Accumulator bits the shared schedule needs: the bound the model validates
  // ACC_W against, max over sections of 2|b0| max|x| + (|a1|+|a2|) max|y|,
  // here from COEFS (a narrower sum is exact: it is kept mod 2^bits and the
  // final value fits).
  function integer shared_acc_bits;
    input integer fold;   // 1: plus the folded rounding constant (ROUNDING 1), one more bit allowed
    integer k, n;
    reg [COEF_W-1:0] c;
    reg [COEF_W+129:0] mag, bound, worst;
    begin
      worst = 0;
      for (k = 0; k < SECTIONS; k = k + 1) begin
        c = COEFS[(5*k+0)*COEF_W +: COEF_W];
        mag = c[COEF_W-1] ? {{130{1'b0}}, ~c} + 1 : {{130{1'b0}}, c};
        bound = (mag << 1) << ((k == 0) ? DATA_FRAC : DATA_W - 1);
        c = COEFS[(5*k+3)*COEF_W +: COEF_W];
        mag = c[COEF_W-1] ? {{130{1'b0}}, ~c} + 1 : {{130{1'b0}}, c};
        bound = bound + (mag << (DATA_W - 1));
        c = COEFS[(5*k+4)*COEF_W +: COEF_W];
        mag = c[COEF_W-1] ? {{130{1'b0}}, ~c} + 1 : {{130{1'b0}}, c};
        bound = bound + (mag << (DATA_W - 1));
        if (bound > worst) worst = bound;
      end
      if (fold != 0 && ROUNDING == 1 && SHIFT > 0)
        worst = worst + ({{(COEF_W+129){1'b0}}, 1'b1} << (SHIFT - 1));
      n = 1;
      while (n < ACC_W + fold && ((({{(COEF_W+129){1'b0}}, 1'b1}) << (n - 1)) - 1) < worst) n = n + 1;
      shared_acc_bits = n;
    end
  endfunction

  generate
  if (SHARED) begin : g_shared
    // Schedule (see header): section j's D product (b0 term) is selected at
    // D_j = 2 + 13*(j/2) + 9*(j%2) clocks after the wave's period start, its
    // a2, a1 products the two clocks before; its output is written 4 clocks
    // after D_j. Pair i = sections 2i (a), 2i+1 (b) uses local slot
    // r = (slot - PH_i) mod 6: r0 a.a2, r1 a.a1, r2 a.D, r3 b.a2, r4 b.a1, r5 b.D.
    localparam integer NP = (SECTIONS + 1) / 2;
    localparam integer DLAST = 2 + 13 * ((SECTIONS - 1) / 2) + 9 * ((SECTIONS - 1) % 2);
    localparam integer WVN = DLAST / 6 + 1;             // wave valid flags kept
    localparam integer Q0 = (DLAST - 2) / 6;            // newer writes of section 0 at output time
    localparam integer HDMAX = (Q0 + 1 > 3) ? Q0 + 1 : 3;
    localparam integer DW1 = DW + 1;
    localparam integer AW = shared_acc_bits(0);        // <= ACC_W
    // ROUNDING 0/1: the rounding constant is the accumulator's initial value, so
    // the quantizer is wiring plus saturation; ROUNDING 2 needs the sum's bit
    // SHIFT first and keeps the adder. AC: accumulator register width.
    localparam FOLD = (ROUNDING != 2);
    // Folded: the final sum plus the rounding constant must fit AC (mod 2^AC is
    // exact then); with 32 bits or fewer SB_MAC16 holds the accumulator itself.
    localparam integer AWF = shared_acc_bits(1);
    localparam integer AC = FOLD ? ((AWF > SHIFT + 2) ? AWF : SHIFT + 2) : AW;
    localparam integer XW = (AC > PW) ? AC : PW;
    localparam [AC+COEF_W-1:0] RNDW = (ROUNDING == 1 && SHIFT > 0)
                                      ? ({{(AC+COEF_W-1){1'b0}}, 1'b1} << (SHIFT - 1)) : {(AC+COEF_W){1'b0}};
    // COEFS and one all-zero section: the lone last section of an odd count has no partner.
    localparam [(SECTIONS+1)*5*COEF_W-1:0] CPAD = {{(5*COEF_W){1'b0}}, COEFS};

    reg  [2:0]            slot;         // global slot 0..5 (2: section 0 takes the input)
    reg  [WVN-1:0]        wv;           // wv[q]: wave decided q+1 periods ago (see header) was a sample
    reg  [IN_W-1:0]       xin, in1, in2;
    reg                   xin_full;
    reg                   out_valid;
    wire                  park = (slot == 3'd2) && !xin_full && (wv == {WVN{1'b0}});
    wire                  run = !(out_valid && !m_ready) && !park;
    wire [SECTIONS*HDMAX*DATA_W-1:0] hv;    // section j output history, depth d at (j*HDMAX+d)*DATA_W
    wire [NP*DATA_W-1:0]  pair_y;
    wire [SECTIONS-1:0]   wr;
    wire [NP*DATA_W-1:0]  q_rd;     // pair i's second EBR read port (x2 words)

    assign s_ready = !xin_full;
    assign m_valid = out_valid;

    // Input aligned to DATA_FRAC fraction bits (wiring), sign-extended to DW.
    function [DW-1:0] sx;                // section output, sign-extended to DW
      input [DATA_W-1:0] v;
      begin
        sx = {{(DW - DATA_W + 1){v[DATA_W-1]}}, v[DATA_W-2:0]};
      end
    endfunction
    wire [DW-1:0] xin_a, in2_a;          // input aligned to DATA_FRAC fraction bits (wiring)
    if (IN_SHIFT == 0) begin : g_align0
      assign xin_a = {{(DW - IN_W + 1){xin[IN_W-1]}}, xin[IN_W-2:0]};
      assign in2_a = {{(DW - IN_W + 1){in2[IN_W-1]}}, in2[IN_W-2:0]};
    end else begin : g_align
      assign xin_a = {{(DW - IN_W - IN_SHIFT + 1){xin[IN_W-1]}}, xin[IN_W-2:0], {IN_SHIFT{1'b0}}};
      assign in2_a = {{(DW - IN_W - IN_SHIFT + 1){in2[IN_W-1]}}, in2[IN_W-2:0], {IN_SHIFT{1'b0}}};
    end

    always @(posedge clk) begin
      if (rst) begin
        // Slots 0 and 1 run once before parking at 2, so that section 0's a2 and
        // a1 products of the first sample read the cleared history.
        slot <= 3'd0; wv <= {WVN{1'b0}};
        xin <= {IN_W{1'b0}}; in1 <= {IN_W{1'b0}}; in2 <= {IN_W{1'b0}};
        xin_full <= 1'b0; out_valid <= 1'b0;
      end else begin
        if (s_valid && !xin_full) begin
          xin <= s_data;
          xin_full <= 1'b1;
        end
        if (run) begin
          slot <= (slot == 3'd5) ? 3'd0 : slot + 3'd1;
          if (slot == 3'd2) begin
            // Wave decision: the input sample (if any) enters section 0 now.
            wv <= (wv << 1) | {{(WVN-1){1'b0}}, xin_full};
            if (xin_full) begin
              in1 <= xin; in2 <= in1;
              xin_full <= 1'b0;
            end
          end
        end
        // The last section's write of a sample raises m_valid.
        if (wr[SECTIONS-1]) out_valid <= 1'b1;
        else if (m_ready) out_valid <= 1'b0;
      end
    end

    // ---- section output histories (the cascade state and the output taps) ---
    genvar j;
    for (j = 0; j < SECTIONS; j = j + 1) begin : g_hist
      localparam integer DJ = 2 + 13 * (j / 2) + 9 * (j % 2);
      localparam integer QJ = (DLAST - DJ) / 6;
      localparam integer NEED = (j + 1 < SECTIONS) ? 3 : 2;
      localparam integer HD = (QJ + 1 > NEED) ? QJ + 1 : NEED;
      reg [HD*DATA_W-1:0] h;
      always @(posedge clk) begin
        if (rst) h <= {(HD*DATA_W){1'b0}};
        else if (wr[j]) h <= {h[0 +: (HD-1)*DATA_W], pair_y[(j/2)*DATA_W +: DATA_W]};
      end
      assign hv[j*HDMAX*DATA_W +: HD*DATA_W] = h;
      if (HD < HDMAX) begin : g_pad
        assign hv[(j*HDMAX+HD)*DATA_W +: (HDMAX-HD)*DATA_W] = {((HDMAX-HD)*DATA_W){1'b0}};
      end
      // Output tap: this section's value for the sample on m_data is below the
      // newer samples it has written since (those of valid waves only).
      integer q, cnt;
      always @(*) begin
        cnt = 0;
        for (q = 1; q <= QJ; q = q + 1) cnt = cnt + {31'd0, wv[(DLAST + 1 - 6*q) / 6]};
      end
      assign m_sections[j*DATA_W +: DATA_W] = h[cnt*DATA_W +: DATA_W];
    end
    assign m_data = hv[(SECTIONS-1)*HDMAX*DATA_W +: DATA_W];
    wire unused_hv = &{1'b0, hv, q_rd};  // depths nobody reads; the last pair's x2 port

    // ---- pairs: one multiplier, one accumulator, one quantizer each ---------
    genvar i;
    for (i = 0; i < NP; i = i + 1) begin : g_pair
      localparam integer A = 2 * i, B = 2 * i + 1;
      localparam HAS_B = (B < SECTIONS);
      localparam integer PH = (13 * i) % 6;
      localparam integer DA = 2 + 13 * i, DB = DA + 9;
      localparam [COEF_W-1:0] B0A = COEFS[(5*A+0)*COEF_W +: COEF_W];
      localparam [COEF_W-1:0] A1A = COEFS[(5*A+3)*COEF_W +: COEF_W];
      localparam [COEF_W-1:0] A2A = COEFS[(5*A+4)*COEF_W +: COEF_W];
      localparam [COEF_W-1:0] B0B = CPAD[(5*B+0)*COEF_W +: COEF_W];
      localparam [COEF_W-1:0] A1B = CPAD[(5*B+3)*COEF_W +: COEF_W];
      localparam [COEF_W-1:0] A2B = CPAD[(5*B+4)*COEF_W +: COEF_W];
      localparam [COEF_W-1:0] NA1A = -A1A, NA2A = -A2A, NA1B = -A1B, NA2B = -A2B;
      localparam [COEF_W-1:0] B0A2 = B0A << 1, B0B2 = B0B << 1;

      // r = (slot - PH) mod 6, kept in a register that steps with slot (no mod-6 adder in
      // front of the operand muxes and the accumulator)
      localparam integer R0_I = (6 - PH) % 6;
      localparam [2:0] R0 = R0_I[2:0];
      reg [2:0] r;
      wire [2:0] nr = (r == 3'd5) ? 3'd0 : r + 3'd1;    // the next slot (the slot a read is for)
      // Decodes of r, registered beside it: one flip-flop each, not a 3-bit compare, in front of
      // the operand muxes, the dropped bit d0 and the accumulator's first-sum select.
      reg r_is2, r_isd;                                    // r == 2; r == 2 or r == 5 (a D slot)
      always @(posedge clk) begin
        if (rst) begin
          r <= R0;
          r_is2 <= (R0 == 3'd2);
          r_isd <= (R0 == 3'd2) || (R0 == 3'd5);
        end else if (run) begin
          r <= nr;
          r_is2 <= (nr == 3'd2);
          r_isd <= (nr == 3'd2) || (nr == 3'd5);
        end
      end
      // Operands (sign-extended to DW): section a reads signal A (its input) and
      // A+1 (its output history); section b reads A+1 and B+1.
      // Operands: section a's input words x0 (signal A: the input register or
      // section A-1's newest word, kept in a register anyway for m_data/m_sections)
      // and x2 (in2, or pair i-1's second read port); the histories of sections
      // A and B live in one small EBR (two read ports: yosys duplicates it).
      wire [DW-1:0] a_x0, a_x2;
      if (i == 0) begin : g_in
        assign a_x0 = xin_a;
        assign a_x2 = in2_a;
      end else begin : g_prev
        wire [DATA_W-1:0] p0 = hv[((A-1)*HDMAX+0)*DATA_W +: DATA_W];
        assign a_x0 = sx(p0);
        assign a_x2 = sx(q_rd[(i-1)*DATA_W +: DATA_W]);
      end
      // ---- history EBR: words 0-3 ring of section A, 4-7 ring of B, 8 zero --
      // A read is issued one clock before its slot (synchronous read) at
      // wp + (write now) - 1 - depth, so it returns the word the slot's depth
      // names after this clock's write; depth 0 is never read in the clock
      // after its section's write. Words not written since reset read word 8.
      wire wr_a = wr[A];
      wire wr_b;
      if (HAS_B) begin : g_wrb
        assign wr_b = wr[B];
      end else begin : g_nowrb
        assign wr_b = 1'b0;
      end
      reg [1:0] wp_a, wp_b;                 // write pointers
      reg [2:0] vd_a, vd_b;                 // vd[k]: more than k words written since reset
      (* no_rw_check *) reg [DATA_W-1:0] hmem [0:15];
      reg [DATA_W-1:0] prd, qrd;
      integer mi;
      initial begin
        for (mi = 0; mi < 16; mi = mi + 1) hmem[mi] = {DATA_W{1'b0}};
      end
      // Address of depth d after this clock (w: the section writes now): ring
      // word wp - (1 + d - w) (mod 4, table, no adder), or word 8 if not written.
      // Words 8..15 are never written (zero): reset reads one of them by setting
      // the address MSB at the read port, so the addresses depend on registers
      // only (no input-to-address logic for a simulator to settle).
      function [3:0] raddr;
        input       sec, w;
        input [1:0] wp;
        input [2:0] vd;
        input [1:0] d;
        reg   [1:0] k, a;
        reg         ok;
        begin
          k = (d == 2'd0) ? (w ? 2'd0 : 2'd1) : (d == 2'd1) ? (w ? 2'd1 : 2'd2) : (w ? 2'd2 : 2'd3);
          case (k)
            2'd0:    a = wp;
            2'd1:    a = {wp[1] ^ ~wp[0], ~wp[0]};
            2'd2:    a = {~wp[1], wp[0]};
            default: a = {wp[1] ^ wp[0], ~wp[0]};
          endcase
          ok = (d == 2'd0) ? (w | vd[0]) : (d == 2'd1) ? (w ? vd[0] : vd[1]) : (w ? vd[1] : vd[2]);
          raddr = !ok ? 4'd8 : {1'b0, sec, a};
        end
      endfunction
      reg  [3:0] pa;
      always @(*) begin
        case (nr)
          3'd0:    pa = raddr(1'b0, wr_a, wp_a, vd_a, 2'd1);
          3'd3:    pa = raddr(1'b1, wr_b, wp_b, vd_b, 2'd1);
          3'd4:    pa = raddr(1'b1, wr_b, wp_b, vd_b, 2'd0);
          default: pa = raddr(1'b0, wr_a, wp_a, vd_a, 2'd0);
        endcase
      end
      // second port: A depth 2 for slot 5 (b's x2), B depth 2 for slot 3 (pair i+1's a x2)
      wire [3:0] qa = (nr == 3'd3) ? raddr(1'b1, wr_b, wp_b, vd_b, 2'd2)
                                   : raddr(1'b0, wr_a, wp_a, vd_a, 2'd2);
      always @(posedge clk) begin
        if (wr_a || wr_b) hmem[{1'b0, wr_b, wr_b ? wp_b : wp_a}] <= pair_y[i*DATA_W +: DATA_W];
        if (run || rst) begin
          prd <= hmem[{pa[3] | rst, pa[2:0]}];
          qrd <= HAS_B ? hmem[{qa[3] | rst, qa[2:0]}] : {DATA_W{1'b0}};  // a lone last section needs no x2 port
        end
        if (rst) begin
          wp_a <= 2'd0; wp_b <= 2'd0; vd_a <= 3'd0; vd_b <= 3'd0;
        end else begin
          if (wr_a) begin wp_a <= {wp_a[1] ^ wp_a[0], ~wp_a[0]}; vd_a <= {vd_a[1:0], 1'b1}; end
          if (wr_b) begin wp_b <= {wp_b[1] ^ wp_b[0], ~wp_b[0]}; vd_b <= {vd_b[1:0], 1'b1}; end
        end
      end
      assign q_rd[i*DATA_W +: DATA_W] = qrd;

      reg  [DW-1:0]     p, qv;
      reg  [COEF_W-1:0] cf;
      reg               dsel;            // D product: q is x2, else q = ~p
      always @(*) begin
        dsel = r_isd;
        p = r_is2 ? a_x0 : sx(prd);
        qv = r_is2 ? a_x2 : sx(qrd);
        case (r)
          3'd0:    cf = NA2A;
          3'd1:    cf = NA1A;
          3'd2:    cf = B0A2;
          3'd3:    cf = NA2B;
          3'd4:    cf = NA1B;
          default: cf = B0B2;
        endcase
        if (!dsel) qv = ~p;              // (p - ~p) >> 1 == p exactly
      end
      // floor((p - q) / 2): the D operand x0-x2 needs DW+1 bits.
      wire [DW1-1:0] diff = {p[DW-1], p} - {qv[DW-1], qv};
      wire d0 = p[0] ^ qv[0];
      // The dropped bit of x0-x2 weighs b0: it becomes the section's initial
      // partial sum, added when its first (a2) product is accumulated, which is
      // the very cycle its D operands are selected.
      // Initial partial sums (mod 2^AC): rounding constant, plus b0 if d0.
      localparam [AC+COEF_W-1:0] IAW = {{AC{B0A[COEF_W-1]}}, B0A} + RNDW;
      localparam [AC+COEF_W-1:0] IBW = {{AC{B0B[COEF_W-1]}}, B0B} + RNDW;
      localparam [AC-1:0] IA = IAW[AC-1:0], IB = IBW[AC-1:0], I0 = RNDW[AC-1:0];
      wire [AC-1:0] init = !d0 ? I0 : r_is2 ? IA : IB;
      wire first = r_isd;

      reg signed [COEF_W-1:0] mul_a;
      reg signed [DW-1:0]     mul_b;
      reg signed [PW-1:0]     prod;
      reg        [AC-1:0]     acc;
      wire [XW-1:0] prod_x = {{(XW - PW + 1){prod[PW-1]}}, prod[PW-2:0]};
      wire [AC-1:0] acc_next = (first ? init : acc) + prod_x[AC-1:0];
      always @(posedge clk) begin
        if (run) begin
          mul_a <= cf;
          mul_b <= diff[DW1-1:1];
`ifdef FORMAL_FREE_PRODUCT
          prod <= f_prod;
`else
          prod <= mul_a * mul_b;
`endif
          acc <= acc_next;  // exact mod 2^AC: the final sum fits
        end
      end
      if (XW > AC) begin : g_acc_top
        wire unused_prod_top = &{1'b0, prod_x[XW-1:AC]};
      end
      wire unused_diff = diff[0];

      // ---- quantizer: acc (SHIFT more fraction bits) -> DATA_W (rtl/fx_quantize.v) ----
      // FOLD: the rounding constant is already in the sum, so the quantizer truncates.
      wire signed [DATA_W-1:0] y_new;
      wire unused_fits;
      fx_quantize #(.IN_W(AC), .OUT_W(DATA_W), .SHIFT(SHIFT), .ROUNDING(FOLD ? 0 : ROUNDING),
                    .SATURATE(SATURATE)) u_quantize (.x(acc), .y(y_new), .fits(unused_fits));
      assign pair_y[i*DATA_W +: DATA_W] = y_new;

      // Writes: a's sum is final at r5, b's at r2; only for valid waves.
      assign wr[A] = run && r_isd && !r_is2 && wv[DA / 6];   // r == 5
      if (HAS_B) begin : g_wb
        assign wr[B] = run && r_is2 && wv[DB / 6];
      end
    end
  end else begin : g_seq
    // Link k is the input of section k: link 0 is the s port, link SECTIONS the m port.
    wire [SECTIONS:0]        link_valid;
    wire [SECTIONS:1]        link_take;   // link k's beat moves this cycle (link 0: s_valid && s_ready)
    wire [(SECTIONS+1)*DW-1:0] link_data;
    wire [(SECTIONS+1)*TW-1:0] link_taps; // outputs of the sections before k for this sample

    // ---- input port ----------------------------------------------------------
    assign link_valid[0] = s_valid;
    assign link_taps[0 +: TW] = {TW{1'b0}};

      if (IN_SHIFT == 0) begin : g_align0
        assign link_data[0 +: DW] = {{(DW - IN_W + 1){s_data[IN_W-1]}}, s_data[IN_W-2:0]};
      end else begin : g_align
        assign link_data[0 +: DW] = {{(DW - IN_W - IN_SHIFT + 1){s_data[IN_W-1]}},
                                     s_data[IN_W-2:0], {IN_SHIFT{1'b0}}};
      end


    // ---- sections ------------------------------------------------------------
    genvar k;

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

        // ---- quantizer: acc (SHIFT more fraction bits) -> DATA_W (rtl/fx_quantize.v) ----
        wire signed [DATA_W-1:0] y_new;
        wire unused_fits;
        fx_quantize #(.IN_W(ACC_W), .OUT_W(DATA_W), .SHIFT(SHIFT), .ROUNDING(ROUNDING),
                      .SATURATE(SATURATE)) u_quantize (.x(acc), .y(y_new), .fits(unused_fits));

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
    `ifdef FORMAL_FREE_PRODUCT
          prod <= f_prod;
`else
          prod <= mul_a * mul_b;
`endif
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


    // ---- output port ---------------------------------------------------------
    assign link_take[SECTIONS] = link_valid[SECTIONS] && m_ready;
    assign m_valid = link_valid[SECTIONS];
    assign m_sections = link_taps[SECTIONS*TW +: TW];
    assign m_data = link_taps[SECTIONS*TW + (SECTIONS-1)*DATA_W +: DATA_W];
    // The link data of the last section has no consumer (m_data comes from the taps).
    wire unused_last_link = &{1'b0, link_data[SECTIONS*DW +: DW]};
  end
  endgenerate

`ifdef FORMAL
  // Formal properties (formal/run_formal.sh bandpass_sos, bandpass_sos_general). Assumed: reset
  // first; the input follows the AXI-Stream rules (valid held until ready, data stable while
  // waiting); m_ready free.
  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume(rst);
  always @(posedge clk)
    if (f_past_valid && !$past(rst) && $past(s_valid && !s_ready)) begin
      assume(s_valid);
      assume(s_data == $past(s_data));
    end
  // samples in flight: taken on s_*, not yet handed out on m_*
  localparam integer F_MAXFLY = 2 * SECTIONS + 8;
  reg [7:0] f_fly = 8'd0;
  always @(posedge clk)
    if (rst) f_fly <= 8'd0;
    else f_fly <= f_fly + {7'd0, s_valid && s_ready} - {7'd0, m_valid && m_ready};
  // Reset state: no output, ready for a sample.
  always @(posedge clk)
    if (f_past_valid && $past(rst)) assert(!m_valid && s_ready && f_fly == 0);
  // No output without a sample taken for it (nothing duplicated), and a bounded pipeline.
  always @(*)
    if (f_past_valid && !rst) begin
      if (m_valid) assert(f_fly != 8'd0);
      assert(f_fly <= F_MAXFLY);
    end
  // AXI-Stream master: m_valid stays up until m_ready, the sample and the taps are stable.
  always @(posedge clk)
    if (f_past_valid && !$past(rst) && !rst && $past(m_valid && !m_ready)) begin
      assert(m_valid);
      assert(m_data == $past(m_data) && m_sections == $past(m_sections));
    end
`endif

endmodule

`default_nettype wire
