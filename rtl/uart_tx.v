////////////////////////////////////////////////////////////////////////////////
//
// Filename:  rtl/uart_tx.v
//
// Project:   ranging -- coded ultrasonic ranging system
//
// Purpose:   UART transmitter, 8N1 (start bit 0, 8 data bits LSB first, one
//            stop bit 1), BAUD_DIV system clocks per bit (f_clk / baud, integer:
//            30 MHz / 1.5 Mbaud = 20 by default). Line idles high.
//
// Stream:    s_valid/s_ready byte input; s_ready is high when idle; a byte takes
//            10 BAUD_DIV clocks.
//
////////////////////////////////////////////////////////////////////////////////
`default_nettype none
// Widths of constant expressions (parameters are 32-bit integers) are checked by design.
/* verilator lint_off WIDTH */

module uart_tx #(
  parameter integer BAUD_DIV = 30
) (
  input  wire clk, rst,
  input  wire [7:0] s_data,
  input  wire s_valid,
  output wire s_ready,
  output reg  tx
);
  localparam integer CW = $clog2(BAUD_DIV + 1);
  reg [CW-1:0] count;
  reg [3:0]    bits;   // bits left to send, 0 = idle
  reg [8:0]    shift;  // {stop, data} after the start bit went out

  assign s_ready = bits == 0;

  always @(posedge clk) begin
    if (rst) begin
      tx <= 1'b1;
      bits <= 0;
      count <= 0;
      shift <= 9'h1ff;
    end else if (bits == 0) begin
      if (s_valid) begin
        tx <= 1'b0;  // start bit
        shift <= {1'b1, s_data};
        bits <= 4'd10;
        count <= BAUD_DIV - 1;
      end
    end else if (count != 0) begin
      count <= count - 1'b1;
    end else begin
      bits <= bits - 1'b1;
      count <= BAUD_DIV - 1;
      if (bits != 1) begin
        tx <= shift[0];
        shift <= {1'b1, shift[8:1]};
      end
    end
  end
`ifdef FORMAL
  // Formal properties (formal/run_formal.sh uart_tx). As the top (F_UART_TX defined) the stream
  // rules of the input are assumed; inside measurement_uart they are asserted of its driver.
`ifdef F_UART_TX
`define UT_ASSUME assume
`else
`define UT_ASSUME assert
`endif
  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
`ifdef F_UART_TX
  always @(*) if (!f_past_valid) assume(rst);
`endif
  // AXI-Stream input: valid stays up until ready, the byte stays stable while waiting.
  always @(posedge clk)
    if (f_past_valid && !$past(rst) && !rst && $past(s_valid && !s_ready)) begin
      `UT_ASSUME(s_valid);
      `UT_ASSUME(s_data == $past(s_data));
    end
  // Reset state: line high (idle), ready, counters cleared.
  always @(posedge clk)
    if (f_past_valid && $past(rst)) assert(tx && bits == 0 && count == 0 && s_ready);
  // Frame format: a shadow transmitter of the 8N1 frame, bit k (1 start, 2..9 data LSB first,
  // 10 stop) for BAUD_DIV clocks each; the line equals the shadow's bit in every clock.
  reg [3:0]    f_bit;   // 0 idle
  reg [CW-1:0] f_cnt;   // clocks of the current bit so far
  reg [7:0]    f_byte;
  always @(posedge clk)
    if (rst) begin
      f_bit <= 0; f_cnt <= 0;
    end else if (f_bit == 0) begin
      if (s_valid) begin f_bit <= 1; f_cnt <= 0; f_byte <= s_data; end
    end else if (f_cnt == BAUD_DIV - 1) begin
      f_cnt <= 0;
      f_bit <= (f_bit == 10) ? 4'd0 : f_bit + 1'b1;
    end else begin
      f_cnt <= f_cnt + 1'b1;
    end
  wire [17:0] f_rest = {9'h1ff, 1'b1, f_byte} >> (f_bit - 1);
  always @(*)
    if (f_past_valid && !rst) begin
      assert(s_ready == (f_bit == 0));
      if (f_bit == 0) assert(tx);                  // idle line high
      else if (f_bit == 1) assert(!tx);            // start bit
      else if (f_bit == 10) assert(tx);            // stop bit
      else assert(tx == f_byte[f_bit - 2]);        // data, LSB first
      // invariants linking the shadow to the state (they make the induction close)
      assert(f_bit <= 10);
      assert(bits == (f_bit == 0 ? 4'd0 : 4'd11 - f_bit));
      if (f_bit != 0) begin
        assert(f_cnt <= BAUD_DIV - 1);
        assert(count == BAUD_DIV - 1 - f_cnt);
        assert(shift == f_rest[8:0]);
      end
    end
`undef UT_ASSUME
`endif
endmodule

`default_nettype wire
