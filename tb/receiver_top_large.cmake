# The large configuration (configs/large.yaml: full rate, 524-tap received template) through the
# same stage-by-stage testbench as the default.
ranging_verilator_test(NAME tb_receiver_top_large TOP receiver_top COST 1000
  RTL ${PROJECT_SOURCE_DIR}/generated/large/rtl/receiver_top.v
      ${RANGING_RECEIVER_RTL}
  TB ${CMAKE_CURRENT_SOURCE_DIR}/tb_receiver_top.cpp)
target_compile_definitions(tb_receiver_top_large PRIVATE RANGING_TB_LARGE=1)
# ranging_verilator_test defines RANGING_CONFIG as the default; the large one wins (last -D).
target_compile_options(tb_receiver_top_large PRIVATE -URANGING_CONFIG
  "-DRANGING_CONFIG=\"${PROJECT_SOURCE_DIR}/configs/large.yaml\"")
