# The ranging system (issue 5, docs/bitstream.md): generated system top, closed-loop Verilator
# test of rtl/ranging_system.v, and the FPGA flow (target `bitstream`, ctest label "bitstream").

# The generated system files of the default configuration are in generated/default (committed).
set(RANGING_GEN_SYSTEM ${RANGING_GEN_DEFAULT})
set(RANGING_SYSTEM_TB_VC ${CMAKE_CURRENT_BINARY_DIR}/ranging_system_tb.vc)
if(EXISTS ${RANGING_GEN_SYSTEM}/rtl/ranging_system.vc)
  # The closed loop runs at the configuration's own clock divider (hardware.clock_hz / fs):
  # the receiver RTL must keep up with the ADC at the real rate (tb_ranging_system.cpp).
  file(READ ${RANGING_GEN_SYSTEM}/rtl/ranging_system.vc RANGING_SYSTEM_VC_TEXT)
  string(REGEX MATCH "-GCLK_DIV=(32'd)?([0-9]+)" _clk_div_match "${RANGING_SYSTEM_VC_TEXT}")
  set(RANGING_TB_CLK_DIV_VALUE ${CMAKE_MATCH_2})
  file(WRITE ${RANGING_SYSTEM_TB_VC} "${RANGING_SYSTEM_VC_TEXT}")
  # Regenerated parameters (ranging generate) must reach the testbench's copy.
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${RANGING_GEN_SYSTEM}/rtl/ranging_system.vc)
endif()

set(RANGING_SYSTEM_RTL
  ${PROJECT_SOURCE_DIR}/rtl/adc_interface.v ${PROJECT_SOURCE_DIR}/rtl/tx_scheduler.v
  ${PROJECT_SOURCE_DIR}/rtl/tof_distance.v ${PROJECT_SOURCE_DIR}/rtl/uart_tx.v
  ${PROJECT_SOURCE_DIR}/rtl/measurement_uart.v ${PROJECT_SOURCE_DIR}/rtl/ranging_system.v)

if(EXISTS ${PROJECT_SOURCE_DIR}/rtl/peak_detector.v AND EXISTS ${RANGING_SYSTEM_TB_VC})
  ranging_verilator_test(NAME tb_ranging_system TOP ranging_system
    RTL ${RANGING_SYSTEM_RTL} ${RANGING_RECEIVER_RTL} ${RANGING_GEN_DEFAULT}/rtl/receiver_top.v
    VC ${RANGING_SYSTEM_TB_VC}
    TB ${CMAKE_CURRENT_SOURCE_DIR}/tb_ranging_system.cpp)
  target_compile_definitions(tb_ranging_system PRIVATE RANGING_TB_CLK_DIV=${RANGING_TB_CLK_DIV_VALUE})
endif()

# Post-synthesis equivalence: the synthesized receiver netlist against the golden model
# (gate-level simulation with Verilator and yosys' ice40 cells_sim.v).
find_program(RANGING_YOSYS_BIN yosys)
find_program(RANGING_PS_VERILATOR verilator)
if(RANGING_YOSYS_BIN AND RANGING_PS_VERILATOR AND EXISTS ${PROJECT_SOURCE_DIR}/rtl/peak_detector.v)
  get_filename_component(RANGING_YOSYS_PREFIX ${RANGING_YOSYS_BIN} DIRECTORY)
  find_path(RANGING_YOSYS_DATDIR ice40/cells_sim.v HINTS ${RANGING_YOSYS_PREFIX}/../share/yosys
            /usr/share/yosys /usr/local/share/yosys REQUIRED)
  ranging_tb_executable(tb_postsynth ${CMAKE_CURRENT_SOURCE_DIR}/tb_postsynth.cpp)
  target_compile_definitions(tb_postsynth PRIVATE
    RANGING_YOSYS_BIN="${RANGING_YOSYS_BIN}"
    RANGING_YOSYS_DATDIR="${RANGING_YOSYS_DATDIR}"
    RANGING_VERILATOR_BIN="${RANGING_PS_VERILATOR}"
    RANGING_POSTSYNTH_WORK_DIR="${CMAKE_CURRENT_BINARY_DIR}/postsynth")
  add_test(NAME postsynth_equivalence COMMAND tb_postsynth)
  set_tests_properties(postsynth_equivalence PROPERTIES LABELS "postsynth" TIMEOUT 3600)
endif()

# The bitstream of the default configuration: `cmake --build BUILD --target bitstream` writes
# docs/results/bitstream.{json,md}; the ctest entry (label "bitstream") builds it into the
# build tree and fails unless the targets of docs/bitstream.md are met.
add_custom_target(bitstream
  COMMAND ${PROJECT_SOURCE_DIR}/scripts/build_bitstream.sh --build-dir ${CMAKE_BINARY_DIR} --breakdown --seeds 5
          --results ${PROJECT_SOURCE_DIR}/docs/results
  DEPENDS ranging
  WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
  USES_TERMINAL)
# The test checks the targets only: no per-module breakdown and no ECP5 / Xilinx estimates (report
# features of the `bitstream` target above, several minutes of yosys that --check never reads).
add_test(NAME bitstream_targets
  COMMAND ${PROJECT_SOURCE_DIR}/scripts/build_bitstream.sh --build-dir ${CMAKE_BINARY_DIR} --no-others --seeds 5
          --out ${CMAKE_BINARY_DIR}/bitstream-test --results ${CMAKE_BINARY_DIR}/bitstream-test/results --check
          --min-seeds 4)  # issue 18: 1.1x the clock on at least 4 of seeds 1-5
# COST: the longest test (~11 min on one core) starts first, so that `ctest -j` runs the rest
# beside it instead of after it (a fresh clone has no CTestCostData to order by).
set_tests_properties(bitstream_targets PROPERTIES LABELS "bitstream" TIMEOUT 7200 COST 100000)
