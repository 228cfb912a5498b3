// `ranging frames FILE|-`: decodes the board's UART stream of measurement frames
// (rtl/measurement_uart.v, model/hw/frames.hpp) into CSV or JSON distances. Checksums are
// checked, the decoder resyncs after a corrupt byte, and bad frames, skipped bytes and a
// truncated last frame are counted and reported (stderr, and in the JSON).
// --port DEV --baud B reads a serial port directly (termios: raw 8N1, no flow control), frame
// by frame as the bytes come, until --frames N good frames, --timeout S seconds without a
// byte, or the end of the stream (hang-up).
#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <iterator>

#include "model/base/error.hpp"
#include "model/base/input_file.hpp"
#include "model/hw/frames.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/json_meta.hpp"
#include "tool/options.hpp"

namespace ranging::tool {
namespace {

speed_t termios_speed(long long baud) {
  static const std::pair<long long, speed_t> k[] = {
      {1200, B1200},       {2400, B2400},       {4800, B4800},       {9600, B9600},       {19200, B19200},
      {38400, B38400},     {57600, B57600},     {115200, B115200},   {230400, B230400},   {460800, B460800},
      {500000, B500000},   {576000, B576000},   {921600, B921600},   {1000000, B1000000}, {1152000, B1152000},
      {1500000, B1500000}, {2000000, B2000000}, {2500000, B2500000}, {3000000, B3000000}, {3500000, B3500000},
      {4000000, B4000000}};
  std::string valid;
  for (const auto& [b, s] : k) {
    if (b == baud) return s;
    valid += (valid.empty() ? "" : ", ") + std::to_string(b);
  }
  throw InputError("option --baud: " + std::to_string(baud) + " is not a termios rate; valid: " + valid);
}

// Opens DEV raw (8N1, no echo, no flow control, non-blocking reads through poll()).
int open_port(const std::string& dev, long long baud) {
  const speed_t sp = termios_speed(baud);
  const int fd = ::open(dev.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw InputError("option --port: " + dev + ": cannot open: " + std::strerror(errno));
  termios t{};
  if (::tcgetattr(fd, &t) != 0) {
    const int e = errno;
    ::close(fd);
    throw InputError("option --port: " + dev + ": not a serial port: " + std::strerror(e));
  }
  ::cfmakeraw(&t);
  t.c_cflag |= CLOCAL | CREAD;
  t.c_cflag &= ~static_cast<tcflag_t>(CSTOPB | PARENB | CRTSCTS);
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (::cfsetispeed(&t, sp) != 0 || ::cfsetospeed(&t, sp) != 0 || ::tcsetattr(fd, TCSANOW, &t) != 0) {
    const int e = errno;
    ::close(fd);
    throw InputError("option --port: " + dev + ": cannot set raw mode at " + std::to_string(baud) +
                     " baud: " + std::strerror(e));
  }
  return fd;
}

// Streaming decode of the port: a frame is taken as soon as its 17 bytes are in; the same
// rules as decode_uart_frames (a sync whose checksum fails is bad, the search resumes one byte
// after it; other bytes are skipped).
class PortDecoder {
 public:
  template <class Emit>
  void feed(const std::uint8_t* p, std::size_t n, Emit&& emit) {
    buf_.insert(buf_.end(), p, p + n);
    st.bytes += n;
    std::size_t i = 0;
    while (i < buf_.size()) {
      if (buf_[i] != 0xA5) {
        ++st.skipped_bytes;
        ++i;
        continue;
      }
      if (i + 1 >= buf_.size()) break;
      if (buf_[i + 1] != 0x5A) {
        ++st.skipped_bytes;
        ++i;
        continue;
      }
      if (i + kUartFrameBytes > buf_.size()) break;
      FrameStats one;
      auto f = decode_uart_frames(std::span<const std::uint8_t>(buf_.data() + i, kUartFrameBytes), one);
      if (f.size() == 1 && f[0].offset == 0) {
        f[0].offset = consumed_ + i;
        emit(f[0]);
        i += kUartFrameBytes;
      } else {
        ++st.bad_frames;
        ++st.skipped_bytes;
        ++i;
      }
    }
    buf_.erase(buf_.begin(), buf_.begin() + static_cast<long>(i));
    consumed_ += i;
  }
  void finish() { st.truncated = !buf_.empty(); }
  FrameStats st;

 private:
  std::vector<std::uint8_t> buf_;
  std::uint64_t consumed_ = 0;
};

}  // namespace

int cmd_frames(const Args& args) {
  cli::Parser p = command_parser("frames");
  p.positional("FILE", "captured bytes (binary), or - for stdin (not with --port)", false);
  p.option("--port", "DEV", "read the serial port DEV (e.g. /dev/ttyUSB1) instead of FILE: raw 8N1");
  p.option("--baud", "B", "with --port: the line rate (the board's: 1500000)", "1500000");
  p.option("--frames", "N", "with --port: stop after N good frames (default: no limit)");
  p.option("--timeout", "S", "with --port: stop after S seconds without a byte (default: none)");
  add_output_options(p, {.json = true, .json_note = "JSON instead of CSV"});
  p.flag("--strict", "exit 1 when any frame was bad or truncated");
  if (!p.parse(args)) return 0;
  const bool port = p.has("--port");
  for (const char* o : {"--baud", "--frames", "--timeout"}) {
    if (p.has(o) && !port) throw InputError(std::string("option ") + o + ": only with --port");
  }
  if (port && !p.positionals().empty()) throw InputError("option --port: give --port or FILE, not both");
  if (!port && p.positionals().empty()) throw InputError("missing FILE (or --port DEV)");
  const std::string path = port ? p.get_or("--port", "") : p.positionals().at(0);
  std::vector<std::uint8_t> bytes;
  FrameStats st;
  std::vector<UartFrame> frames;
  bool decoded = false;
  if (port) {
    const long long baud = p.integer("--baud", 1500000, 1200, 4000000);
    const long long max_frames = p.has("--frames") ? p.integer("--frames", 1, 1, 1LL << 40) : 0;
    const double timeout = p.has("--timeout") ? p.number("--timeout", 1, 0.001, 1e6) : 0;
    const int fd = open_port(path, baud);
    const bool csv = !p.has("--json");
    if (csv) std::cout << "offset,code,flags,no_burst,saturated,adc_overrun,tof_samples,distance_m,score,margin\n";
    PortDecoder dec;
    std::uint8_t buf[4096];
    bool done = false;
    while (!done) {
      pollfd pfd{fd, POLLIN, 0};
      const int pr = ::poll(&pfd, 1, timeout > 0 ? static_cast<int>(std::ceil(timeout * 1000)) : -1);
      if (pr < 0 && errno == EINTR) continue;
      if (pr <= 0) break;  // timeout (or a poll error)
      const ssize_t n = ::read(fd, buf, sizeof buf);
      if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
      if (n <= 0) break;  // end of stream or hang-up (EIO on a pty)
      dec.feed(buf, static_cast<std::size_t>(n), [&](const UartFrame& f) {
        if (done) return;
        frames.push_back(f);
        if (csv) {
          std::printf("%llu,%d,%u,%d,%d,%d,%.8g,%.6f,%.6f,%.6f\n", static_cast<unsigned long long>(f.offset), f.code,
                      static_cast<unsigned>(f.flags), f.flags & 1, (f.flags >> 1) & 1, (f.flags >> 2) & 1,
                      f.tof_q8 / 256.0, f.distance_um * 1e-6, f.score / 65536.0, f.margin / 65536.0);
          std::fflush(stdout);
        }
        if (max_frames > 0 && static_cast<long long>(frames.size()) >= max_frames) done = true;
      });
    }
    ::close(fd);
    if (!done) dec.finish();
    st = dec.st;
    decoded = true;
    if (csv) {
      if (st.bad_frames || st.truncated || st.skipped_bytes) {
        std::cerr << "ranging frames: " << frames.size() << " good frames, " << st.bad_frames << " bad (checksum), "
                  << st.skipped_bytes << " bytes skipped" << (st.truncated ? ", last frame truncated" : "") << "\n";
      }
      return (p.has("--strict") && (st.bad_frames || st.truncated)) ? 1 : 0;
    }
  } else if (path == "-") {
    std::cin >> std::noskipws;
    bytes.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
  } else {
    // a missing file, a folder, an unreadable or a > 1 GiB file: exit 2 with what it is
    const std::string text = read_input_file(path, "byte capture", std::size_t{1} << 30);
    bytes.assign(text.begin(), text.end());
  }
  if (!decoded) frames = decode_uart_frames(bytes, st);
  if (p.has("--json")) {
    nlohmann::ordered_json j;
    stamp_build_info(j);
    j["file"] = path;
    j["bytes"] = st.bytes;
    j["frames"] = frames.size();
    j["bad_frames"] = st.bad_frames;
    j["skipped_bytes"] = st.skipped_bytes;
    j["truncated"] = st.truncated;
    j["measurements"] = nlohmann::ordered_json::array();
    for (const auto& f : frames) {
      j["measurements"].push_back({{"offset", f.offset}, {"code", f.code}, {"flags", f.flags},
                                   {"no_burst", (f.flags & 1) != 0}, {"saturated", (f.flags & 2) != 0},
                                   {"adc_overrun", (f.flags & 4) != 0}, {"tof_samples", f.tof_q8 / 256.0},
                                   {"distance_m", f.distance_um * 1e-6}, {"score", f.score / 65536.0},
                                   {"margin", f.margin / 65536.0}});
    }
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "offset,code,flags,no_burst,saturated,adc_overrun,tof_samples,distance_m,score,margin\n";
    for (const auto& f : frames) {
      std::printf("%llu,%d,%u,%d,%d,%d,%.8g,%.6f,%.6f,%.6f\n", static_cast<unsigned long long>(f.offset), f.code,
                  static_cast<unsigned>(f.flags), f.flags & 1, (f.flags >> 1) & 1, (f.flags >> 2) & 1,
                  f.tof_q8 / 256.0, f.distance_um * 1e-6, f.score / 65536.0, f.margin / 65536.0);
    }
  }
  if (st.bad_frames || st.truncated || st.skipped_bytes) {
    std::cerr << "ranging frames: " << frames.size() << " good frames, " << st.bad_frames << " bad (checksum), "
              << st.skipped_bytes << " bytes skipped" << (st.truncated ? ", last frame truncated" : "") << "\n";
  }
  return (p.has("--strict") && (st.bad_frames || st.truncated)) ? 1 : 0;
}

}  // namespace ranging::tool
