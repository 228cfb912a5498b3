////////////////////////////////////////////////////////////////////////////////
//
// Filename:  rtl/measurement_uart.v
//
// Project:   ranging -- coded ultrasonic ranging system
//
// Purpose:   Streams one measurement per frame over the UART (docs/bitstream.md):
//
//              byte  0     0xA5                sync
//              byte  1     0x5A                sync
//              byte  2     code                1-based code j
//              byte  3     flags               bit 0: no burst of this code was sent
//                                              before the arrival (ToF, distance 0)
//                                              bit 1: distance saturated
//                                              bit 2: ADC overrun since reset
//              bytes 4-7   ToF                 unsigned 32, full-rate samples, 8 fraction bits
//              bytes 8-11  distance            unsigned 32, micrometres
//              bytes 12-13 score               rho^2, unsigned 16-bit fraction
//              bytes 14-15 margin              rho^2 best - second, same format
//              byte  16    checksum            XOR of bytes 2..15
//
//            Multi-byte fields little-endian. 17 bytes = 170 bit times
//            (113 us at 1.5 Mbaud), shorter than a burst period, so one frame
//            per measurement never backs up.
//
// Stream:    s_valid/s_ready: one measurement per frame; s_ready is high only
//            between frames (the measurement is latched at the handshake).
//
////////////////////////////////////////////////////////////////////////////////
`default_nettype none
// Widths of constant expressions (parameters are 32-bit integers) are checked by design.
/* verilator lint_off WIDTH */

module measurement_uart #(
  parameter integer BAUD_DIV = 30
) (
  input  wire clk, rst,
  input  wire s_valid,
  output wire s_ready,
  input  wire [7:0]  s_code,
  input  wire [7:0]  s_flags,
  input  wire [31:0] s_tof,
  input  wire [31:0] s_distance,
  input  wire [15:0] s_score,
  input  wire [15:0] s_margin,
  output wire tx
);
  localparam integer BYTES = 17;
  reg [8*BYTES-1:0] frame;
  reg [4:0] left;  // bytes left, 0 = idle
  wire byte_ready;

  wire [8*14-1:0] payload = {s_margin, s_score, s_distance, s_tof, s_flags, s_code};
  reg [7:0] x;
  integer i;
  always @(*) begin
    x = 8'h00;
    for (i = 0; i < 14; i = i + 1) x = x ^ payload[8*i +: 8];
  end

  assign s_ready = left == 0;

  always @(posedge clk) begin
    if (rst) begin
      left <= 0;
      frame <= 0;
    end else if (left == 0) begin
      if (s_valid) begin
        frame <= {x, payload, 8'h5A, 8'hA5};
        left <= BYTES[4:0];
      end
    end else if (byte_ready) begin
      frame <= {8'h00, frame[8*BYTES-1:8]};
      left <= left - 1'b1;
    end
  end

  uart_tx #(.BAUD_DIV(BAUD_DIV)) u_tx (
    .clk(clk), .rst(rst),
    .s_data(frame[7:0]), .s_valid(left != 0), .s_ready(byte_ready),
    .tx(tx)
  );
endmodule

`default_nettype wire
