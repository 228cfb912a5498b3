// libFuzzer target: ranging::fuzz::uart_frames (tests/fuzz/fuzz_entry.hpp).
#include "tests/fuzz/fuzz_entry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return ranging::fuzz::uart_frames(data, size);
}
