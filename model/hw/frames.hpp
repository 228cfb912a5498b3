#pragma once
// Host side of the board's UART (rtl/measurement_uart.v): one 17-byte frame per measurement,
//   0xA5 0x5A | code | flags | ToF u32 (samples, 8 fraction bits) | distance u32 (um) |
//   score u16 (rho^2, Q0.16) | margin u16 | checksum = XOR of bytes 2..15
// little-endian. The decoder resynchronizes on the sync pair: a sync whose checksum fails is a
// bad frame and the search resumes one byte after it; bytes outside frames are counted as
// skipped; a frame cut short by the end of the stream is counted as truncated.
#include <cstdint>
#include <span>
#include <vector>

namespace ranging {

struct UartFrame {
  std::uint64_t offset = 0;  // byte offset of the sync in the stream
  int code = 0;
  std::uint8_t flags = 0;    // bit 0 no burst sent before the arrival, 1 distance saturated, 2 ADC overrun
  std::uint32_t tof_q8 = 0;  // full-rate samples * 256
  std::uint32_t distance_um = 0;
  std::uint16_t score = 0, margin = 0;
};

struct FrameStats {
  std::uint64_t bytes = 0, bad_frames = 0, skipped_bytes = 0;
  bool truncated = false;
};

constexpr std::size_t kUartFrameBytes = 17;

// Decodes a whole byte stream.
std::vector<UartFrame> decode_uart_frames(std::span<const std::uint8_t> bytes, FrameStats& stats);

// The 17 bytes of a frame (used by tests and by anything that fakes a board).
std::vector<std::uint8_t> encode_uart_frame(const UartFrame& f);

}  // namespace ranging
