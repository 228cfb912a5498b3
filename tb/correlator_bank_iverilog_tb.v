// Icarus testbench of rtl/correlator_bank.v: feeds $readmemh input samples (+vin=FILE) and
// compares every beat of every decimated output with the model's ($readmemh +vout=FILE, one
// word per beat: {corr_im, corr_re, chip_im, chip_re, index, energy, last, code, weighted}),
// with a periodic m_ready stall; checks that s_ready and m_valid are never X after reset and
// that no m_* field is X on a valid beat (the beat words come from a synchronous-read memory
// that is not reset, so they are undefined while m_valid is low, as AXI-Stream allows).
// Instantiated by a wrapper generated from the .vc parameters (tb/tb_correlator_bank.cpp).
// Prints "RESULT outputs=N mismatches=M xs=X" (N counts beats).
`timescale 1ns/1ps
module correlator_bank_iverilog_tb #(
  parameter integer N_IN = 1, N_OUT = 1,
  parameter integer DATA_W = 16, DATA_FRAC = 14,
  parameter integer PERIOD = 25,
  parameter integer LO_W = 16,
  parameter integer MIX_W = 18, MIX_FRAC = 16, MIX_SHIFT = 13,
  parameter integer DECIM = 20,
  parameter integer DEC_W = 23,
  parameter integer TAPS = 20, TAP_W = 16,
  parameter integer FIR_W = 42,
  parameter integer CHIP_W = 20, CHIP_SHIFT = 20,
  parameter integer CHIPS = 7, CODES = 9,
  parameter integer CHIP_STEP = 5,
  parameter integer COMB_W = 23, CORR_W = 16, CORR_SHIFT = 7,
  parameter integer POWER_W = 32, WEIGHT_W = 16, WEIGHTED_W = 48,
  parameter integer WINDOW = 1000,
  parameter integer ENERGY_W = 41,
  parameter integer TIME_W = 40,
  parameter integer CODE_W = 4,
  parameter [PERIOD*LO_W-1:0]     LO_COS = 400'h7bfa702a5d4e4495278e0809e804c980ae6a987388fe8103810388fe9873ae6ac980e8040809278e44955d4e702a7bfa7fff,
  parameter [PERIOD*LO_W-1:0]     LO_SIN = 400'he02bc256a86193ee8645804282458c309d61b4c4d0e2eff5100b2f1e4b3c629f73d07dbb7fbe79bb6c12579f3daa1fd50000,
  parameter [TAPS*TAP_W-1:0]      TAP_VALUES = 320'h0000003c030e0aca22003b1a58e6748c7ffe7fff755f655052d446bc37782d8c23d61b4716330f48,
  parameter [CODES*CHIPS-1:0]     CODE_BITS = 63'h6a42d8c44fa3ee53,
  parameter [CODES*WEIGHT_W-1:0]  WEIGHTS = 144'hd6be5bc4b762504964e54068378365789e12
) ();
  localparam integer OUT_BITS = WEIGHTED_W + CODE_W + 1 + ENERGY_W + TIME_W + 2*CHIP_W + 2*CORR_W;
  reg clk = 1'b0, rst = 1'b1;
  reg [DATA_W-1:0] s_data = 0;
  reg s_valid = 1'b0, m_ready = 1'b0;
  wire s_ready, m_valid;
  wire [WEIGHTED_W-1:0] m_weighted;
  wire [CODE_W-1:0] m_code;
  wire m_last;
  wire [ENERGY_W-1:0] m_energy;
  wire [TIME_W-1:0] m_index;
  wire signed [CHIP_W-1:0] m_chip_re, m_chip_im;
  wire signed [CORR_W-1:0] m_corr_re, m_corr_im;
  correlator_bank #(
    .DATA_W(DATA_W),
    .DATA_FRAC(DATA_FRAC),
    .PERIOD(PERIOD),
    .LO_W(LO_W),
    .MIX_W(MIX_W),
    .MIX_FRAC(MIX_FRAC),
    .MIX_SHIFT(MIX_SHIFT),
    .DECIM(DECIM),
    .DEC_W(DEC_W),
    .TAPS(TAPS),
    .TAP_W(TAP_W),
    .FIR_W(FIR_W),
    .CHIP_W(CHIP_W),
    .CHIP_SHIFT(CHIP_SHIFT),
    .CHIPS(CHIPS),
    .CODES(CODES),
    .CHIP_STEP(CHIP_STEP),
    .COMB_W(COMB_W),
    .CORR_W(CORR_W),
    .CORR_SHIFT(CORR_SHIFT),
    .POWER_W(POWER_W),
    .WEIGHT_W(WEIGHT_W),
    .WEIGHTED_W(WEIGHTED_W),
    .WINDOW(WINDOW),
    .ENERGY_W(ENERGY_W),
    .TIME_W(TIME_W),
    .CODE_W(CODE_W),
    .LO_COS(LO_COS),
    .LO_SIN(LO_SIN),
    .TAP_VALUES(TAP_VALUES),
    .CODE_BITS(CODE_BITS),
    .WEIGHTS(WEIGHTS)
  ) dut (
    .clk(clk), .rst(rst), .s_data(s_data), .s_valid(s_valid), .s_ready(s_ready),
    .m_valid(m_valid), .m_ready(m_ready), .m_weighted(m_weighted), .m_code(m_code),
    .m_last(m_last), .m_energy(m_energy),
    .m_index(m_index), .m_chip_re(m_chip_re), .m_chip_im(m_chip_im),
    .m_corr_re(m_corr_re), .m_corr_im(m_corr_im));

  reg [DATA_W-1:0] vin [0:N_IN-1];
  reg [OUT_BITS-1:0] vout [0:N_OUT-1];
  reg [1023:0] fin, fout;
  integer in_i = 0, out_i = 0, mism = 0, xs = 0, cyc = 0;
  wire [OUT_BITS-1:0] got = {m_corr_im, m_corr_re, m_chip_im, m_chip_re, m_index, m_energy, m_last,
                             m_code, m_weighted};

  always #5 clk = ~clk;

  initial begin
    if (!$value$plusargs("vin=%s", fin) || !$value$plusargs("vout=%s", fout)) begin
      $display("RESULT outputs=0 mismatches=1 xs=0 (missing +vin/+vout)");
      $finish;
    end
    $readmemh(fin, vin);
    $readmemh(fout, vout);
    repeat (3) @(posedge clk);
    #1 rst = 1'b0;
  end

  always @(posedge clk) if (!rst) begin
    cyc <= cyc + 1;
    if ((^{s_ready, m_valid}) === 1'bx || (m_valid && (^got) === 1'bx)) xs = xs + 1;
    if (s_valid && s_ready) in_i = in_i + 1;
    if (m_valid && m_ready) begin
      if (got !== vout[out_i]) begin
        if (mism < 5) $display("mismatch at beat %0d: got %h expected %h", out_i, got, vout[out_i]);
        mism = mism + 1;
      end
      out_i = out_i + 1;
    end
    if (out_i == N_OUT || cyc > 400 * N_IN + 1000) begin
      $display("RESULT outputs=%0d mismatches=%0d xs=%0d", out_i, mism + (N_OUT - out_i), xs);
      $finish;
    end
    // drive the next cycle's inputs (after the edge)
    s_valid <= (in_i < N_IN);
    s_data <= (in_i < N_IN) ? vin[in_i] : {DATA_W{1'b0}};
    m_ready <= (cyc % 7) != 3;
  end
endmodule
