# Icarus Verilog: the generated receiver_top of every 7-bit paper family on model vectors.
ranging_tb_executable(tb_receiver_families_iverilog ${CMAKE_CURRENT_SOURCE_DIR}/tb_receiver_families_iverilog.cpp)
gtest_discover_tests(tb_receiver_families_iverilog DISCOVERY_TIMEOUT 60 PROPERTIES LABELS "hardware" TIMEOUT 900 COST 500)
