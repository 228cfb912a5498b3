# Verilator test of rtl/tof_distance.v against TofDistanceModel on directed and random events,
# including the corners the closed loop never reaches (no burst yet, a code's burst before the
# first one, stepping back whole cycles, ToF and distance saturation, speed register writes).
set(RANGING_TOF_VC ${CMAKE_CURRENT_BINARY_DIR}/tof_distance_tb.vc)
if(EXISTS ${RANGING_GEN_DEFAULT}/rtl/ranging_system.vc)
  file(STRINGS ${RANGING_GEN_DEFAULT}/rtl/ranging_system.vc _sys_params)
  set(_tof_params "")
  foreach(_line ${_sys_params})
    if(_line MATCHES "^-G(CODES|CODE_W|TIME_W|FRAC_W|PERIOD_T|SCORE_W|OFF_W|OFFSETS|C_FRAC|C_INIT)=")
      string(APPEND _tof_params "${_line}\n")
    endif()
  endforeach()
  file(WRITE ${RANGING_TOF_VC} "${_tof_params}")
  ranging_verilator_test(NAME tb_tof_distance TOP tof_distance
    RTL ${PROJECT_SOURCE_DIR}/rtl/tof_distance.v
    VC ${RANGING_TOF_VC}
    TB ${CMAKE_CURRENT_SOURCE_DIR}/tb_tof_distance.cpp)
endif()
