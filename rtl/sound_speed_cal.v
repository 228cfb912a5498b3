////////////////////////////////////////////////////////////////////////////////
//
// Filename:  rtl/sound_speed_cal.v
//
// Project:   ranging -- coded ultrasonic ranging system
//
// Purpose:   Sound-velocity compensation (the paper's section 3.1; issue 14 §6):
//            a reference path at a calibrated distance D (CAL_DIST_UM
//            micrometres, the system's calibration_distance_m) measures the
//            speed of sound, and the result is loaded into the speed register
//            C of tof_distance (model: calibrated_speed_register() in
//            model/hw/sound_speed_cal.hpp, bit exact).
//
//            Calibration event: `arm` (one clock) makes the next measurement
//            without flags (m_flags == 0) the reference path's. With its ToF
//            (full-rate samples, FRAC_W fraction bits) the speed register
//            becomes
//              C = floor((D 2^SH + floor(ToF / 2)) / ToF),  SH = FRAC_W + C_FRAC
//            i.e. D / ToF rounded half up, in micrometres per full-rate sample
//            with C_FRAC fraction bits (tof_distance's format: distance =
//            (ToF C + 2^(SH-1)) >> SH, so the reference path then reads D).
//            C saturates at 2^C_W - 1 (sat_count counts it); a ToF of 0 or
//            a measurement with flags leaves the calibration armed.
//            c_wr pulses one clock with c_value = C when the division ends.
//
// Timing:    restoring division, one quotient bit per clock: NW + 1 clocks
//            from the reference measurement to c_wr (NW = numerator width,
//            about 42 for D = 0.1 m); measurements come every PERIOD_T
//            samples, so the next one already uses the new C.
//
////////////////////////////////////////////////////////////////////////////////
`default_nettype none
/* verilator lint_off WIDTH */

module sound_speed_cal #(
  parameter integer TOF_W = 32,
  parameter integer C_W = 32,
  parameter integer SH = 24,               // FRAC_W + C_FRAC of tof_distance
  parameter integer CAL_DIST_UM = 100000   // D, micrometres (> 0)
) (
  input  wire clk, rst,
  input  wire arm,                      // calibration event
  input  wire meas_valid,               // a measurement is taken (m_valid & m_ready)
  input  wire [1:0] meas_flags,
  input  wire [TOF_W-1:0] meas_tof,
  output reg  c_wr,
  output reg  [C_W-1:0] c_value,
  output reg  armed,
  output wire busy,
  output reg  [7:0] sat_count
);
  localparam integer DW = $clog2(CAL_DIST_UM + 1);
  localparam integer NW = ((DW + SH > TOF_W) ? DW + SH : TOF_W) + 1;  // D 2^SH + ToF/2 fits
  localparam integer CNT_W = $clog2(NW + 1);
  localparam [NW-1:0] D_SHIFTED = CAL_DIST_UM * (64'd1 << SH);

  reg running;
  reg [CNT_W-1:0] cnt;
  reg [NW-1:0] num;        // numerator, shifted out MSB first; the quotient shifts in
  reg [TOF_W-1:0] den;
  reg [TOF_W-1:0] rem;     // < den
  wire [TOF_W:0] rem_sh = {rem, num[NW-1]};
  wire [TOF_W+1:0] diff = {1'b0, rem_sh} - {2'b00, den};
  wire q_bit = !diff[TOF_W+1];
  wire [NW-1:0] quot = {num[NW-2:0], q_bit};   // after the last step
  wire over = |quot[NW-1:C_W];

  assign busy = running;

  always @(posedge clk) begin
    if (rst) begin
      armed <= 1'b0;
      running <= 1'b0;
      c_wr <= 1'b0;
      sat_count <= 0;
    end else begin
      c_wr <= 1'b0;
      if (arm) armed <= 1'b1;
      if (!running && armed && meas_valid && meas_flags == 2'b00 && meas_tof != 0) begin
        armed <= arm;
        running <= 1'b1;
        cnt <= 0;
        num <= D_SHIFTED + (meas_tof >> 1);
        den <= meas_tof;
        rem <= 0;
      end else if (running) begin
        rem <= q_bit ? diff[TOF_W-1:0] : rem_sh[TOF_W-1:0];
        num <= quot;
        cnt <= cnt + 1'b1;
        if (cnt == NW - 1) begin
          running <= 1'b0;
          c_wr <= 1'b1;
          c_value <= over ? {C_W{1'b1}} : quot[C_W-1:0];
          if (over && sat_count != 8'hff) sat_count <= sat_count + 1'b1;
        end
      end
    end
  end

`ifdef FORMAL
  // Formal properties (formal/run_formal.sh sound_speed_cal). Assumed: reset first; every input
  // else is free (arm, measurements, flags, ToF). The division is checked against the
  // equation with a shadow of the ToF the run started with.
  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume(rst);
  reg [TOF_W-1:0] f_tof;
  always @(posedge clk)
    if (!rst && !running && armed && meas_valid && meas_flags == 2'b00 && meas_tof != 0) f_tof <= meas_tof;
  wire [NW-1:0] f_num0 = D_SHIFTED + (f_tof >> 1);           // D 2^SH + floor(ToF / 2)
  wire [NW-1:0] f_quot = f_num0 / f_tof;                      // the equation's C before saturation
  wire f_over = |(f_quot >> C_W);
  wire [C_W-1:0] f_c = f_over ? {C_W{1'b1}} : f_quot[C_W-1:0];
  // restoring division after cnt steps: the top cnt numerator bits consumed, quotient q in
  // num's low cnt bits, the rest of the numerator above it, and top = q den + rem, rem < den
  wire [NW-1:0] f_mask = ({{(NW-1){1'b0}}, 1'b1} << cnt) - 1'b1;
  wire [NW-1:0] f_top = f_num0 >> (NW - cnt);
  /* verilator lint_off UNUSEDSIGNAL */
  wire [NW+TOF_W-1:0] f_qd = (num & f_mask) * den + rem;
  /* verilator lint_on UNUSEDSIGNAL */
  always @(posedge clk)
    if (f_past_valid && $past(rst)) assert(!armed && !running && !c_wr && sat_count == 0);
  always @(*)
    if (f_past_valid && !rst) begin
      assert(busy == running);
      if (running) begin
        assert(cnt < NW && den == f_tof && den != 0 && rem < den);
        assert(f_qd == {{TOF_W{1'b0}}, f_top});
        assert((num >> cnt) == (f_num0 & ~(f_mask << (NW - cnt)) & ({NW{1'b1}} >> cnt)));
      end
    end
  always @(posedge clk)
    if (f_past_valid && !$past(rst) && !rst) begin
      if (c_wr) assert(c_value == f_c && $past(running) && !$past(c_wr));  // C by the equation, one clock
      if (c_wr && f_over) assert(sat_count == ($past(sat_count) == 8'hff ? 8'hff : $past(sat_count) + 8'd1));
      if (c_wr && !f_over || !c_wr) assert(sat_count == $past(sat_count));
    end
`endif
endmodule

`default_nettype wire
