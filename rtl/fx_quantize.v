////////////////////////////////////////////////////////////////////////////////
//
// Filename:  rtl/fx_quantize.v
//
// Project:   ranging -- coded ultrasonic ranging receiver
//
// Purpose:   The fixed-point quantizer of every rounding node of the receiver
//            (bandpass section outputs, the correlator's mixer, chip filter and
//            combiner): drop SHIFT fraction bits with a rounding mode, then fit
//            the result into OUT_W bits with an overflow mode,
//
//              q = round(x / 2^SHIFT)                      (exact, QW bits)
//              y = q                if q fits OUT_W bits
//                  saturate(q)      if SATURATE, else the low OUT_W bits (wrap)
//
//            bit for bit the model's fx_quantize (model/dsp/fixed_point.hpp).
//            x and y are two's complement; y has SHIFT fewer fraction bits.
//
// Rounding:  ROUNDING 0: truncate (floor, toward -inf); 1: round half up (add
//            2^(SHIFT-1), then floor); 2: convergent (half to even: add
//            2^(SHIFT-1) - 1 plus the lsb of the truncated result). SHIFT 0:
//            no rounding.
// Widths:    x is sign-extended to RW = max(IN_W, SHIFT + 1) + 1 bits, so the
//            rounding add never overflows; q has QW = RW - SHIFT bits. When
//            QW <= OUT_W, q always fits (y is q sign-extended).
// Overflow:  fits = 1 when q fits OUT_W bits (the bits from OUT_W-1 up are all
//            equal: a LUT tree, not two compares). SATURATE 1: y = -2^(OUT_W-1)
//            or 2^(OUT_W-1)-1 when q does not fit; 0: y wraps mod 2^OUT_W.
//            A caller that counts overflows reads fits.
//
// Timing:    combinational (no clock, no registers): latency 0, one result per
//            evaluation. Cost: one RW-bit adder when SHIFT > 0 and ROUNDING > 0,
//            plus the fit test and a 2:1 mux when SATURATE and QW > OUT_W.
//
////////////////////////////////////////////////////////////////////////////////
`default_nettype none

module fx_quantize #(
  parameter integer IN_W = 32,      // input word, two's complement
  parameter integer OUT_W = 16,     // output word, two's complement
  parameter integer SHIFT = 14,     // fraction bits dropped, >= 0 (may exceed IN_W)
  parameter integer ROUNDING = 1,   // 0 truncate, 1 round half up, 2 convergent
  parameter integer SATURATE = 1    // 1 saturate, 0 wrap
) (
  input  wire [IN_W-1:0]  x,
  output wire [OUT_W-1:0] y,
  output wire             fits      // q fitted OUT_W bits (no saturation, no wrap)
);
  localparam integer RW = ((IN_W > SHIFT + 1) ? IN_W : SHIFT + 1) + 1;
  localparam integer QW = RW - SHIFT;

  generate
    if (IN_W < 2 || OUT_W < 2 || SHIFT < 0) begin : g_bad_width
      initial $error("fx_quantize: needs IN_W >= 2, OUT_W >= 2 and SHIFT >= 0");
    end
    if (ROUNDING < 0 || ROUNDING > 2 || SATURATE < 0 || SATURATE > 1) begin : g_bad_mode
      initial $error("fx_quantize: ROUNDING must be 0..2 and SATURATE 0..1");
    end
  endgenerate

  wire [RW-1:0] xr = {{(RW - IN_W + 1){x[IN_W-1]}}, x[IN_W-2:0]};
  wire [QW-1:0] q;

  generate
    if (SHIFT == 0) begin : g_noround
      assign q = xr;
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
                   + {{(RW - 1){1'b0}}, xr[SHIFT]};
      end
      wire [RW-1:0] sum = xr + rnd;
      assign q = sum[RW-1:SHIFT];
      // The dropped fraction bits only matter through the carry into q.
      wire unused_round_bits = &{1'b0, sum[SHIFT-1:0]};
    end

    if (QW > OUT_W) begin : g_ovf
      assign fits = &q[QW-1:OUT_W-1] || ~|q[QW-1:OUT_W-1];
      if (SATURATE != 0) begin : g_sat
        assign y = fits ? q[OUT_W-1:0]
                 : (q[QW-1] ? {1'b1, {(OUT_W-1){1'b0}}} : {1'b0, {(OUT_W-1){1'b1}}});
      end else begin : g_wrap
        assign y = q[OUT_W-1:0];
      end
    end else begin : g_noovf
      assign fits = 1'b1;
      assign y = {{(OUT_W - QW + 1){q[QW-1]}}, q[QW-2:0]};
    end
  endgenerate
endmodule

`default_nettype wire
