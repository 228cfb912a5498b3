// `verilator --lint-only -Wall` is clean on every RTL file: each module with the parameters the
// generator gives it, and every generated top (default and large receiver, the ranging system).
#include <gtest/gtest.h>

#include <string>

#include "tests/process.hpp"

namespace {

const std::string kRoot = RANGING_SOURCE_DIR;

void expect_clean(const std::string& args) {
  const auto r = ranging::testing_support::run_command("verilator --lint-only -Wall " + args);
  EXPECT_EQ(r.status, 0) << args << "\n" << r.out << r.err;
  EXPECT_EQ(r.out + r.err, "") << args;
}

const std::string kReceiver =
    kRoot + "/rtl/bandpass_sos.v " + kRoot + "/rtl/correlator_bank.v " + kRoot + "/rtl/peak_detector.v";

}  // namespace

TEST(RtlLint, EveryReceiverModuleWithItsGeneratedParameters) {
  for (const char* m : {"bandpass_sos", "correlator_bank", "peak_detector"}) {
    expect_clean("-f " + kRoot + "/generated/default/rtl/" + m + ".vc " + kRoot + "/rtl/" + m + ".v --top-module " + m);
  }
}

TEST(RtlLint, GeneratedReceiverTops) {
  for (const char* c : {"default", "large"}) {
    expect_clean(kRoot + "/generated/" + c + "/rtl/receiver_top.v " + kReceiver + " --top-module receiver_top");
  }
}

TEST(RtlLint, GeneratedSystemTop) {
  expect_clean(kRoot + "/generated/default/rtl/ranging_system_top.v " + kRoot + "/generated/default/rtl/receiver_top.v " +
               kReceiver + " " + kRoot + "/rtl/adc_interface.v " + kRoot + "/rtl/tx_scheduler.v " + kRoot +
               "/rtl/tof_distance.v " + kRoot + "/rtl/uart_tx.v " + kRoot + "/rtl/measurement_uart.v " + kRoot +
               "/rtl/ranging_system.v --top-module ranging_system_top");
}
