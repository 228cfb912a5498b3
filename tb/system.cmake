# The ranging system (issue 5, docs/bitstream.md): generated system top, closed-loop Verilator
# test of rtl/ranging_system.v, and the FPGA flow (target `bitstream`, ctest label "bitstream").

set(RANGING_TB_CLK_DIV_VALUE 24)  # clocks per sample in the closed-loop testbench

# Until `ranging generate` writes the system files itself, a small generator does.
add_executable(ranging_system_gen ${CMAKE_CURRENT_SOURCE_DIR}/gen_system.cpp)
target_link_libraries(ranging_system_gen PRIVATE ranging_model)
target_include_directories(ranging_system_gen PRIVATE ${PROJECT_SOURCE_DIR})
# The generated system files of the default configuration: in generated/default once
# `ranging generate` writes them, committed in generated/default-system/ until then
# (tests/test_hw_system.cpp regenerates them and fails on any difference).
set(RANGING_GEN_SYSTEM ${PROJECT_SOURCE_DIR}/generated/default-system)
if(EXISTS ${RANGING_GEN_DEFAULT}/rtl/ranging_system.vc)
  set(RANGING_GEN_SYSTEM ${RANGING_GEN_DEFAULT})
endif()
set(RANGING_SYSTEM_TB_VC ${CMAKE_CURRENT_BINARY_DIR}/ranging_system_tb.vc)
if(EXISTS ${RANGING_GEN_SYSTEM}/rtl/ranging_system.vc)
  # The testbench's clock divider: the receiver RTL as it is must keep up (tb_ranging_system.cpp).
  file(READ ${RANGING_GEN_SYSTEM}/rtl/ranging_system.vc RANGING_SYSTEM_VC_TEXT)
  string(REGEX REPLACE "-GCLK_DIV=[0-9]+" "-GCLK_DIV=${RANGING_TB_CLK_DIV_VALUE}" RANGING_SYSTEM_VC_TEXT
         "${RANGING_SYSTEM_VC_TEXT}")
  file(WRITE ${RANGING_SYSTEM_TB_VC} "${RANGING_SYSTEM_VC_TEXT}")
endif()

set(RANGING_SYSTEM_RTL
  ${PROJECT_SOURCE_DIR}/rtl/adc_interface.v ${PROJECT_SOURCE_DIR}/rtl/tx_scheduler.v
  ${PROJECT_SOURCE_DIR}/rtl/tof_distance.v ${PROJECT_SOURCE_DIR}/rtl/uart_tx.v
  ${PROJECT_SOURCE_DIR}/rtl/measurement_uart.v ${PROJECT_SOURCE_DIR}/rtl/ranging_system.v)
set(RANGING_RECEIVER_RTL
  ${PROJECT_SOURCE_DIR}/rtl/bandpass_sos.v ${PROJECT_SOURCE_DIR}/rtl/correlator_bank.v
  ${PROJECT_SOURCE_DIR}/rtl/peak_detector.v)

if(EXISTS ${PROJECT_SOURCE_DIR}/rtl/peak_detector.v AND EXISTS ${RANGING_SYSTEM_TB_VC})
  ranging_verilator_test(NAME tb_ranging_system TOP ranging_system
    RTL ${RANGING_SYSTEM_RTL} ${RANGING_RECEIVER_RTL} ${RANGING_GEN_DEFAULT}/rtl/receiver_top.v
    VC ${RANGING_SYSTEM_TB_VC}
    TB ${CMAKE_CURRENT_SOURCE_DIR}/tb_ranging_system.cpp)
  target_compile_definitions(tb_ranging_system PRIVATE RANGING_TB_CLK_DIV=${RANGING_TB_CLK_DIV_VALUE})
endif()
