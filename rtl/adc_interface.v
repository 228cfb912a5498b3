////////////////////////////////////////////////////////////////////////////////
//
// Filename:  rtl/adc_interface.v
//
// Project:   ranging -- coded ultrasonic ranging system
//
// Purpose:   Clock and capture of a parallel ADC (for example a 12-bit 5 MS/s
//            pipeline ADC on two PMODs). The system clock is divided by
//            CLK_DIV (integer, >= 2): one ADC period = CLK_DIV clocks, the
//            ADC clock fs = f_clk / CLK_DIV.
//
//              phase 0 .. CLK_DIV/2-1   adc_clk high  (rising edge at phase 0:
//                                       the ADC samples)
//              phase CLK_DIV/2 .. end   adc_clk low
//              phase CLK_DIV-1          adc_data captured (the ADC's output has
//                                       settled for almost a whole period)
//
//            `tick` pulses at phase 0 of every period: it is the full-rate
//            sample strobe of the system (tx_scheduler). The word captured in
//            period k is the system's sample k (k = 0 in the first period after
//            reset); an ADC's pipeline latency (a fixed number of periods) is a
//            constant offset of the time of flight, which the calibration of a
//            known distance removes (docs/bitstream.md).
//
// Format:    ADC_OFFSET_BINARY = 1: straight binary (0 = -full scale), converted
//            to two's complement by inverting the MSB; 0: two's complement.
//            m_data is signed ADC_W bits.
//
// Stream:    AXI4-Stream master, one beat per period. m_valid stays up until the
//            beat is taken; if the next capture finds it still untaken the new
//            word replaces it and `overrun` (sticky until reset) is raised, and
//            overruns counts it (saturating): the receiver did not keep up with
//            fs and its time base no longer matches the transmitter's.
//
// Latency:   m_valid rises the clock after the capture (phase CLK_DIV-1).
//
////////////////////////////////////////////////////////////////////////////////
`default_nettype none
// Widths of constant expressions (parameters are 32-bit integers) are checked by design.
/* verilator lint_off WIDTH */

module adc_interface #(
  parameter integer CLK_DIV = 9,             // system clocks per ADC period, >= 2
  parameter integer ADC_W = 12,              // ADC word width
  parameter integer ADC_OFFSET_BINARY = 1,   // 1: straight binary from the ADC (MSB inverted); 0: two's complement
  parameter integer COUNT_W = 16             // width of the saturating overrun counter
) (
  input  wire clk, rst,
  output reg  adc_clk,
  input  wire [ADC_W-1:0] adc_data,
  output reg  tick,
  output reg  signed [ADC_W-1:0] m_data,
  output reg  m_valid,
  input  wire m_ready,
  output reg  overrun,
  output reg  [COUNT_W-1:0] overruns
);
  localparam integer DW = $clog2(CLK_DIV);
  localparam integer HIGH = CLK_DIV / 2;

  generate
    if (CLK_DIV < 2) begin : g_bad_div
      initial $error("adc_interface: CLK_DIV must be >= 2");
    end
  endgenerate

  reg [DW-1:0] phase;
  reg primed;             // 0 in the clock after reset: that "capture" only starts period 0
  reg [ADC_W-1:0] pin_q;  // input register (in the IO tile on the iCE40)

  wire [ADC_W-1:0] converted = ADC_OFFSET_BINARY != 0 ? {~pin_q[ADC_W-1], pin_q[ADC_W-2:0]} : pin_q;
  wire capture = phase == CLK_DIV - 1;

  always @(posedge clk) begin
    pin_q <= adc_data;
    if (rst) begin
      phase <= CLK_DIV - 1;
      primed <= 1'b0;
      adc_clk <= 1'b0;
      tick <= 1'b0;
      m_valid <= 1'b0;
      m_data <= 0;
      overrun <= 1'b0;
      overruns <= 0;
    end else begin
      phase <= capture ? {DW{1'b0}} : phase + 1'b1;
      // registered: adc_clk rises with phase 0 and falls with phase HIGH
      adc_clk <= capture || (phase < HIGH - 1);
      tick <= capture;
      if (m_valid && m_ready) m_valid <= 1'b0;
      // pin_q holds adc_data of the previous clock: sampling it at the last phase
      // reads the bus one clock before the next rising edge of adc_clk.
      if (capture) primed <= 1'b1;
      if (capture && primed) begin
        m_data <= converted;
        m_valid <= 1'b1;
        if (m_valid && !m_ready) begin
          overrun <= 1'b1;
          if (overruns != {COUNT_W{1'b1}}) overruns <= overruns + 1'b1;
        end
      end
    end
  end
`ifdef FORMAL
  // Formal properties (formal/run_formal.sh adc_interface). Assumed: reset first; m_ready free.
  reg f_past_valid = 1'b0;
  always @(posedge clk) f_past_valid <= 1'b1;
  always @(*) if (!f_past_valid) assume(rst);
  // Reset state.
  always @(posedge clk)
    if (f_past_valid && $past(rst))
      assert(!m_valid && !tick && !adc_clk && !overrun && overruns == 0 && phase == CLK_DIV - 1 && !primed);
  always @(posedge clk)
    if (f_past_valid && !$past(rst) && !rst) begin
      // AXI-Stream master: valid stays up until ready; the data changes while waiting only when
      // the next capture overruns it, and then the overrun is flagged and counted (saturating).
      if ($past(m_valid && !m_ready)) begin
        assert(m_valid);
        if (m_data != $past(m_data))
          assert(overrun && $past(capture && primed) &&
                 (overruns == $past(overruns) + 1'b1 || $past(overruns) == {COUNT_W{1'b1}}));
      end
      // a new beat only at a capture, and its word is the converted ADC bus
      if (m_valid && !$past(m_valid)) assert($past(capture && primed));
      if ($past(capture && primed))
        assert(m_data == (ADC_OFFSET_BINARY != 0 ? {~$past(pin_q[ADC_W-1]), $past(pin_q[ADC_W-2:0])} : $past(pin_q)));
      // the overrun flag is sticky, the counter never wraps
      if ($past(overrun)) assert(overrun);
      assert(overruns >= $past(overruns));
      // tick: one clock in CLK_DIV, in the clock after the capture phase
      assert(tick == $past(capture));
    end
  always @(*)
    if (f_past_valid && !rst) begin
      assert(phase <= CLK_DIV - 1);
      if (overruns != 0) assert(overrun);
    end
`endif
endmodule

`default_nettype wire
