// Replays the fuzz seeds and every regression input (tests/fuzz/regressions/, crashes found
// by the libFuzzer targets and hand-written hostile inputs) through the fuzz targets' entry
// points (tests/fuzz/fuzz_entry.hpp) in the normal unit tests: each input must parse or be
// refused with InputError (the entries swallow only InputError, so anything else fails here,
// and the ASan+UBSan pass of the suite catches memory errors and UB).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "model/base/error.hpp"
#include "model/hw/frames.hpp"
#include "model/sim/capture.hpp"
#include "tests/fuzz/fuzz_entry.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kSrc = RANGING_SOURCE_DIR;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

using Entry = int (*)(const std::uint8_t*, std::size_t);

std::size_t replay(Entry entry, const std::vector<std::string>& dirs) {
  std::size_t n = 0;
  for (const auto& d : dirs) {
    if (!fs::is_directory(d)) continue;
    for (const auto& e : fs::directory_iterator(d)) {
      if (!e.is_regular_file() || e.path().extension() == ".md") continue;
      const std::string bytes = slurp(e.path());
      EXPECT_NO_THROW(entry(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size())) << e.path();
      ++n;
    }
  }
  return n;
}

const std::string kReg = kSrc + "/tests/fuzz/regressions/";

TEST(FuzzRegressions, ReceiverConfig) {
  EXPECT_GE(replay(ranging::fuzz::receiver_config, {kSrc + "/configs", kReg + "receiver_config"}), 10u);
}
TEST(FuzzRegressions, Scene) { EXPECT_GE(replay(ranging::fuzz::scene, {kSrc + "/scenes", kReg + "scene"}), 10u); }
TEST(FuzzRegressions, CaptureCsv) {
  EXPECT_GE(replay(ranging::fuzz::capture_csv, {kSrc + "/tests/fuzz/seeds/capture_csv", kReg + "capture_csv"}), 5u);
}
TEST(FuzzRegressions, CaptureWav) {
  EXPECT_GE(replay(ranging::fuzz::capture_wav, {kSrc + "/tests/fuzz/seeds/capture_wav", kReg + "capture_wav"}), 5u);
}

TEST(FuzzRegressions, UartFrames) {
  EXPECT_GE(replay(ranging::fuzz::uart_frames, {kSrc + "/tests/fuzz/seeds/uart_frames", kReg + "uart_frames"}), 4u);
}
TEST(FuzzRegressions, SweepSpec) {
  auto entry = [](const std::uint8_t* d, std::size_t n) { return ranging::fuzz::sweep_spec(d, n, kSrc); };
  EXPECT_GE(replay(entry, {kSrc + "/tests/fuzz/seeds/sweep_spec", kReg + "sweep_spec"}), 3u);
}

// The seeds of the uart_frames target decode as built: whole frames, and a stream with noise,
// a bad checksum and a frame cut short.
TEST(FuzzRegressions, UartFramesSeedsDecode) {
  const std::string bytes = slurp(kSrc + "/tests/fuzz/seeds/uart_frames/three-frames.bin");
  ranging::FrameStats st;
  const auto frames = ranging::decode_uart_frames(
      std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()), st);
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[1].tof_q8, 0xffffffffu);
  EXPECT_EQ(frames[2].code, 9);
  const std::string noisy = slurp(kSrc + "/tests/fuzz/seeds/uart_frames/noise-bad-truncated.bin");
  ranging::FrameStats st2;
  const auto f2 = ranging::decode_uart_frames(
      std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(noisy.data()), noisy.size()), st2);
  EXPECT_EQ(f2.size(), 1u);  // the bad-checksum frame and the truncated one are not frames
  EXPECT_GE(st2.bad_frames, 1u);
  EXPECT_TRUE(st2.truncated);
}

// The hostile inputs are refused (not merely survived), with the file's line where it has one.
TEST(FuzzRegressions, HostileInputsAreRefused) {
  auto refused = [](auto parse, const std::string& file, const std::string& what) {
    try {
      parse(slurp(kReg + file));
      ADD_FAILURE() << file << " was accepted";
    } catch (const ranging::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << file << ": " << e.what();
    }
  };
  auto cfg = [](const std::string& t) { return ranging::parse_receiver_config(t, "c.yaml"); };
  auto csv = [](const std::string& t) { return ranging::parse_capture_csv(t, "x.csv"); };
  auto wav = [](const std::string& t) { return ranging::parse_capture_wav(t, "x.wav"); };
  refused(cfg, "receiver_config/alias-bomb.yaml", "alias bomb");
  refused(cfg, "receiver_config/deep-nesting.yaml", "c.yaml:1:");
  refused(cfg, "receiver_config/duplicate-key.yaml", "c.yaml:2: name: duplicate key (first at c.yaml:1)");
  refused(cfg, "receiver_config/latin1.yaml", "c.yaml:1: truncated UTF-8 sequence (byte 0xE9)");
  refused(cfg, "receiver_config/two-documents.yaml", "c.yaml:2: a second YAML document");
  refused(cfg, "receiver_config/nul-byte.yaml", "control character 0x00");
  refused(cfg, "receiver_config/complex-key.yaml", "c.yaml:1:");
  refused(csv, "capture_csv/huge-times.csv", "x.csv:");
  refused(csv, "capture_csv/denormal-times.csv", "x.csv:");
  refused(csv, "capture_csv/record-length-huge.csv", "x.csv:1: Record Length");
  refused(wav, "capture_wav/data-size-past-end.wav", "x.wav: byte 36: truncated");
  refused(wav, "capture_wav/chunk-size-max.wav", "x.wav: byte");
}

}  // namespace
