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
endmodule

`default_nettype wire
