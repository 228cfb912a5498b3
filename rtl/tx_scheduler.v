////////////////////////////////////////////////////////////////////////////////
//
// Filename:  rtl/tx_scheduler.v
//
// Project:   ranging -- coded ultrasonic ranging system
//
// Purpose:   The transmit scheduler. Every PERIOD_T full-rate samples it starts
//            one burst, cycling through the CODES codes of the family in order
//            (code 1, 2, ..., CODES, 1, ...), and drives the transmitter's
//            H-bridge with the two-level BPSK drive of that code: sample n of
//            chip m is
//              ph   = (2 CYC n + (c_m + 1) SPC) mod 2 SPC
//              sign = ph < SPC ? +1 : -1
//            exactly model/dsp/excitation.cpp hbridge_drive (CYC = q carrier cycles
//            per chip, SPC = q fs / f samples per chip, c_m the chip bit). The
//            phase is kept as a counter stepped by 2 CYC mod 2 SPC (no divider).
//            Outside a burst both legs are off (hb_p = hb_n = 0).
//
// Timing:    `tick` is the full-rate sample strobe (one clock per sample, from
//            adc_interface). Sample k of the schedule is the k-th tick after
//            reset (k = 0 at the first tick); burst b starts at k = b PERIOD_T
//            and carries code (b mod CODES) + 1. The drive of sample k is on
//            hb_p/hb_n from the clock after tick k until the clock after tick
//            k+1 (registered outputs, no glitches).
//            burst_valid is high in the clock of the tick that starts a
//            burst (combinational from the tick), with burst_code (1-based)
//            and burst_time = k: the live code index and sample counter, so
//            there is no registered copy of them (the consumer registers what
//            it keeps).
//
// Resources: counters only (no multiplier, no memory): the code bits are a
//            CODES*CHIPS constant read by a mux.
//
////////////////////////////////////////////////////////////////////////////////
`default_nettype none
// Widths of constant expressions (parameters are 32-bit integers) are checked by design.
/* verilator lint_off WIDTH */

module tx_scheduler #(
  parameter integer CODES    = 9,
  parameter integer CHIPS    = 7,
  parameter integer SPC      = 100,   // samples per chip = q fs / f
  parameter integer CYC      = 4,     // q, carrier cycles per chip
  parameter integer PERIOD_T = 1634,  // samples between burst starts (>= CHIPS*SPC)
  parameter integer CODE_W   = 4,     // holds 1..CODES
  parameter integer TIME_W   = 40,
  parameter [CODES*CHIPS-1:0] CODE_BITS = 0  // code j (0-based) chip m at bit j*CHIPS + m
) (
  input  wire clk, rst,
  input  wire tick,                    // one clock per full-rate sample
  input  wire enable,                  // 0: no new burst starts (a running one completes)
  output reg  hb_p, hb_n,              // H-bridge legs: +1 -> (1,0), -1 -> (0,1), idle (0,0)
  output reg  tx_active,
  output wire burst_valid,
  output wire [CODE_W-1:0] burst_code, // 1-based
  output wire [TIME_W-1:0] burst_time  // sample index of the burst's first sample
);
  localparam integer BURST = CHIPS * SPC;
  localparam integer PW = $clog2(PERIOD_T + 1);
  localparam integer SW = $clog2(SPC + 1);
  localparam integer HW = $clog2(2 * SPC + 1);
  localparam integer MW = $clog2(CHIPS + 1);

  // Parameter checks (elaboration fails on a bad configuration).
  generate
    if (PERIOD_T < BURST) begin : g_bad_period
      initial $error("tx_scheduler: PERIOD_T %0d shorter than a burst (%0d samples)", PERIOD_T, BURST);
    end
  endgenerate

  reg [TIME_W-1:0] n;          // sample index of the current tick
  reg [PW-1:0]     t;          // position in the period
  reg [CODE_W-1:0] code_idx;   // 0-based code of the current/next burst
  reg              in_burst;
  reg [MW-1:0]     chip;
  reg [SW-1:0]     s;          // sample within the chip
  reg [HW-1:0]     ph;         // 2 CYC s mod 2 SPC

  wire [CODES*CHIPS-1:0] code_bits = CODE_BITS;
  // Every decision a tick takes is registered in the clock before it: the state (code_idx,
  // chip, s, ph, t) changes only on a tick and ticks are at least 2 clocks apart (CLK_DIV >= 2,
  // adc_interface), so a register loaded from the state every clock is current at the next
  // tick. This keeps the chip lookup (a CODES*CHIPS-to-1 multiplexer), the phase compare and
  // step, and the counters' end tests off the tick's paths. In reset they take the values of
  // the reset state.
  reg chip_bit, first_positive;
  reg ph_low;                  // ph < SPC
  reg [HW-1:0] ph_next;        // (ph + 2 CYC) mod 2 SPC
  reg t_zero, t_last, s_last, chip_last, code_last;
  wire [HW:0] ph_step = {1'b0, ph} + 2 * CYC;
  always @(posedge clk) begin
    chip_bit <= code_bits[code_idx * CHIPS + chip];
    first_positive <= code_bits[code_idx * CHIPS];
    if (rst) begin
      ph_low <= 1'b1;
      ph_next <= 2 * CYC >= 2 * SPC ? (2 * CYC) % (2 * SPC) : 2 * CYC;
      t_zero <= 1'b1; t_last <= PERIOD_T == 1; s_last <= SPC == 1; chip_last <= CHIPS == 1;
      code_last <= CODES == 1;
    end else begin
      ph_low <= ph < SPC;
      ph_next <= ph_step >= 2 * SPC ? ph_step - 2 * SPC : ph_step[HW-1:0];
      t_zero <= t == 0;
      t_last <= t == PERIOD_T - 1;
      s_last <= s == SPC - 1;
      chip_last <= chip == CHIPS - 1;
      code_last <= code_idx == CODES - 1;
    end
  end
  // ph_mod = (ph + (c+1) SPC) mod 2 SPC, (c+1) SPC mod 2 SPC being 0 for a chip 1 and SPC for a
  // chip 0; ph_mod < SPC is then ph < SPC for a chip 1 and ph >= SPC for a chip 0.
  wire positive = chip_bit ? ph_low : ~ph_low;

  // First sample of a burst: chip 0 of the code about to start, phase 0: +1 for a chip 1
  // (first_positive, registered above).
  wire start_now = tick && t_zero && enable;
  assign burst_valid = start_now;
  assign burst_code = code_idx + 1'b1;
  assign burst_time = n;

  always @(posedge clk) begin
    if (rst) begin
      n <= 0; t <= 0; code_idx <= 0; in_burst <= 1'b0; chip <= 0; s <= 0; ph <= 0;
      hb_p <= 1'b0; hb_n <= 1'b0; tx_active <= 1'b0;
    end else if (tick) begin
      n <= n + 1'b1;
      t <= t_last ? {PW{1'b0}} : t + 1'b1;
      if (start_now || in_burst) begin
        // Sample of the burst at (chip, s): drive it, then advance.
        if (start_now) begin
          // first sample of a burst: chip 0, s 0, ph 0 (use the code of this burst)
          hb_p <= first_positive;
          hb_n <= ~first_positive;
        end else begin
          hb_p <= positive;
          hb_n <= ~positive;
        end
        tx_active <= 1'b1;
        if (start_now) begin
          in_burst <= 1'b1;
          chip <= 0;
          s <= 1;
          ph <= 2 * CYC >= 2 * SPC ? (2 * CYC) % (2 * SPC) : 2 * CYC;
        end else if (s_last) begin
          s <= 0;
          ph <= 0;
          if (chip_last) begin
            in_burst <= 1'b0;
            chip <= 0;
            code_idx <= code_last ? {CODE_W{1'b0}} : code_idx + 1'b1;
          end else begin
            chip <= chip + 1'b1;
          end
        end else begin
          s <= s + 1'b1;
          ph <= ph_next;
        end
      end else begin
        hb_p <= 1'b0;
        hb_n <= 1'b0;
        tx_active <= 1'b0;
      end
    end
  end

`ifdef FORMAL
  // Formal properties (formal/run_formal.sh tx_scheduler). Assumed: reset first, ticks at least
  // 2 clocks apart (adc_interface's strobe, CLK_DIV >= 2).
  reg f_past_valid = 1'b0;
  reg f_tick_q = 1'b0;
  always @(posedge clk) begin f_past_valid <= 1'b1; f_tick_q <= tick; end
  always @(*) if (!f_past_valid) assume(rst);
  always @(*) if (f_tick_q) assume(!tick);
  // Reset state: both H-bridge legs off, no burst, counters at 0.
  always @(posedge clk)
    if (f_past_valid && $past(rst))
      assert(!hb_p && !hb_n && !tx_active && !in_burst && n == 0 && t == 0 && code_idx == 0);
  // phase model: ph = 2 CYC s mod 2 SPC (hbridge_drive's phase without the chip offset)
  wire [HW+SW+8:0] f_ph = (2 * CYC * s) % (2 * SPC);
  always @(*)
    if (f_past_valid && !rst) begin
      assert(!(hb_p && hb_n));                     // never both legs on (shoot-through)
      assert(tx_active == (hb_p || hb_n));         // a leg is on exactly while transmitting
      if (burst_valid) assert(burst_code >= 1 && burst_code <= CODES);
      assert(code_idx < CODES && t < PERIOD_T && chip < CHIPS && s < SPC && ph < 2 * SPC);
      if (in_burst) assert(ph == f_ph);
      if (!in_burst) assert(chip == 0 && s == 0);
      // the registered decisions are current whenever a tick can come
      if (!f_tick_q) begin
        assert(t_zero == (t == 0) && t_last == (t == PERIOD_T - 1) && s_last == (s == SPC - 1));
        assert(chip_last == (chip == CHIPS - 1) && code_last == (code_idx == CODES - 1));
        assert(ph_low == (ph < SPC));
        assert(ph_next == (ph + 2 * CYC) % (2 * SPC));
      end
    end
`endif
endmodule

`default_nettype wire
