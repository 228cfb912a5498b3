// libFuzzer target: ranging::fuzz::sweep_spec (tests/fuzz/fuzz_entry.hpp).
#include "tests/fuzz/fuzz_entry.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return ranging::fuzz::sweep_spec(data, size, RANGING_SOURCE_DIR);
}
