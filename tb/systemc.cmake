# SystemC testbench: the Verilated receiver (verilator --sc) beside the golden model as an
# SC_MODULE, connected by sc_fifo streams. Debian's libsystemc: /usr/include, /usr/lib/x86_64-linux-gnu.
set(SYSTEMC_INCLUDE /usr/include)
set(SYSTEMC_LIBDIR /usr/lib/x86_64-linux-gnu)
add_executable(sc_receiver_top ${CMAKE_CURRENT_SOURCE_DIR}/sc_receiver_top.cpp)
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/sc_receiver_top.cpp PROPERTIES
  COMPILE_OPTIONS "$<$<BOOL:${RANGING_WERROR}>:-Werror>")
target_include_directories(sc_receiver_top SYSTEM PRIVATE ${VERILATOR_ROOT}/include ${VERILATOR_ROOT}/include/vltstd)
target_link_libraries(sc_receiver_top PRIVATE ranging_model)
target_include_directories(sc_receiver_top PRIVATE ${PROJECT_SOURCE_DIR})
target_compile_definitions(sc_receiver_top PRIVATE RANGING_CONFIG="${PROJECT_SOURCE_DIR}/configs/default.yaml"
  SC_CPLUSPLUS=201703L)
add_dependencies(sc_receiver_top generated_default)
verilate(sc_receiver_top SYSTEMC
  SOURCES ${RANGING_GEN_DEFAULT}/rtl/receiver_top.v
          ${RANGING_RECEIVER_RTL}
  TOP_MODULE receiver_top PREFIX Vreceiver_top
  VERILATOR_ARGS -Wno-fatal)
verilator_link_systemc(sc_receiver_top)
add_test(NAME systemc_receiver_top COMMAND sc_receiver_top)
set_tests_properties(systemc_receiver_top PROPERTIES LABELS "hardware" TIMEOUT 600)
