# The whole generated receiver against the golden model, stage by stage.
ranging_verilator_test(NAME tb_receiver_top TOP receiver_top
  RTL ${RANGING_GEN_DEFAULT}/rtl/receiver_top.v
      ${RANGING_RECEIVER_RTL}
  TB ${CMAKE_CURRENT_SOURCE_DIR}/tb_receiver_top.cpp)
