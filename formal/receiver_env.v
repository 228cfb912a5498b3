// formal/receiver_env.v -- the receiver as the system proof's environment (formal only).
//
// formal/ranging_system.job proves ranging_system with this module in place of the generated
// receiver_top: the receiver's own properties are proven module by module (bandpass_sos,
// correlator_bank, peak_detector jobs), so here it is what those proofs guarantee at its
// ports and nothing more: an event stream that follows the AXI-Stream rules (no event in the
// clock after reset, valid held until ready, data stable while waiting) with any event word,
// and any s_axis_tready. Its constraints are assumptions; every other module's assumptions
// become assertions of the composition (the job's `assert_inputs`).
//
// Widths: EVENT_W = CODE_W + TIME_W + FRAC_W + 1 + 2 SCORE_W of the job (2 + 6 + 2 + 1 + 4 =
// 15), ADC_W the job's. The debug ports are left unconnected by ranging_system.
`default_nettype none
module receiver_top #(
  parameter integer ADC_W = 4,       // sample width (ranging_system's ADC_W)
  parameter integer EVENT_W = 15     // event word width (ranging_system's EVENT_W)
) (
  input  wire               clk, rst,
  input  wire [ADC_W-1:0]   s_axis_tdata,
  input  wire               s_axis_tvalid,
  output wire               s_axis_tready,
  output reg  [EVENT_W-1:0] m_axis_tdata,
  output reg                m_axis_tvalid,
  input  wire               m_axis_tready,
  output wire dbg_filter_valid, dbg_filter_data, dbg_filter_sections, dbg_bank_valid,
  output wire dbg_weighted, dbg_code, dbg_last, dbg_energy, dbg_index, dbg_chip_re,
  output wire dbg_chip_im, dbg_corr_re, dbg_corr_im
);
  (* anyseq *) wire               f_ready;
  (* anyseq *) wire               f_valid;
  (* anyseq *) wire [EVENT_W-1:0] f_data;
  assign s_axis_tready = f_ready;
  // an event is offered when the stream is free, and held (word and valid) until taken
  always @(posedge clk)
    if (rst) m_axis_tvalid <= 1'b0;
    else if (!m_axis_tvalid || m_axis_tready) begin
      m_axis_tvalid <= f_valid;
      m_axis_tdata <= f_data;
    end
  assign {dbg_filter_valid, dbg_filter_data, dbg_filter_sections, dbg_bank_valid, dbg_weighted,
          dbg_code, dbg_last, dbg_energy, dbg_index, dbg_chip_re, dbg_chip_im, dbg_corr_re,
          dbg_corr_im} = 13'd0;
  wire unused = &{1'b0, s_axis_tdata, s_axis_tvalid};
endmodule
`default_nettype wire
