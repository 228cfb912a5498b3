# Benchmark, not a test: Verilator samples/s of receiver_top and the ratio to the golden model.
add_executable(bench_receiver_top ${CMAKE_CURRENT_SOURCE_DIR}/bench_receiver_top.cpp)
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/bench_receiver_top.cpp PROPERTIES
  COMPILE_OPTIONS "$<$<BOOL:${RANGING_WERROR}>:-Werror>")
target_link_libraries(bench_receiver_top PRIVATE ranging_model)
target_include_directories(bench_receiver_top PRIVATE ${PROJECT_SOURCE_DIR})
target_include_directories(bench_receiver_top SYSTEM PRIVATE ${VERILATOR_ROOT}/include ${VERILATOR_ROOT}/include/vltstd)
target_compile_definitions(bench_receiver_top PRIVATE RANGING_CONFIG="${PROJECT_SOURCE_DIR}/configs/default.yaml")
verilate(bench_receiver_top SOURCES ${RANGING_GEN_DEFAULT}/rtl/receiver_top.v
  ${RANGING_RECEIVER_RTL}
  TOP_MODULE receiver_top PREFIX Vreceiver_top
  # Bench build only (the equivalence testbenches keep their settings): X values resolved once
  # at compile time and initial values not randomized (scripts/bench.sh measures the choice).
  VERILATOR_ARGS -Wno-fatal -O3 --x-assign fast --x-initial fast)
