#pragma once
// The fuzzed entry points, shared by the libFuzzer targets (tests/fuzz/fuzz_*.cpp) and the
// unit test that replays the seeds and every regression input (tests/test_fuzz_regressions.cpp).
// Contract under test: any input either parses or is refused with ranging::InputError; any
// other exception, a crash, a leak or undefined behaviour is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "model/base/error.hpp"
#include "model/config/receiver_config.hpp"
#include "model/sim/capture.hpp"
#include "model/sim/scene.hpp"

namespace ranging::fuzz {

inline std::string text_of(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

inline int receiver_config(const std::uint8_t* data, std::size_t size) {
  try {
    (void)parse_receiver_config(text_of(data, size), "fuzz.yaml");
  } catch (const InputError&) {
  }
  return 0;
}

inline int scene(const std::uint8_t* data, std::size_t size) {
  try {
    (void)parse_scene(text_of(data, size), "fuzz.yaml", "/nonexistent-fuzz-dir");
  } catch (const InputError&) {
  }
  return 0;
}

inline int capture_csv(const std::uint8_t* data, std::size_t size) {
  try {
    (void)parse_capture_csv(text_of(data, size), "fuzz.csv");
  } catch (const InputError&) {
  }
  return 0;
}

inline int capture_wav(const std::uint8_t* data, std::size_t size) {
  try {
    (void)parse_capture_wav(text_of(data, size), "fuzz.wav");
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace ranging::fuzz
