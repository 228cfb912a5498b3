# Verilator testbenches of rtl/correlator_bank.v and rtl/peak_detector.v against the golden
# model (CorrelatorBankFixed, PeakDetectorFixed), bit for bit; each also runs the Verilator
# lint and an Icarus simulation of the same module.
ranging_verilator_test(NAME tb_correlator_bank TOP correlator_bank
  RTL ${PROJECT_SOURCE_DIR}/rtl/correlator_bank.v ${RANGING_RTL_QUANTIZE}
  VC ${RANGING_GEN_DEFAULT}/rtl/correlator_bank.vc
  TB ${CMAKE_CURRENT_SOURCE_DIR}/tb_correlator_bank.cpp)
ranging_verilator_test(NAME tb_peak_detector TOP peak_detector
  RTL ${PROJECT_SOURCE_DIR}/rtl/peak_detector.v
  VC ${RANGING_GEN_DEFAULT}/rtl/peak_detector.vc
  TB ${CMAKE_CURRENT_SOURCE_DIR}/tb_peak_detector.cpp)
