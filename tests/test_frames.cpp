// `ranging frames`: the UART measurement frames of rtl/measurement_uart.v, built here byte by
// byte from the documented layout (independent of the encoder), decoded with corrupted,
// inserted and truncated bytes.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "model/hw/frames.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"

using namespace ranging;
namespace fs = std::filesystem;

namespace {

// code, flags, ToF (samples * 256), distance (um), score, margin; XOR of bytes 2..15.
std::vector<std::uint8_t> frame(int code, int flags, std::uint32_t tof, std::uint32_t um, int score, int margin) {
  std::vector<std::uint8_t> b = {0xA5, 0x5A, static_cast<std::uint8_t>(code), static_cast<std::uint8_t>(flags),
                                 static_cast<std::uint8_t>(tof), static_cast<std::uint8_t>(tof >> 8),
                                 static_cast<std::uint8_t>(tof >> 16), static_cast<std::uint8_t>(tof >> 24),
                                 static_cast<std::uint8_t>(um), static_cast<std::uint8_t>(um >> 8),
                                 static_cast<std::uint8_t>(um >> 16), static_cast<std::uint8_t>(um >> 24),
                                 static_cast<std::uint8_t>(score), static_cast<std::uint8_t>(score >> 8),
                                 static_cast<std::uint8_t>(margin), static_cast<std::uint8_t>(margin >> 8)};
  std::uint8_t x = 0;
  for (std::size_t i = 2; i < b.size(); ++i) x ^= b[i];
  b.push_back(x);
  return b;
}

std::vector<std::uint8_t> three() {
  std::vector<std::uint8_t> s;
  for (const auto& f : {frame(1, 0, 3676 * 256 + 128, 250000, 40000, 20000), frame(2, 2, 7353 * 256, 500000, 50000, 1),
                        frame(9, 4, 14706 * 256, 1000000, 65535, 0)}) {
    s.insert(s.end(), f.begin(), f.end());
  }
  return s;
}

}  // namespace

TEST(Frames, DecodesEveryFieldOfCleanFrames) {
  FrameStats st;
  const auto bytes = three();
  const auto f = decode_uart_frames(bytes, st);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(st.bad_frames, 0u);
  EXPECT_EQ(st.skipped_bytes, 0u);
  EXPECT_FALSE(st.truncated);
  EXPECT_EQ(f[0].code, 1);
  EXPECT_EQ(f[0].tof_q8, 3676u * 256 + 128);
  EXPECT_EQ(f[0].distance_um, 250000u);
  EXPECT_EQ(f[0].score, 40000);
  EXPECT_EQ(f[0].margin, 20000);
  EXPECT_EQ(f[1].flags, 2);
  EXPECT_EQ(f[2].code, 9);
  EXPECT_EQ(f[2].distance_um, 1000000u);
  EXPECT_EQ(f[2].offset, 34u);
  EXPECT_EQ(encode_uart_frame(f[1]), frame(2, 2, 7353 * 256, 500000, 50000, 1));
}

TEST(Frames, ACorruptByteIsABadFrameAndTheNextFrameIsFound) {
  for (std::size_t at = 2; at < kUartFrameBytes; ++at) {  // every byte after the sync, checksum included
    auto bytes = three();
    bytes[kUartFrameBytes + at] ^= 0x10;
    FrameStats st;
    const auto f = decode_uart_frames(bytes, st);
    ASSERT_EQ(f.size(), 2u) << "byte " << at;
    EXPECT_EQ(f[0].code, 1);
    EXPECT_EQ(f[1].code, 9);
    EXPECT_EQ(st.bad_frames, 1u) << "byte " << at;
  }
}

TEST(Frames, InsertedBytesAreSkippedAndCounted) {
  auto bytes = three();
  const std::vector<std::uint8_t> junk = {0x00, 0xA5, 0x13, 0xA5, 0xFF};
  bytes.insert(bytes.begin() + kUartFrameBytes, junk.begin(), junk.end());
  bytes.insert(bytes.begin(), 0x42);
  FrameStats st;
  const auto f = decode_uart_frames(bytes, st);
  ASSERT_EQ(f.size(), 3u);
  EXPECT_EQ(st.skipped_bytes, junk.size() + 1);
  EXPECT_EQ(st.bad_frames, 0u);
  EXPECT_EQ(f[1].code, 2);
}

TEST(Frames, ATruncatedLastFrameIsReported) {
  auto bytes = three();
  bytes.resize(bytes.size() - 5);
  FrameStats st;
  const auto f = decode_uart_frames(bytes, st);
  EXPECT_EQ(f.size(), 2u);
  EXPECT_TRUE(st.truncated);
}

TEST(Frames, CommandReadsAFileOrStdinAndCountsBadFrames) {
  const testing_support::ScratchDir scratch("ranging_frames");
  const fs::path p = scratch.path() / "frames.bin";
  auto bytes = three();
  bytes[kUartFrameBytes + 9] ^= 0x01;  // frame 2's distance: checksum fails
  std::ofstream(p, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                           static_cast<std::streamsize>(bytes.size()));
  auto r = testing_support::run_tool("frames " + p.string() + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames"], 2);
  EXPECT_EQ(j["bad_frames"], 1);
  EXPECT_NEAR(j["measurements"][1]["distance_m"].get<double>(), 1.0, 1e-9);
  EXPECT_NEAR(j["measurements"][0]["tof_samples"].get<double>(), 3676.5, 1e-9);
  EXPECT_NE(r.err.find("1 bad"), std::string::npos) << r.err;
  r = testing_support::run_command("cat '" + p.string() + "' | '" + RANGING_TOOL + "' frames - --strict");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.out.substr(0, r.out.find('\n')),
            "offset,code,flags,no_burst,saturated,adc_overrun,tof_samples,distance_m,score,margin");
  EXPECT_NE(r.out.find("\n34,9,4,0,0,1,14706,1.000000,"), std::string::npos) << r.out;
  r = testing_support::run_tool("frames " + p.string() + ".missing");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "");
}
