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
// Stream:    s_valid/s_ready: one measurement per frame. Nothing is latched: the
//            bytes are selected from the s_* inputs, which AXI4-Stream keeps stable
//            while s_valid && !s_ready, and s_ready completes the handshake when
//            the frame's last byte is handed to the transmitter (a 17:1 byte
//            multiplexer instead of a 136-bit frame register). The checksum is a
//            running XOR of the bytes as they are sent.
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
  reg       busy;
  reg [4:0] idx;  // byte being sent, 0..BYTES-1
  wire byte_ready;

  wire [8*14-1:0] payload = {s_margin, s_score, s_distance, s_tof, s_flags, s_code};
  // checksum: XOR of bytes 2..15 accumulated as they are handed to the transmitter (one 8-bit
  // register instead of a 14-input XOR tree per bit)
  reg [7:0] x;
  wire [8*BYTES-1:0] frame = {8'h00, payload, 8'h5A, 8'hA5};
  wire last_byte = idx == BYTES - 1;
  wire [7:0] byte_now = last_byte ? x : frame[8*idx +: 8];

  assign s_ready = busy && last_byte && byte_ready;

  always @(posedge clk) begin
    if (rst) begin
      busy <= 1'b0;
      idx <= 0;
    end else if (!busy) begin
      busy <= s_valid;
      idx <= 0;
    end else if (byte_ready) begin
      if (last_byte) busy <= 1'b0;
      idx <= idx + 1'b1;
    end
    if (!busy) x <= 8'h00;
    else if (byte_ready && idx >= 2) x <= x ^ byte_now;  // byte 16 (x itself) is never added
  end

  uart_tx #(.BAUD_DIV(BAUD_DIV)) u_tx (
    .clk(clk), .rst(rst),
    .s_data(byte_now), .s_valid(busy), .s_ready(byte_ready),
    .tx(tx)
  );
`ifdef FORMAL
  // Formal properties (formal/run_formal.sh measurement_uart): the measurement input's stream
  // rules are assumed, the transmitter's (uart_tx) asserted of the byte multiplexer here.
  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume(rst);
  always @(posedge clk)
    if (f_past_valid && !$past(rst) && !rst && $past(s_valid && !s_ready)) begin
      assume(s_valid);
      assume({s_code, s_flags, s_tof, s_distance, s_score, s_margin} ==
             $past({s_code, s_flags, s_tof, s_distance, s_score, s_margin}));
    end
  // Reset state: idle, not ready, line high.
  always @(posedge clk)
    if (f_past_valid && $past(rst)) assert(!busy && idx == 0 && !s_ready && tx);
  // Frame format: the bytes handed to the transmitter are, in order, the 17 bytes of the frame
  // (sync, fields little-endian, XOR of bytes 2..15), and the measurement is acknowledged with
  // the last one. f_bytes is written from the field list, not from the multiplexer.
  wire [8*BYTES-1:0] f_bytes;     // byte k at [8k +: 8]
  wire [8*BYTES-1:0] f_prefix;    // XOR of bytes 2..k-1 at [8k +: 8]
  assign f_bytes[0 +: 8] = 8'hA5;
  assign f_bytes[8 +: 8] = 8'h5A;
  assign f_bytes[16 +: 8] = s_code;
  assign f_bytes[24 +: 8] = s_flags;
  genvar f_i;
  generate
    for (f_i = 0; f_i < 4; f_i = f_i + 1) begin : g_f_le
      assign f_bytes[8 * (4 + f_i) +: 8] = s_tof[8 * f_i +: 8];
      assign f_bytes[8 * (8 + f_i) +: 8] = s_distance[8 * f_i +: 8];
    end
    for (f_i = 0; f_i < 2; f_i = f_i + 1) begin : g_f_le16
      assign f_bytes[8 * (12 + f_i) +: 8] = s_score[8 * f_i +: 8];
      assign f_bytes[8 * (14 + f_i) +: 8] = s_margin[8 * f_i +: 8];
    end
    assign f_prefix[0 +: 24] = 24'h0;
    for (f_i = 3; f_i < BYTES; f_i = f_i + 1) begin : g_f_x
      assign f_prefix[8 * f_i +: 8] = f_prefix[8 * (f_i - 1) +: 8] ^ f_bytes[8 * (f_i - 1) +: 8];
    end
  endgenerate
  assign f_bytes[8 * 16 +: 8] = f_prefix[8 * 16 +: 8];  // checksum: XOR of bytes 2..15
  always @(*)
    if (f_past_valid && !rst) begin
      if (busy) begin
        assert(idx <= BYTES - 1);
        assert(s_valid);                                  // a frame is only sent for a measurement
        assert(x == f_prefix[8 * idx +: 8]);              // the running checksum (induction)
        assert(byte_now == f_bytes[8 * idx +: 8]);
      end else begin
        assert(x == 8'h00 || idx == 0);
      end
      assert(s_ready == (busy && idx == BYTES - 1 && byte_ready));
    end
`endif
endmodule

`default_nettype wire
