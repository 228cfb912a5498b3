////////////////////////////////////////////////////////////////////////////////
//
// Filename:  rtl/tof_distance.v
//
// Project:   ranging -- coded ultrasonic ranging system
//
// Purpose:   Time of flight and distance of every receiver event
//            (model: ranging::TofDistanceModel in model/hw_system.hpp, bit exact).
//
//            For an event {code j, arrival a} (a: signed full-rate sample index
//            with FRAC_W fraction bits, the correlation peak of the receiver):
//              A   = a - OFFSETS[j]          receiver latency of code j (the
//                                            matched-filter peak of a burst sent
//                                            at sample 0 over zero distance),
//                                            calibrated on the golden model
//              t_j = start sample of the most recent burst of code j with
//                    t_j 2^FRAC_W <= A: from the last burst (time S, code c)
//                    t_j = S - ((c - j) mod CODES) PERIOD_T, then minus
//                    CODES PERIOD_T while A - t_j 2^FRAC_W < 0 (the schedule is
//                    strictly periodic, so no per-code table is needed); t_j < 0
//                    means the code was never sent (flag)
//              ToF = A - t_j 2^FRAC_W     unsigned TOF_W, FRAC_W fraction bits
//                                         (full-rate samples), saturated
//              distance = (ToF * C + 2^(FRAC_W+C_FRAC-1)) >> (FRAC_W+C_FRAC)
//                                         round half up, unsigned DIST_W,
//                                         micrometres, saturated
//            C is the speed of sound in micrometres per full-rate sample with
//            C_FRAC fraction bits (c / fs * 1e6 * 2^C_FRAC), held in a register
//            loaded with C_INIT at reset and by c_wr/c_value at run time (the
//            paper's sound-velocity compensation module writes a measured c).
//            Flags: bit 0 no burst of code j before the arrival (ToF and
//            distance 0), bit 1 ToF or distance saturated.
//
// Timing:    sequential (no DSP): up to CODES-1 cycles to step back to code j's
//            burst, 1-2 cycles for the ToF, TOF_W cycles of shift-add (one C_W+1-bit adder)
//            multiply, then the result waits on m_ready. s_ready is high only
//            when idle: under 50 cycles per event, events come every PERIOD_T
//            samples.
//
////////////////////////////////////////////////////////////////////////////////
`default_nettype none
// Widths of constant expressions (parameters are 32-bit integers) are checked by design.
/* verilator lint_off WIDTH */

module tof_distance #(
  parameter integer CODES = 9,
  parameter integer CODE_W = 4,
  parameter integer TIME_W = 40,
  parameter integer FRAC_W = 8,
  parameter integer PERIOD_T = 1634,
  parameter integer SCORE_W = 16,
  parameter integer OFF_W = 32,
  parameter [CODES*OFF_W-1:0] OFFSETS = 0,  // signed, FRAC_W fraction bits, code j (1-based) at [(j-1)*OFF_W +: OFF_W]
  parameter integer C_W = 32,
  parameter integer C_FRAC = 16,
  parameter [C_W-1:0] C_INIT = 32'd4456448,  // 340 m/s at 5 MS/s: 68 um/sample * 2^16
  parameter integer TOF_W = 32,
  parameter integer DIST_W = 32
) (
  input  wire clk, rst,
  // transmit schedule (tx_scheduler)
  input  wire burst_valid,
  input  wire [CODE_W-1:0] burst_code,
  input  wire [TIME_W-1:0] burst_time,
  // speed of sound register
  input  wire c_wr,
  input  wire [C_W-1:0] c_value,
  output reg  [C_W-1:0] c_current,
  // receiver events
  input  wire s_valid,
  output wire s_ready,
  input  wire [CODE_W-1:0] s_code,
  input  wire signed [TIME_W+FRAC_W:0] s_arrival,
  input  wire [SCORE_W-1:0] s_score, s_margin,
  // measurements
  output reg  m_valid,
  input  wire m_ready,
  output reg  [CODE_W-1:0] m_code,
  output reg  [1:0] m_flags,
  output reg  [TOF_W-1:0] m_tof,
  output reg  [DIST_W-1:0] m_distance,
  output reg  [SCORE_W-1:0] m_score, m_margin
);
  localparam integer AW = TIME_W + FRAC_W + 3;        // signed working width
  localparam integer TW = TIME_W + 2;                 // signed burst times
  localparam integer KW = CODE_W + 1;
  localparam integer PW = TOF_W + C_W;
  localparam integer SH = FRAC_W + C_FRAC;
  localparam integer MCW = $clog2(TOF_W + 1);
  localparam [2:0] IDLE = 0, BACK = 1, TOF = 2, MUL = 3, OUT = 4;

  reg [2:0] state;
  reg have_burst;
  reg [TIME_W-1:0] last_time;
  reg [CODE_W-1:0] last_code;

  reg signed [AW-1:0] a;      // A = arrival - offset
  reg signed [TW-1:0] t;      // candidate burst start
  reg [KW:0] k;
  reg no_tx, sat;
  // Product ToF * C by right-shifting shift-add: {hi, mplier} holds the partial product;
  // each step adds C to hi when the multiplier's low bit is 1 and shifts the pair right,
  // so after TOF_W steps {hi, mplier} = ToF * C (PW bits) with only a C_W+1-bit adder.
  reg [TOF_W-1:0] mplier;
  reg [C_W-1:0] hi;      // < 2^C_W after every step: (hi + C) / 2 < 2^C_W
  reg [C_W-1:0] c_used;
  reg [MCW-1:0] mcount;

  assign s_ready = state == IDLE;

  // offset of the event's code (a small ROM)
  wire [CODES*OFF_W-1:0] offsets = OFFSETS;
  wire [CODE_W-1:0] j0 = s_code - 1'b1;
  wire signed [OFF_W-1:0] off = (s_code >= 1 && s_code <= CODES) ? offsets[j0 * OFF_W +: OFF_W] : {OFF_W{1'b0}};
  wire signed [KW:0] diff = $signed({2'b00, last_code}) - $signed({2'b00, s_code});
  wire signed [KW:0] k0 = diff < 0 ? diff + CODES : diff;

  wire signed [AW-1:0] t_scaled = $signed(t) <<< FRAC_W;
  wire signed [AW-1:0] tof_w = a - t_scaled;
  localparam integer CYCLE = CODES * PERIOD_T;
  // (P + 2^(SH-1)) >> SH == (P >> SH) + P[SH-1]: round half up as an increment.
  wire [PW-1:0] prod = {hi, mplier};
  wire [C_W:0] hsum = {1'b0, hi} + (mplier[0] ? {1'b0, c_used} : {(C_W+1){1'b0}});
  wire [PW:0] dist_full = {1'b0, prod[PW-1:SH]} + prod[SH-1];
  wire dist_over = |dist_full[PW:DIST_W];

  always @(posedge clk) begin
    if (rst) begin
      state <= IDLE;
      have_burst <= 1'b0;
      last_time <= 0;
      last_code <= 0;
      c_current <= C_INIT;
      m_valid <= 1'b0;
      m_code <= 0; m_flags <= 0; m_tof <= 0; m_distance <= 0; m_score <= 0; m_margin <= 0;
      a <= 0; t <= 0; k <= 0; no_tx <= 0; sat <= 0; mplier <= 0; hi <= 0;
      c_used <= 0; mcount <= 0;
    end else begin
      if (burst_valid) begin
        have_burst <= 1'b1;
        last_time <= burst_time;
        last_code <= burst_code;
      end
      if (c_wr) c_current <= c_value;
      case (state)
        IDLE: if (s_valid) begin
          m_code <= s_code;
          m_score <= s_score;
          m_margin <= s_margin;
          a <= $signed(s_arrival) - off;
          t <= $signed({2'b00, last_time});
          k <= k0;
          no_tx <= !have_burst;
          sat <= 1'b0;
          c_used <= c_current;
          state <= BACK;
        end
        BACK: if (k != 0) begin
          t <= t - PERIOD_T;
          k <= k - 1'b1;
        end else begin
          state <= TOF;
        end
        TOF: begin
          if (no_tx) begin
            mplier <= 0;
            state <= MUL;
          end else if (t < 0) begin
            no_tx <= 1'b1;  // code j's burst would precede the first one: never sent
          end else if (tof_w < 0) begin
            if (t < CYCLE) no_tx <= 1'b1;
            else t <= t - CYCLE;
          end else begin
            if (|tof_w[AW-1:TOF_W]) begin
              mplier <= {TOF_W{1'b1}};
              sat <= 1'b1;
            end else begin
              mplier <= tof_w[TOF_W-1:0];
            end
            state <= MUL;
          end
          hi <= 0;
          mcount <= 0;
        end
        MUL: begin
          {hi, mplier} <= {hsum, mplier[TOF_W-1:1]};  // (hi + C [lsb]) : mplier, shifted right
          if (mcount == TOF_W - 1) state <= OUT;
          mcount <= mcount + 1'b1;
          if (mcount == 0) m_tof <= mplier;
        end
        OUT: if (!m_valid) begin
          m_valid <= 1'b1;
          m_flags <= {sat || dist_over, no_tx};
          m_distance <= dist_over ? {DIST_W{1'b1}} : dist_full[DIST_W-1:0];
        end else if (m_ready) begin
          m_valid <= 1'b0;
          state <= IDLE;
        end
        default: state <= IDLE;
      endcase
    end
  end
endmodule

`default_nettype wire
