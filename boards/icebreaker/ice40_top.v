////////////////////////////////////////////////////////////////////////////////
//
// Filename:  boards/icebreaker/ice40_top.v
//
// Project:   ranging -- coded ultrasonic ranging system
//
// Purpose:   iCEBreaker (iCE40UP5K-SG48) top: PLL from the 12 MHz oscillator to
//            the system clock (hardware.clock_hz), reset, and the generated
//            ranging_system_top (rtl/ranging_system.v) on the board's pins
//            (boards/icebreaker/icebreaker.pcf, docs/bitstream.md).
//
// Clock:     the PLL settings come from the generated rtl/ice40_pll.vh
//            (`ranging generate`, model/hw/hw_system.cpp: ice40_pll, the same search
//            as `icepll -i 12 -o <MHz>`); the default 30 MHz is DIVR 0, DIVF 79,
//            DIVQ 5, FILTER_RANGE 1: F_PFD 12 MHz, F_VCO 960 MHz, exact,
//            = 6 x 5 MS/s (CLK_DIV 6) = 20 x 1.5 Mbaud (BAUD_DIV 20).
//            SB_PLL40_PAD: the oscillator is on pin 35, a PLL input pad.
//
// Reset:     held while the PLL is not locked or BTN_N is pressed, then 16
//            clocks more, synchronous to the system clock.
//
// LEDs:      green (LEDG_N): a measurement was sent in the last 50 ms;
//            red (LEDR_N): ADC overrun (the receiver lost the sample rate).
//
////////////////////////////////////////////////////////////////////////////////
`default_nettype none

module ice40_top (
  input  wire CLK,          // 12 MHz
  input  wire BTN_N,        // reset button, active low
  output wire TX,           // UART to the FTDI (1.5 Mbaud 8N1)
  output wire LEDR_N, LEDG_N,
  // PMOD 1A + 1B: parallel ADC
  input  wire [11:0] ADC_D,
  output wire ADC_CLK,
  // PMOD 2: H-bridge
  output wire HB_P, HB_N, TX_EN
);
  wire clk, locked;

`include "ice40_pll.vh"

`ifdef SYNTHESIS
  SB_PLL40_PAD #(
    .FEEDBACK_PATH("SIMPLE"),
    .DIVR(`RANGING_PLL_DIVR),
    .DIVF(`RANGING_PLL_DIVF),
    .DIVQ(`RANGING_PLL_DIVQ),
    .FILTER_RANGE(`RANGING_PLL_FILTER_RANGE)
  ) u_pll (
    .LOCK(locked),
    .RESETB(1'b1),
    .BYPASS(1'b0),
    .PACKAGEPIN(CLK),
    .PLLOUTGLOBAL(clk)
  );
`else
  assign clk = CLK;  // simulation without the PLL model
  assign locked = 1'b1;
`endif

  reg [4:0] rst_count = 5'd0;
  reg rst = 1'b1;
  always @(posedge clk) begin
    if (!locked || !BTN_N) begin
      rst_count <= 5'd0;
      rst <= 1'b1;
    end else if (!rst_count[4]) begin
      rst_count <= rst_count + 1'b1;
      rst <= 1'b1;
    end else begin
      rst <= 1'b0;
    end
  end

  wire led_meas, led_error;
  /* verilator lint_off PINCONNECTEMPTY */
  ranging_system_top u_system (
    .clk(clk), .rst(rst),
    .adc_clk(ADC_CLK), .adc_data(ADC_D),
    .hb_p(HB_P), .hb_n(HB_N), .tx_active(TX_EN),
    .c_wr(1'b0), .c_value(32'd0),
    .uart_tx(TX), .led_meas(led_meas), .led_error(led_error),
    .sample_tick(), .meas_valid()
  );
  /* verilator lint_on PINCONNECTEMPTY */

  assign LEDG_N = ~led_meas;
  assign LEDR_N = ~led_error;
endmodule

`default_nettype wire
