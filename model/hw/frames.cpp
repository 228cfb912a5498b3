#include "model/hw/frames.hpp"

namespace ranging {
namespace {

std::uint32_t le(std::span<const std::uint8_t> b, std::size_t at, int n) {
  std::uint32_t v = 0;
  for (int i = n - 1; i >= 0; --i) v = (v << 8) | b[at + static_cast<std::size_t>(i)];
  return v;
}

}  // namespace

std::vector<UartFrame> decode_uart_frames(std::span<const std::uint8_t> b, FrameStats& st) {
  std::vector<UartFrame> out;
  st.bytes = b.size();
  std::size_t i = 0;
  while (i < b.size()) {
    if (b[i] != 0xA5 || i + 1 >= b.size() || b[i + 1] != 0x5A) {
      if (b[i] == 0xA5 && i + 1 >= b.size()) {
        st.truncated = true;
      } else {
        ++st.skipped_bytes;
      }
      ++i;
      continue;
    }
    if (i + kUartFrameBytes > b.size()) {
      st.truncated = true;  // a frame cut short by the end of the stream
      break;
    }
    std::uint8_t x = 0;
    for (std::size_t k = 2; k < kUartFrameBytes - 1; ++k) x ^= b[i + k];
    if (x != b[i + kUartFrameBytes - 1]) {
      ++st.bad_frames;  // resync: search again from the byte after this sync
      ++st.skipped_bytes;
      ++i;
      continue;
    }
    UartFrame f;
    f.offset = i;
    f.code = b[i + 2];
    f.flags = b[i + 3];
    f.tof_q8 = le(b, i + 4, 4);
    f.distance_um = le(b, i + 8, 4);
    f.score = static_cast<std::uint16_t>(le(b, i + 12, 2));
    f.margin = static_cast<std::uint16_t>(le(b, i + 14, 2));
    out.push_back(f);
    i += kUartFrameBytes;
  }
  return out;
}

std::vector<std::uint8_t> encode_uart_frame(const UartFrame& f) {
  std::vector<std::uint8_t> b{0xA5, 0x5A, static_cast<std::uint8_t>(f.code), f.flags};
  auto put = [&](std::uint32_t v, int n) {
    for (int i = 0; i < n; ++i) b.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  put(f.tof_q8, 4);
  put(f.distance_um, 4);
  put(f.score, 2);
  put(f.margin, 2);
  std::uint8_t x = 0;
  for (std::size_t k = 2; k < b.size(); ++k) x ^= b[k];
  b.push_back(x);
  return b;
}

}  // namespace ranging
