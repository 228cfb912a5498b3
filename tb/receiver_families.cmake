# Icarus Verilog: the generated receiver_top of every 7-bit paper family on model vectors.
add_executable(tb_receiver_families_iverilog ${CMAKE_CURRENT_SOURCE_DIR}/tb_receiver_families_iverilog.cpp)
set_source_files_properties(${CMAKE_CURRENT_SOURCE_DIR}/tb_receiver_families_iverilog.cpp PROPERTIES
  COMPILE_OPTIONS "$<$<BOOL:${RANGING_WERROR}>:-Werror>")
target_link_libraries(tb_receiver_families_iverilog PRIVATE ranging_model GTest::gtest GTest::gtest_main)
target_include_directories(tb_receiver_families_iverilog PRIVATE ${PROJECT_SOURCE_DIR})
target_compile_definitions(tb_receiver_families_iverilog PRIVATE
  RANGING_SOURCE_DIR="${PROJECT_SOURCE_DIR}"
  RANGING_CONFIG="${PROJECT_SOURCE_DIR}/configs/default.yaml"
  RANGING_TRACE_DIR="${CMAKE_BINARY_DIR}")
gtest_discover_tests(tb_receiver_families_iverilog DISCOVERY_TIMEOUT 60 PROPERTIES LABELS "hardware" TIMEOUT 900 COST 500)
