////////////////////////////////////////////////////////////////////////////////
//
// Filename:  rtl/tof_distance.v
//
// Project:   ranging -- coded ultrasonic ranging system
//
// Purpose:   Time of flight and distance of every receiver event
//            (model: ranging::TofDistanceModel in model/hw/hw_system.hpp, bit exact).
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
//              A  += 2^(TIME_W+FRAC_W)    while A - t_j 2^FRAC_W < -2^(TIME_W+FRAC_W-1):
//                                         the sample counters wrap after 2^TIME_W
//                                         samples, and an arrival more than half
//                                         that range behind the burst was counted
//                                         after the wrap (tb_tof_distance crosses it)
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
// Timing:    sequential (no DSP): the offset is subtracted over two clocks (low
//            half at capture, high half in the first step-back cycle), up to
//            CODES-1 cycles to step back to code j's burst (t - PERIOD_T or
//            t - CYCLE as a carry-select subtractor: the constant's low bits,
//            and t's high bits or those minus 1), 2-3 cycles for the
//            ToF (its subtractor is registered; two more per cycle stepped back
//            and across a counter wrap),
//            TOF_W cycles of shift-add (one C_W+1-bit adder) multiply with the
//            rounding term as its start value, 1 cycle to saturate the distance,
//            then the result waits on m_ready. s_ready is high only when idle:
//            under 50 cycles per event, events come every PERIOD_T samples.
//            Needs FRAC_W + C_FRAC < TOF_W and FRAC_W + C_FRAC <= C_W.
//
////////////////////////////////////////////////////////////////////////////////
`default_nettype none
// Widths of constant expressions (parameters are 32-bit integers) are checked by design.
/* verilator lint_off WIDTH */

module tof_distance #(
  parameter integer CODES = 9,                 // codes sent in turn, 1..CODES
  parameter integer CODE_W = 4,                // bits of a code number
  parameter integer TIME_W = 40,               // sample index width (burst times, arrivals' integer part)
  parameter integer FRAC_W = 8,                // fraction bits of arrival, offsets and ToF
  parameter integer PERIOD_T = 1634,           // samples between consecutive bursts
  parameter integer SCORE_W = 16,              // event score width (passed through to the result)
  parameter integer OFF_W = 32,                // width of one latency offset
  parameter [CODES*OFF_W-1:0] OFFSETS = 0,     // signed, FRAC_W fraction bits, code j (1-based) at [(j-1)*OFF_W +: OFF_W]
  parameter integer C_W = 32,                  // speed of sound register width
  parameter integer C_FRAC = 16,               // its fraction bits
  parameter [C_W-1:0] C_INIT = 32'd4456448,    // 340 m/s at 5 MS/s: 68 um/sample * 2^16
  parameter integer TOF_W = 32,                // ToF result width (saturated)
  parameter integer DIST_W = 32                // distance result width, micrometres (saturated)
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
  output wire m_valid,
  input  wire m_ready,
  output reg  [CODE_W-1:0] m_code,
  output wire [1:0] m_flags,
  output wire [TOF_W-1:0] m_tof,
  output wire [DIST_W-1:0] m_distance,
  output reg  [SCORE_W-1:0] m_score, m_margin
);
  localparam integer ARR_W = TIME_W + FRAC_W + 1;     // s_arrival
  localparam integer AW = (ARR_W > OFF_W ? ARR_W : OFF_W) + 1;  // A = arrival - offset, signed
  localparam integer DW = AW + 1;                     // A - t 2^FRAC_W, signed (t < 2^TIME_W)
  localparam integer TW = TIME_W + 2;                 // signed burst times, t - CYCLE
  localparam integer KW = CODE_W + 1;
  localparam integer SH = FRAC_W + C_FRAC;
  localparam integer LO_W = TOF_W - SH;               // product bits below hi that reach the distance
  localparam integer CNT_W = ($clog2(TOF_W) > KW + 1 ? $clog2(TOF_W) : KW + 1);
  localparam integer CYCLE = CODES * PERIOD_T;
  generate
    if ($clog2(CODES * PERIOD_T + 1) >= TIME_W + 2) begin : g_bad_cycle
      initial $error("tof_distance: CODES * PERIOD_T = %0d needs more bits than the burst times' %0d", CODES * PERIOD_T, TIME_W + 2);
    end
    if (TOF_W > DW - 1) begin : g_bad_tof_w
      initial $error("tof_distance: TOF_W %0d wider than A - t 2^FRAC_W can be (max(TIME_W + FRAC_W + 1, OFF_W) + 1 = %0d)", TOF_W, DW - 1);
    end
  endgenerate
  localparam [2:0] IDLE = 0, BACK = 1, TOF = 2, MUL = 3, CLAMP = 4, OUT = 5, TOF0 = 6;

  reg [2:0] state;
  reg have_burst;
  reg [TIME_W-1:0] last_time;
  reg [CODE_W-1:0] last_code;

  reg signed [AW-1:0] a;      // A = arrival - offset
  // A in two clocks (half the carry chain each): IDLE subtracts the low AL bits and keeps the
  // borrow and the offset's high part, BACK's first clock (a_fix) the high part
  localparam integer AL = AW / 2;
  reg           a_fix, a_b;
  reg [AW-AL-1:0] off_hi;
  reg signed [TW-1:0] t;      // candidate burst start
  reg [CNT_W-1:0] cnt;        // BACK: periods left to step back; MUL: steps done
  reg no_tx, sat;
  // Product ToF * C + 2^(SH-1) (the rounding term) by right-shifting shift-add: each step adds C
  // to hi when the multiplier's low bit is 1 and shifts hi right; the bit shifted out is the next
  // product bit (only the last LO_W of them reach the distance). hi starts at 2^(SH-1), which
  // adds 2^(SH-1) to the product. The multiplier rotates, so after TOF_W steps it is the ToF again.
  reg [TOF_W-1:0] mplier;
  reg [C_W-1:0] hi;      // < 2^C_W after every step: (hi + C) / 2 < 2^C_W
  reg [LO_W-1:0] lo;
  reg [C_W-1:0] c_used;

  // the event is taken when idle (the consumer of the measurements may hold m_ready low for a
  // whole UART frame; the receiver must not wait that long), its fields are copied
  assign s_ready = state == IDLE;
  assign m_valid = state == OUT;
  assign m_tof = mplier;
  wire [C_W+LO_W-1:0] dist_full = {hi, lo};  // (ToF * C + 2^(SH-1)) >> SH
  wire dist_over = |dist_full[C_W+LO_W-1:DIST_W];
  assign m_distance = dist_full[DIST_W-1:0];  // saturated in CLAMP
  assign m_flags = {sat, no_tx};

  // offset of the event's code (a small ROM)
  wire [CODES*OFF_W-1:0] offsets = OFFSETS;
  wire [CODE_W-1:0] j0 = s_code - 1'b1;
  wire signed [OFF_W-1:0] off = (s_code >= 1 && s_code <= CODES) ? offsets[j0 * OFF_W +: OFF_W] : {OFF_W{1'b0}};
  wire signed [AW-1:0] arr_x = $signed(s_arrival);
  wire signed [AW-1:0] off_x = off;
  wire [AL:0] a_lo = {1'b0, arr_x[AL-1:0]} - {1'b0, off_x[AL-1:0]};
  wire signed [KW:0] diff = $signed({2'b00, last_code}) - $signed({2'b00, s_code});
  wire signed [KW:0] k0 = diff < 0 ? diff + CODES : diff;

  // one subtractor steps t back (a period in BACK, a cycle in TOF); its sign in TOF is t < CYCLE.
  // in_back is state == BACK as a register of its own: the operand select then comes from one
  // flip-flop, not from the state decode, ahead of the TW-bit carry chain (a critical path).
  // Carry-select: both constants fit the low TL bits, so the high TW-TL bits are t's or t's
  // minus 1, picked by the low segment's borrow (two short chains side by side, not one of TW).
  reg in_back;
  localparam integer TL = $clog2(CYCLE + 1);          // CYCLE >= PERIOD_T
  localparam [TL-1:0] PERIOD_L = PERIOD_T, CYCLE_L = CYCLE;
  wire [TL:0]    ts_lo = {1'b0, t[TL-1:0]} - {1'b0, (in_back ? PERIOD_L : CYCLE_L)};
  wire [TW-TL-1:0] ts_hi1 = t[TW-1:TL] - 1'b1;
  wire signed [TW-1:0] t_step = {ts_lo[TL] ? ts_hi1 : t[TW-1:TL], ts_lo[TL-1:0]};
  // sign of t - CYCLE, registered: TOF reads it after TOF0, where t has not changed
  reg t_step_neg;
  always @(posedge clk) t_step_neg <= t_step[TW-1];
  // A - t 2^FRAC_W, registered every clock (TOF0 waits for it after t changes): its wide
  // subtractor and the saturation test into mplier are in different clocks
  reg signed [DW-1:0] tof_w;
  always @(posedge clk) tof_w <= a - ($signed(t) <<< FRAC_W);
  // The sample counters wrap after 2^TIME_W samples: A - t 2^FRAC_W < -2^(TIME_W+FRAC_W-1), an
  // arrival more than half the range behind the burst, was counted after the wrap; A is then
  // 2^TIME_W samples later (a carry into A's top bits; AW leaves room for it).
  localparam integer WK = TIME_W + FRAC_W - 1;
  wire wrapped = tof_w[DW-1] && !(&tof_w[DW-1:WK]);
  wire [C_W:0] hsum = {1'b0, hi} + (mplier[0] ? {1'b0, c_used} : {(C_W+1){1'b0}});

  always @(posedge clk) begin
    if (rst) begin
      state <= IDLE;
      have_burst <= 1'b0;
      last_time <= 0;
      last_code <= 0;
      c_current <= C_INIT;
      in_back <= 1'b0;
    end else begin
      if (burst_valid) begin
        have_burst <= 1'b1;
        last_time <= burst_time;
        last_code <= burst_code;
      end
      if (c_wr) c_current <= c_value;
      case (state)
        IDLE: if (s_valid) begin
          state <= BACK;
          in_back <= 1'b1;
        end
        BACK: if (cnt == 0) begin
          state <= TOF0;
          in_back <= 1'b0;
        end
        TOF0: state <= TOF;
        TOF: state <= (no_tx || (!t[TW-1] && !tof_w[DW-1])) ? MUL
                     : (t[TW-1] || (t_step_neg && !wrapped)) ? TOF : TOF0;  // stepped back or A moved: wait for tof_w
        MUL: if (cnt == TOF_W - 1) state <= CLAMP;
        CLAMP: state <= OUT;
        OUT: if (m_ready) state <= IDLE;
        default: state <= IDLE;
      endcase
    end
  end

  // datapath (no reset: every field is loaded before it is read)
  always @(posedge clk) begin
    case (state)
      IDLE: begin
        a <= {arr_x[AW-1:AL], a_lo[AL-1:0]};   // s_code is a register: one LUT level
        a_b <= a_lo[AL];
        off_hi <= off_x[AW-1:AL];
        a_fix <= 1'b1;
        t <= $signed({2'b00, last_time});
        cnt <= k0;
        no_tx <= !have_burst;
        c_used <= c_current;
        m_code <= s_code;
        m_score <= s_score;
        m_margin <= s_margin;
      end
      BACK: begin
        if (a_fix) a[AW-1:AL] <= a[AW-1:AL] - off_hi - {{(AW-AL-1){1'b0}}, a_b};
        a_fix <= 1'b0;
        if (cnt != 0) begin
          t <= t_step;
          cnt <= cnt - 1'b1;
        end
      end
      TOF: begin
        if (no_tx) begin
          mplier <= 0;
          sat <= 1'b0;
        end else if (t[TW-1]) begin
          no_tx <= 1'b1;  // code j's burst would precede the first one: never sent
        end else if (wrapped) begin
          a[AW-1:WK+1] <= a[AW-1:WK+1] + 1'b1;  // A + 2^(TIME_W+FRAC_W)
        end else if (tof_w[DW-1]) begin
          if (t_step_neg) no_tx <= 1'b1;
          else t <= t_step;
        end else begin
          sat <= |tof_w[DW-1:TOF_W];
          mplier <= |tof_w[DW-1:TOF_W] ? {TOF_W{1'b1}} : tof_w[TOF_W-1:0];
        end
        hi <= 1 << (SH - 1);
        cnt <= 0;
      end
      MUL: begin
        hi <= hsum[C_W:1];
        lo <= {hsum[0], lo[LO_W-1:1]};
        mplier <= {mplier[0], mplier[TOF_W-1:1]};
        cnt <= cnt + 1'b1;
      end
      CLAMP: if (dist_over) begin
        {hi, lo} <= {(C_W+LO_W){1'b1}};
        sat <= 1'b1;
      end
      default: ;
    endcase
  end

`ifdef FORMAL
  // Formal properties (formal/run_formal.sh tof_distance). Assumed: reset first. Every input
  // else is free: any burst schedule, arrival, code (in range or not), c write and m_ready.
  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume(rst);
  // Clocks spent on one event (BACK .. CLAMP), and the bound it must stay under: CODES-1
  // step-backs of a period, a ToF loop of at most 2^TIME_W / CYCLE + 2 cycles stepped back
  // plus the counter-wrap corrections (two clocks each), TOF_W multiply steps, the clamp.
  localparam integer F_BOUND = CODES + 2 * ((1 << TIME_W) / CYCLE + 6) + TOF_W + 4;
  reg [7:0] f_busy = 8'd0;
  always @(posedge clk)
    if (rst || state == IDLE || state == OUT) f_busy <= 8'd0;
    else if (f_busy != 8'hff) f_busy <= f_busy + 8'd1;
  always @(posedge clk)
    if (f_past_valid && $past(rst))
      assert(state == IDLE && !have_burst && c_current == C_INIT && !in_back && f_busy == 0);
  always @(*)
    if (f_past_valid && !rst) begin
      assert(state <= TOF0);                       // the seven legal states
      assert(in_back == (state == BACK));
      assert(f_busy <= F_BOUND);                   // every event ends: no stall in TOF / TOF0
      if (state == MUL) assert(cnt < TOF_W);
      if (m_valid) begin
        assert(!s_ready);
        // no burst of the code before the arrival: ToF and distance 0, not saturated
        if (m_flags[0]) assert(m_tof == 0 && m_distance == 0 && !m_flags[1]);
      end
    end
  // output stream: held with its data until taken
  always @(posedge clk)
    if (f_past_valid && !$past(rst) && !rst && $past(m_valid && !m_ready)) begin
      assert(m_valid);
      assert($stable(m_code) && $stable(m_flags) && $stable(m_tof) && $stable(m_distance));
      assert($stable(m_score) && $stable(m_margin));
    end
`endif
endmodule

`default_nettype wire
