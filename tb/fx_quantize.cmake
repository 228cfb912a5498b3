# rtl/fx_quantize.v (the receiver's shared quantizer) against the model's fx_quantize, every
# input of small widths in every mode (Icarus), and its Verilator lint per parameter set.
ranging_tb_executable(tb_fx_quantize ${CMAKE_CURRENT_SOURCE_DIR}/tb_fx_quantize.cpp)
gtest_discover_tests(tb_fx_quantize DISCOVERY_TIMEOUT 60 PROPERTIES LABELS "hardware" TIMEOUT 300)
