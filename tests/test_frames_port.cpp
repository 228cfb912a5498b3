// `ranging frames --port DEV --baud B` (issue 16 §6): the serial-port path (termios, raw) on a
// pseudo-terminal (openpty): the frames written to the master side come out of the tool; bytes
// a cooked terminal would eat or translate (^C, ^Q, CR, LF, DEL) pass unchanged; bad, inserted
// and truncated bytes are counted as in the file path; a port that cannot be opened is exit 2.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <string>
#include <vector>

#include "model/hw/frames.hpp"
#include "tests/process.hpp"

using namespace ranging;
using ranging::testing_support::run_tool;

namespace {

class Pty {
 public:
  Pty() {
    char name[256] = {};
    if (::openpty(&master_, &slave_, name, nullptr, nullptr) != 0) return;
    name_ = name;
    // raw before anything is written: data queued under a cooked line discipline would be
    // edited before the tool switches the port to raw
    termios t{};
    ::tcgetattr(slave_, &t);
    ::cfmakeraw(&t);
    ::tcsetattr(slave_, TCSANOW, &t);
  }
  ~Pty() {
    if (master_ >= 0) ::close(master_);
    if (slave_ >= 0) ::close(slave_);
  }
  bool ok() const { return !name_.empty(); }
  const std::string& name() const { return name_; }
  void write(const std::vector<std::uint8_t>& b) const {
    std::size_t done = 0;
    while (done < b.size()) {
      const ssize_t n = ::write(master_, b.data() + done, b.size() - done);
      if (n <= 0) break;
      done += static_cast<std::size_t>(n);
    }
  }

 private:
  int master_ = -1, slave_ = -1;
  std::string name_;
};

UartFrame make(int code, std::uint32_t tof, std::uint32_t um, std::uint16_t score) {
  UartFrame f;
  f.code = code;
  f.tof_q8 = tof;
  f.distance_um = um;
  f.score = score;
  f.margin = 0x0d0a;  // CR LF in the payload
  return f;
}

void append(std::vector<std::uint8_t>& s, const std::vector<std::uint8_t>& b) { s.insert(s.end(), b.begin(), b.end()); }

TEST(FramesPort, ReadsRawFramesFromAPseudoTerminal) {
  Pty pty;
  ASSERT_TRUE(pty.ok()) << "openpty failed";
  std::vector<std::uint8_t> s;
  append(s, encode_uart_frame(make(1, 0x03117f03, 250000, 0x1311)));  // ^C ^Q DEL in the ToF
  append(s, {0x03, 0x11, 0x7f, 0xA5});                                 // inserted junk, a lone sync byte
  auto bad = encode_uart_frame(make(2, 7353 * 256, 500000, 40000));
  bad[9] ^= 0x40;                                                      // corrupted distance
  append(s, bad);
  append(s, encode_uart_frame(make(3, 14706 * 256, 1000000, 65535)));
  append(s, encode_uart_frame(make(4, 100, 68, 1)));
  append(s, encode_uart_frame(make(5, 200, 136, 2)));                 // beyond --frames 3
  pty.write(s);
  const auto r = run_tool("frames --port " + pty.name() + " --baud 1500000 --frames 3 --timeout 5 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["frames"], 3);
  EXPECT_EQ(j["bad_frames"], 1);
  EXPECT_GE(j["skipped_bytes"].get<int>(), 3);
  EXPECT_EQ(j["measurements"][0]["code"], 1);
  EXPECT_DOUBLE_EQ(j["measurements"][0]["tof_samples"].get<double>(), 0x03117f03 / 256.0);
  EXPECT_DOUBLE_EQ(j["measurements"][0]["margin"].get<double>(), 0x0d0a / 65536.0);
  EXPECT_EQ(j["measurements"][1]["code"], 3);
  EXPECT_DOUBLE_EQ(j["measurements"][1]["distance_m"].get<double>(), 1.0);
  EXPECT_EQ(j["measurements"][2]["code"], 4);
  // the offset is the byte position in the port's stream: frame 1 (17) + junk (4) + bad (17) + 3 (17)
  EXPECT_EQ(j["measurements"][2]["offset"], 17 + 4 + 17 + 17);
}

TEST(FramesPort, CsvUntilTimeoutCountsATruncatedFrame) {
  Pty pty;
  ASSERT_TRUE(pty.ok());
  std::vector<std::uint8_t> s;
  append(s, encode_uart_frame(make(1, 3676 * 256, 250000, 40000)));
  append(s, encode_uart_frame(make(2, 7353 * 256, 500000, 50000)));
  const auto third = encode_uart_frame(make(3, 1, 1, 1));
  s.insert(s.end(), third.begin(), third.begin() + 9);  // the line stops mid-frame
  pty.write(s);
  auto r = run_tool("frames --port " + pty.name() + " --timeout 0.3");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 3) << r.out;  // header + 2 rows
  EXPECT_NE(r.out.find("\n0,1,0,"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\n17,2,0,"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("truncated"), std::string::npos) << r.err;
  pty.write(s);
  r = run_tool("frames --port " + pty.name() + " --timeout 0.3 --strict --json");
  EXPECT_EQ(r.status, 1) << "--strict: a truncated frame";
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["frames"], 2);
  EXPECT_TRUE(j["truncated"].get<bool>());
}

TEST(FramesPort, BadPortsAndOptionsAreExit2) {
  auto r = run_tool("frames --port /nonexistent/ttyUSB7");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("--port"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/nonexistent/ttyUSB7: cannot open"), std::string::npos) << r.err;
  r = run_tool("frames --port /dev/null");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("not a serial port"), std::string::npos) << r.err;
  Pty pty;
  ASSERT_TRUE(pty.ok());
  r = run_tool("frames --port " + pty.name() + " --baud 1234");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty());
  EXPECT_NE(r.err.find("--baud"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1500000"), std::string::npos) << "the valid rates are listed: " << r.err;
  r = run_tool("frames --baud 115200 some.bin");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("only with --port"), std::string::npos) << r.err;
  r = run_tool("frames --port " + pty.name() + " some.bin");
  EXPECT_EQ(r.status, 2);
  r = run_tool("frames");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("FILE"), std::string::npos) << r.err;
}

}  // namespace
