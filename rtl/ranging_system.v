////////////////////////////////////////////////////////////////////////////////
//
// Filename:  rtl/ranging_system.v
//
// Project:   ranging -- coded ultrasonic ranging system
//
// Purpose:   The whole ranging system around the generated receiver
//            (docs/bitstream.md):
//
//              adc_interface --s_axis--> receiver_top --events--> tof_distance
//                   | tick                                           ^   |
//                   v                                  burst (code,  |   v
//              tx_scheduler --> H-bridge (hb_p, hb_n)  start time) --+  measurement_uart --> uart_tx
//
//            One full-rate sample per CLK_DIV clocks (fs = f_clk / CLK_DIV);
//            the transmitter and the receiver share that sample count, so an
//            event's arrival (receiver sample index) and the bursts' start
//            times are on one time base. The configuration-dependent
//            parameters come from the generated rtl/ranging_system_top.v
//            (model/hw/hw_system.cpp).
//
// Status:    led_meas: stretched pulse (LED_HOLD clocks) per measurement sent;
//            led_error: sticky ADC overrun (the receiver did not keep up with
//            fs: the time base is lost until reset).
//
////////////////////////////////////////////////////////////////////////////////
`default_nettype none
/* verilator lint_off WIDTH */

module ranging_system #(
  // Every default is the default configuration's (generated/default/rtl/ranging_system.vc).
  parameter integer CLK_DIV = 6,              // system clocks per full-rate sample (fs = f_clk / CLK_DIV), >= 2
  parameter integer ADC_W = 12,               // ADC word and receiver input width, bits
  parameter integer ADC_OFFSET_BINARY = 1,    // 1: the ADC outputs straight binary; 0: two's complement
  parameter integer CODES = 9,                // codes of the family, sent 1..CODES in turn
  parameter integer CHIPS = 7,                // chips per code
  parameter integer SPC = 100,                // full-rate samples per chip (CYC carrier cycles)
  parameter integer CYC = 4,                  // carrier cycles per chip
  parameter integer PERIOD_T = 1634,          // samples from one burst's start to the next's
  parameter [CODES*CHIPS-1:0] CODE_BITS = 63'h6a42d8c44fa3ee53,  // chip m of code j at bit j*CHIPS + m, 1: +carrier
  parameter integer CODE_W = 4,               // bits of a code number (1..CODES)
  parameter integer TIME_W = 40,              // sample counters: wrap after 2^TIME_W samples
  parameter integer FRAC_W = 8,               // fraction bits of arrival and time of flight
  parameter integer SCORE_W = 16,             // detector score width (0..1 in SCORE_W-1 fraction bits)
  parameter integer OFF_W = 32,               // width of one code's latency offset
  parameter [CODES*OFF_W-1:0] OFFSETS = 288'h0003e8850003e7f90003e4610003e6f50003e6050003e8ad0003eb190003e7590003e691,  // receiver latency per code (tof_distance)
  parameter integer C_FRAC = 16,              // fraction bits of the speed of sound register
  parameter [31:0] C_INIT = 32'd4456448,      // speed of sound at reset, um per sample * 2^C_FRAC
  parameter integer BAUD_DIV = 20,            // system clocks per UART bit
  parameter integer LED_HOLD = 1500000,       // clocks the measurement LED stays on per frame
  // Sound-velocity compensation (rtl/sound_speed_cal.v): the calibration distance in um, 0: none
  // (the default and the committed bitstream: no logic, c_wr/c_value write C directly).
  parameter integer CAL_DIST_UM = 0
) (
  input  wire clk, rst,
  // ADC
  output wire adc_clk,
  input  wire [ADC_W-1:0] adc_data,
  // transmitter H-bridge
  output wire hb_p, hb_n,
  output wire tx_active,
  // measured speed of sound (compensation module): C format of tof_distance. With
  // CAL_DIST_UM > 0, c_wr with c_value == 0 (not a speed) is the calibration event instead:
  // the next measurement is the reference path at CAL_DIST_UM, and C becomes D / ToF.
  input  wire c_wr,
  input  wire [31:0] c_value,
  // UART and status
  output wire uart_tx,
  output reg  led_meas,
  output wire led_error,
  // observation (testbench)
  output wire sample_tick,
  output wire meas_valid
);
  localparam integer ARR_W = TIME_W + FRAC_W + 1;
  localparam integer EVENT_W = CODE_W + ARR_W + 2 * SCORE_W;

  wire tick;
  wire signed [ADC_W-1:0] sample;
  wire sample_valid, sample_ready;
  wire [15:0] overruns;

  adc_interface #(.CLK_DIV(CLK_DIV), .ADC_W(ADC_W), .ADC_OFFSET_BINARY(ADC_OFFSET_BINARY)) u_adc (
    .clk(clk), .rst(rst), .adc_clk(adc_clk), .adc_data(adc_data), .tick(tick),
    .m_data(sample), .m_valid(sample_valid), .m_ready(sample_ready),
    .overrun(led_error), .overruns(overruns)
  );

  wire burst_valid;
  wire [CODE_W-1:0] burst_code;
  wire [TIME_W-1:0] burst_time;
  tx_scheduler #(.CODES(CODES), .CHIPS(CHIPS), .SPC(SPC), .CYC(CYC), .PERIOD_T(PERIOD_T),
                 .CODE_W(CODE_W), .TIME_W(TIME_W), .CODE_BITS(CODE_BITS)) u_tx (
    .clk(clk), .rst(rst), .tick(tick), .enable(1'b1),
    .hb_p(hb_p), .hb_n(hb_n), .tx_active(tx_active),
    .burst_valid(burst_valid), .burst_code(burst_code), .burst_time(burst_time)
  );

  wire [EVENT_W-1:0] event_data;
  wire event_valid, event_ready;
  /* verilator lint_off PINCONNECTEMPTY */
  receiver_top u_receiver (
    .clk(clk), .rst(rst),
    .s_axis_tdata(sample), .s_axis_tvalid(sample_valid), .s_axis_tready(sample_ready),
    .m_axis_tdata(event_data), .m_axis_tvalid(event_valid), .m_axis_tready(event_ready),
    .dbg_filter_valid(), .dbg_filter_data(), .dbg_filter_sections(),
    .dbg_bank_valid(), .dbg_weighted(), .dbg_code(), .dbg_last(), .dbg_energy(), .dbg_index(),
    .dbg_chip_re(), .dbg_chip_im(), .dbg_corr_re(), .dbg_corr_im()
  );
  /* verilator lint_on PINCONNECTEMPTY */

  wire [CODE_W-1:0] ev_code = event_data[0 +: CODE_W];
  wire signed [ARR_W-1:0] ev_arrival = event_data[CODE_W +: ARR_W];
  wire [SCORE_W-1:0] ev_score = event_data[CODE_W + ARR_W +: SCORE_W];
  wire [SCORE_W-1:0] ev_margin = event_data[CODE_W + ARR_W + SCORE_W +: SCORE_W];

  wire m_valid, m_ready;
  wire [CODE_W-1:0] m_code;
  wire [1:0] m_flags;
  wire [31:0] m_tof, m_distance;
  wire [SCORE_W-1:0] m_score, m_margin;
  wire tof_c_wr;
  wire [31:0] tof_c_value;
  generate
    if (CAL_DIST_UM > 0) begin : g_cal
      wire cal_wr;
      wire [31:0] cal_value;
      /* verilator lint_off PINCONNECTEMPTY */
      sound_speed_cal #(.TOF_W(32), .C_W(32), .SH(FRAC_W + C_FRAC), .CAL_DIST_UM(CAL_DIST_UM)) u_cal (
        .clk(clk), .rst(rst), .arm(c_wr && c_value == 32'd0),
        .meas_valid(m_valid && m_ready), .meas_flags(m_flags), .meas_tof(m_tof),
        .c_wr(cal_wr), .c_value(cal_value), .armed(), .busy(), .sat_count()
      );
      /* verilator lint_on PINCONNECTEMPTY */
      assign tof_c_wr = cal_wr || (c_wr && c_value != 32'd0);
      assign tof_c_value = cal_wr ? cal_value : c_value;
    end else begin : g_no_cal
      assign tof_c_wr = c_wr;
      assign tof_c_value = c_value;
    end
  endgenerate
  /* verilator lint_off PINCONNECTEMPTY */
  tof_distance #(.CODES(CODES), .CODE_W(CODE_W), .TIME_W(TIME_W), .FRAC_W(FRAC_W),
                 .PERIOD_T(PERIOD_T), .SCORE_W(SCORE_W), .OFF_W(OFF_W), .OFFSETS(OFFSETS),
                 .C_W(32), .C_FRAC(C_FRAC), .C_INIT(C_INIT), .TOF_W(32), .DIST_W(32)) u_tof (
    .clk(clk), .rst(rst),
    .burst_valid(burst_valid), .burst_code(burst_code), .burst_time(burst_time),
    .c_wr(tof_c_wr), .c_value(tof_c_value), .c_current(),
    .s_valid(event_valid), .s_ready(event_ready),
    .s_code(ev_code), .s_arrival(ev_arrival), .s_score(ev_score), .s_margin(ev_margin),
    .m_valid(m_valid), .m_ready(m_ready), .m_code(m_code), .m_flags(m_flags),
    .m_tof(m_tof), .m_distance(m_distance), .m_score(m_score), .m_margin(m_margin)
  );
  /* verilator lint_on PINCONNECTEMPTY */

  // 16-bit fields of the frame: a narrower score is zero-extended, a wider one keeps its top bits.
  wire [15:0] f_score, f_margin;
  generate
    if (SCORE_W >= 16) begin : g_score_wide
      assign f_score = m_score[SCORE_W-1 -: 16];
      assign f_margin = m_margin[SCORE_W-1 -: 16];
    end else begin : g_score_narrow
      assign f_score = {{(16-SCORE_W){1'b0}}, m_score};
      assign f_margin = {{(16-SCORE_W){1'b0}}, m_margin};
    end
  endgenerate

  // The frame's overrun flag: led_error (sticky, it may rise at any sample) taken while no
  // measurement waits, so a measurement's fields stay stable until the UART has sent it
  // (AXI-Stream; found by the system proof, formal/ranging_system.job).
  reg frame_error;
  always @(posedge clk)
    if (rst) frame_error <= 1'b0;
    else if (!m_valid || m_ready) frame_error <= led_error;

  measurement_uart #(.BAUD_DIV(BAUD_DIV)) u_uart (
    .clk(clk), .rst(rst),
    .s_valid(m_valid), .s_ready(m_ready),
    .s_code({{(8-CODE_W){1'b0}}, m_code}),
    .s_flags({5'd0, frame_error, m_flags}),
    .s_tof(m_tof), .s_distance(m_distance), .s_score(f_score), .s_margin(f_margin),
    .tx(uart_tx)
  );

  assign sample_tick = tick;
  assign meas_valid = m_valid & m_ready;

  // Measurement LED: LED_HOLD clocks per measurement. An up-counter cleared by the event
  // (one set/reset net for every bit) keeps its carry chain in one piece in the iCE40
  // tiles; loading the constant LED_HOLD mixed set and reset nets and split the chain.
  localparam integer LW = $clog2(LED_HOLD + 1);
  localparam [LW-1:0] LED_LAST = LED_HOLD - 1;
  reg [LW-1:0] led_count;
  always @(posedge clk) begin
    if (rst || (m_valid && m_ready)) led_count <= 0;
    else if (led_meas) led_count <= led_count + 1'b1;
    if (rst) led_meas <= 1'b0;
    else if (m_valid && m_ready) led_meas <= 1'b1;
    else if (led_count == LED_LAST) led_meas <= 1'b0;
  end

  wire unused = &{1'b0, overruns};

`ifdef FORMAL
  // System proof (formal/run_formal.sh ranging_system; formal/receiver_env.v stands in for the
  // receiver): the submodules' input rules are asserted of the modules that drive them (the job's
  // assert_inputs): the ADC's tick against tx_scheduler's spacing, the events against
  // tof_distance, the measurements against measurement_uart and its bytes against uart_tx. Here:
  // reset first, and the system's outputs after reset.
  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume(rst);
  always @(posedge clk)
    if (f_past_valid && $past(rst))
      assert(!hb_p && !hb_n && !tx_active && uart_tx && !led_meas && !led_error && !meas_valid);
  // the H-bridge never drives both legs, and drives only in a burst
  always @(*)
    if (f_past_valid && !rst) begin
      assert(!(hb_p && hb_n));
      if (hb_p || hb_n) assert(tx_active);
    end
`endif
endmodule

`default_nettype wire
