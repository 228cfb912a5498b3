# The ranging system RTL in closed loops (tb/tb_system_loop.cpp, issues 15 §5, 14 §6, 16 §6):
# a rotor blade crossing through the moving-transducer channel, the sound-velocity compensation
# (rtl/sound_speed_cal.v, enabled here by -GCAL_DIST_UM: the default system has none), and
# `ranging frames` on the RTL's UART bytes. Label hardware, about 20 s together.
if(EXISTS ${RANGING_SYSTEM_TB_VC})
  # CAL_DIST_UM: the system's calibration distance (SystemOptions, 0.1 m), checked by the test.
  set(RANGING_TB_CAL_DIST_UM 100000)
  set(RANGING_SYSTEM_LOOP_VC ${CMAKE_CURRENT_BINARY_DIR}/ranging_system_loop_tb.vc)
  file(WRITE ${RANGING_SYSTEM_LOOP_VC} "${RANGING_SYSTEM_VC_TEXT}-GCAL_DIST_UM=32'd${RANGING_TB_CAL_DIST_UM}\n")
  ranging_verilator_test(NAME tb_system_loop TOP ranging_system
    RTL ${RANGING_SYSTEM_RTL} ${PROJECT_SOURCE_DIR}/rtl/sound_speed_cal.v ${RANGING_RECEIVER_RTL}
        ${RANGING_GEN_DEFAULT}/rtl/receiver_top.v
    VC ${RANGING_SYSTEM_LOOP_VC}
    TB ${CMAKE_CURRENT_SOURCE_DIR}/tb_system_loop.cpp)
  target_compile_definitions(tb_system_loop PRIVATE RANGING_TB_CAL_DIST_UM=${RANGING_TB_CAL_DIST_UM}
                             RANGING_TOOL="$<TARGET_FILE:ranging>")
  add_dependencies(tb_system_loop ranging)
endif()
