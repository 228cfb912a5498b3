# bandpass_sos: the Verilog SOS cascade against BandpassFixed (tb/tb_bandpass_sos.cpp), plus
# its Verilator lint and an Icarus Verilog run of the same vectors.
ranging_verilator_test(NAME tb_bandpass_sos TOP bandpass_sos
  RTL ${PROJECT_SOURCE_DIR}/rtl/bandpass_sos.v ${RANGING_RTL_QUANTIZE}
  VC ${RANGING_GEN_DEFAULT}/rtl/bandpass_sos.vc
  TB ${CMAKE_CURRENT_SOURCE_DIR}/tb_bandpass_sos.cpp)
find_program(RANGING_VERILATOR_LINT verilator REQUIRED)
find_program(RANGING_IVERILOG_BIN iverilog REQUIRED)
find_program(RANGING_VVP_BIN vvp REQUIRED)
target_compile_definitions(tb_bandpass_sos PRIVATE
  RANGING_VERILATOR_BIN="${RANGING_VERILATOR_LINT}"
  RANGING_IVERILOG_BIN="${RANGING_IVERILOG_BIN}"
  RANGING_VVP_BIN="${RANGING_VVP_BIN}"
  RANGING_TB_WORK_DIR="${CMAKE_CURRENT_BINARY_DIR}/tb_bandpass_sos_work")
# Verilator's runtime headers are not ours: include them as system headers so -Werror on the
# testbench does not trip over their warnings (GCC drops the plain -I of the same directory).
target_include_directories(tb_bandpass_sos SYSTEM PRIVATE ${VERILATOR_ROOT}/include ${VERILATOR_ROOT}/include/vltstd)
# tb/CMakeLists.txt replaces the directory's compile options (dropping -fsanitize): put the
# sanitizers back on this testbench so RANGING_SANITIZE=ON checks its code too.
if(RANGING_SANITIZE)
  target_compile_options(tb_bandpass_sos PRIVATE -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
endif()
