// Captures: CSV/WAV readers and writers, `ranging decode`, the simulate -> capture -> decode
// round trip, and every bad-capture case (clear error naming file and line, exit 2, no output).
#include <gtest/gtest.h>

#include "tests/process.hpp"
#include "tests/scratch.hpp"
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>

#include "model/sim/capture.hpp"
#include "model/sim/capture_stream.hpp"
#include "model/base/error.hpp"

using namespace ranging;
namespace fs = std::filesystem;

namespace {

using ToolRun = testing_support::ProcessResult;
using testing_support::run_tool;

std::string sci(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.9e", v);
  return b;
}

void write(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::string error_of_csv(const std::string& text) {
  try {
    parse_capture_csv(text, "cap.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Capture, CsvAndWavRoundTripInEveryFormat) {
  Capture c;
  c.sample_rate = 5e6;
  for (int n = 0; n < 1000; ++n) c.samples.push_back(0.7 * std::sin(n * 0.251) * std::exp(-n / 400.0));
  const Capture csv = parse_capture_csv(capture_csv(c), "x.csv");
  EXPECT_NEAR(csv.sample_rate, 5e6, 1e-3);
  EXPECT_EQ(csv.t0, 0.0);
  ASSERT_EQ(csv.samples.size(), c.samples.size());
  for (std::size_t n = 0; n < c.samples.size(); ++n) EXPECT_NEAR(csv.samples[n], c.samples[n], 1e-9);
  for (auto [fmt, tol] : {std::pair{WavFormat::Pcm8, 1.0 / 256}, std::pair{WavFormat::Pcm16, 1.0 / 65536},
                          std::pair{WavFormat::Pcm24, 1.0 / 16777216}, std::pair{WavFormat::Pcm32, 1.0 / 4294967296.0},
                          std::pair{WavFormat::Float32, 1e-7}, std::pair{WavFormat::Float64, 0.0}}) {
    const Capture w = parse_capture_wav(capture_wav(c, fmt), "x.wav");
    EXPECT_EQ(w.sample_rate, 5e6);
    ASSERT_EQ(w.samples.size(), c.samples.size());
    for (std::size_t n = 0; n < c.samples.size(); ++n) EXPECT_NEAR(w.samples[n], c.samples[n], tol);
  }
}

TEST(Capture, TektronixStyleHeaderAndNegativeStartTime) {
  std::string text =
      "Model,MDO3024\nFirmware Version,1.26\n\nWaveform Type,ANALOG\nSample Interval,2e-07\n"
      "Record Length,5\nTIME,CH1\n";
  for (int n = 0; n < 5; ++n) text += sci(-4e-7 + n * 2e-7) + "," + std::to_string(0.1 * n) + "\n";
  const Capture c = parse_capture_csv(text, "tek.csv");
  EXPECT_NEAR(c.sample_rate, 5e6, 1.0);
  EXPECT_NEAR(c.t0, -4e-7, 1e-12);
  EXPECT_EQ(c.samples.size(), 5u);
}

// numpy.savetxt (spaces), SPICE / tab-separated and European (';') exports read as the comma
// file does; a decimal comma is refused naming its line and cell.
TEST(Capture, CsvWithSemicolonTabOrSpaceSeparatorsReadsTheSame) {
  std::string comma = "Time (s),Voltage (V)\n", semi = "time;volts\n", tab = "time\tV(out)\n", space = "# time volts\n";
  for (int n = 0; n < 50; ++n) {
    const std::string t = sci(-1e-6 + n * 2e-7), v = sci(0.3 * std::sin(0.7 * n));
    comma += t + "," + v + "\n";
    semi += t + ";" + v + "\r\n";
    tab += t + "\t" + v + "\t" + sci(-1.0) + "\n";
    space += "  " + t + "   " + v + " \n";
  }
  const Capture ref = parse_capture_csv(comma, "c.csv");
  ASSERT_EQ(ref.samples.size(), 50u);
  EXPECT_NEAR(ref.sample_rate, 5e6, 1e-3);
  for (const auto& [text, name] : {std::pair{semi, "s.csv"}, std::pair{tab, "t.csv"}, std::pair{space, "w.csv"}}) {
    const Capture c = parse_capture_csv(text, name);
    EXPECT_EQ(c.samples, ref.samples) << name;
    EXPECT_EQ(c.sample_rate, ref.sample_rate) << name;
    EXPECT_EQ(c.t0, ref.t0) << name;
  }
  EXPECT_NE(error_of_csv("time;volts\n0;0,5\n").find("cap.csv:2: voltage column: '0,5' is not a number"),
            std::string::npos)
      << error_of_csv("time;volts\n0;0,5\n");
}

TEST(Capture, BadCsvNamesFileAndLine) {
  const std::string head = "TIME,CH1\n0,0\n2e-7,0.1\n";
  auto has = [](const std::string& text, const std::string& what) {
    const std::string e = error_of_csv(text);
    EXPECT_NE(e.find(what), std::string::npos) << "error '" << e << "'";
  };
  has("", "cap.csv:0: no data rows");
  has("TIME,CH1\n", "cap.csv:1: no data rows");
  has(head + "4e-7,abc\n", "cap.csv:4: voltage column: 'abc' is not a number");
  has(head + "4e-7,nan\n", "cap.csv:4: voltage column: 'nan' is not finite");
  has(head + "inf,0.1\n", "cap.csv:4: time column: 'inf' is not finite");
  has(head + "1e-7,0.1\n", "cap.csv:4: time does not increase");
  has(head + "6e-7,0.1\n8e-7,0\n1e-6,0\n", "uneven sampling");
  has(head + "4e-7\n", "cap.csv:4: expected 'time,voltage'");
}

TEST(Capture, BadWavIsRefusedWithByteOffset) {
  Capture c;
  c.sample_rate = 5e6;
  c.samples.assign(100, 0.25);
  const std::string good = capture_wav(c, WavFormat::Pcm16);
  auto err = [](const std::string& bytes) {
    try {
      parse_capture_wav(bytes, "cap.wav");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(err(good.substr(0, good.size() - 10)).find("cap.wav: byte 36: truncated"), std::string::npos);
  EXPECT_NE(err(good.substr(0, 30)).find("truncated"), std::string::npos);
  EXPECT_NE(err("").find("empty"), std::string::npos);
  EXPECT_NE(err("RIFX0000WAVE").find("not a RIFF/WAVE"), std::string::npos);
  std::string bits12 = good;
  bits12[34] = 12;  // bits per sample
  EXPECT_NE(err(bits12).find("cap.wav: byte 36: unsupported sample format (format 1, 12 bits); valid: 8/16/24/32-bit "
                             "PCM, 32/64-bit float"),
            std::string::npos)
      << err(bits12);
  std::string alaw = good;
  alaw[20] = 6;  // format 6 (A-law)
  EXPECT_NE(err(alaw).find("unsupported sample format (format 6"), std::string::npos);
  // a NaN in a 64-bit float WAV names its sample and byte
  c.samples[7] = std::nan("");
  EXPECT_NE(err(capture_wav(c, WavFormat::Float64)).find("cap.wav: byte 100: sample 7 is not finite"), std::string::npos)
      << err(capture_wav(c, WavFormat::Float64));
  // and in a one-channel 32-bit float WAV (its vectorized reader): the first bad sample, NaN or Inf
  EXPECT_NE(err(capture_wav(c, WavFormat::Float32)).find("cap.wav: byte 72: sample 7 is not finite"), std::string::npos)
      << err(capture_wav(c, WavFormat::Float32));
  c.samples[7] = 0.25;
  c.samples[9] = -HUGE_VAL;
  c.samples[11] = std::nan("");
  EXPECT_NE(err(capture_wav(c, WavFormat::Float32)).find("cap.wav: byte 80: sample 9 is not finite"), std::string::npos)
      << err(capture_wav(c, WavFormat::Float32));
}

// The codes of each format, as scipy.io.wavfile and other tools write them (little-endian,
// 8-bit unsigned with 128 as zero), read back as full-scale fractions.
TEST(Capture, WavPcmCodesAreFullScaleFractionsInEveryWidth) {
  Capture c;
  c.sample_rate = 2e6;
  c.samples = {0.0, 0.5, -0.5, -1.0, 127.0 / 128.0};
  const std::string w8 = capture_wav(c, WavFormat::Pcm8);
  ASSERT_EQ(w8.size(), 44u + 5u);
  EXPECT_EQ(static_cast<unsigned char>(w8[44]), 128);  // 0
  EXPECT_EQ(static_cast<unsigned char>(w8[45]), 192);  // 0.5
  EXPECT_EQ(static_cast<unsigned char>(w8[46]), 64);   // -0.5
  EXPECT_EQ(static_cast<unsigned char>(w8[47]), 0);    // -1
  EXPECT_EQ(static_cast<unsigned char>(w8[48]), 255);  // 127/128
  const std::string w32 = capture_wav(c, WavFormat::Pcm32);
  ASSERT_EQ(w32.size(), 44u + 20u);
  EXPECT_EQ(w32.substr(48, 4), std::string("\x00\x00\x00\x40", 4));  // 0.5 = 2^30
  EXPECT_EQ(w32.substr(56, 4), std::string("\x00\x00\x00\x80", 4));  // -1 = -2^31
  for (WavFormat f : {WavFormat::Pcm8, WavFormat::Pcm32, WavFormat::Float64}) {
    const Capture r = parse_capture_wav(capture_wav(c, f), "x.wav");
    ASSERT_EQ(r.samples.size(), c.samples.size());
    for (std::size_t i = 0; i < c.samples.size(); ++i) EXPECT_EQ(r.samples[i], c.samples[i]) << i;
  }
}

// simulate --write-captures, then decode every capture back: same code, same distance.
TEST(DecodeCli, DecodesSimulatedCapturesBackToTheSimulatedResults) {
  const testing_support::ScratchDir scratch("capture_rt", ::testing::TempDir());
  const std::string dir = scratch.str();
  const std::string scene = dir + "/rt.yaml";
  write(scene,
        "name: rt\ntransducers: {}\ngeometry:\n  distances_m: [0.25, 0.9]\nexcitation:\n  family: M1\n"
        "  codes: [3, 6]\nnoise:\n  noise_v: 0.002\n  seed: 11\n");
  const ToolRun sim = run_tool("simulate " + scene + " --out " + dir + "/out --write-captures --quiet --json");
  ASSERT_EQ(sim.status, 0) << sim.err;
  std::ifstream csv(dir + "/out/measurements.csv");
  std::string line;
  std::getline(csv, line);
  int checked = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> cell;
    std::stringstream ss(line);
    std::string x;
    while (std::getline(ss, x, ',')) cell.push_back(x);
    const double d = std::stod(cell[3]);
    const int code = std::stoi(cell[4]);
    const double tof = std::stod(cell[6]), rho = std::stod(cell[9]);
    const std::string stem = dir + "/out/captures/M1_" + std::to_string(std::lround(d * 1e3)) + "mm_r1_j" + std::to_string(code);
    for (const char* ext : {".csv", ".wav"}) {
      const ToolRun dec = run_tool("decode " + stem + ext + " --family M1 --json");
      ASSERT_EQ(dec.status, 0) << dec.err;
      const auto j = nlohmann::json::parse(dec.out);
      EXPECT_EQ(j["sample_rate"], 5e6);
      // The burst, and possibly a noise event that passed --min-rho: take the best rho.
      ASSERT_GE(j["detections"].size(), 1u) << dec.out;
      nlohmann::json det = j["detections"][0];
      for (const auto& x : j["detections"]) {
        if (x["rho"].get<double>() > det["rho"].get<double>()) det = x;
      }
      EXPECT_EQ(det["code"], code);
      // The same receiver on the same samples: the ToF agrees to a fraction of a sample
      // (the decoder's calibration uses the same transducers), rho to float rounding.
      EXPECT_NEAR(det["tof_s"].get<double>(), tof, 0.05 / 5e6) << stem << ext;
      EXPECT_NEAR(det["distance_m"].get<double>(), d, 1e-4);
      EXPECT_NEAR(det["rho"].get<double>(), rho, 1e-5);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 8);
  // 16-bit PCM of the same stream decodes too.
  const Capture c = read_capture(dir + "/out/captures/M1_900mm_r1_j6.wav");
  write(dir + "/pcm16.wav", capture_wav(c, WavFormat::Pcm16, 0.1));
  const ToolRun p16 = run_tool("decode " + dir + "/pcm16.wav --family M1 --json");
  ASSERT_EQ(p16.status, 0) << p16.err;
  EXPECT_EQ(nlohmann::json::parse(p16.out)["detections"][0]["code"], 6);
}

// A capture at 4 MS/s (a common scope rate that does not divide the 30 MHz receiver clock) is
// decoded: the receiver's clock moves to 36 MHz (the next multiple the board's PLL makes) with a warning on stderr, the code and distance
// are the simulated ones.
TEST(DecodeCli, ACaptureWhoseRateDoesNotDivideTheClockDecodes) {
  const testing_support::ScratchDir scratch("capture_4ms", ::testing::TempDir());
  const std::string dir = scratch.str();
  write(dir + "/s.yaml", "name: r4\nsample_rate: 4000000\ntransducers: {}\ngeometry:\n  distances_m: [0.6]\n"
                         "excitation:\n  family: Gold4\n  codes: [5]\nnoise:\n  noise_v: 0.002\n");
  const ToolRun sim = run_tool("simulate " + dir + "/s.yaml --out " + dir + "/out --write-captures --quiet --json");
  ASSERT_EQ(sim.status, 0) << sim.err;
  EXPECT_NE(sim.err.find("the receiver's clock is 36 MHz (9 clocks per sample"), std::string::npos) << sim.err;
  const ToolRun dec = run_tool("decode " + dir + "/out/captures/Gold4_600mm_r1_j5.wav --family Gold4 --json");
  ASSERT_EQ(dec.status, 0) << dec.err;
  EXPECT_NE(dec.err.find("the receiver's clock is 36 MHz"), std::string::npos) << dec.err;
  const auto j = nlohmann::json::parse(dec.out);
  EXPECT_EQ(j["sample_rate"], 4e6);
  ASSERT_GE(j["detections"].size(), 1u) << dec.out;
  EXPECT_EQ(j["detections"][0]["code"], 5);
  EXPECT_NEAR(j["detections"][0]["distance_m"].get<double>(), 0.6, 1e-3);
}

TEST(DecodeCli, BadCapturesExitTwoWithAClearMessageAndNoOutput) {
  const testing_support::ScratchDir scratch("capture_bad", ::testing::TempDir());
  const std::string dir = scratch.str();
  std::string ok = "TIME,CH1\n";
  for (int n = 0; n < 3000; ++n) ok += sci(n * 2e-7) + "," + std::to_string(std::sin(n * 0.25)) + "\n";
  Capture c;
  c.sample_rate = 5e6;
  c.samples.assign(5000, 0.1);
  const std::string wav = capture_wav(c, WavFormat::Pcm16);
  struct Case {
    std::string name, content, args, expect;
  };
  const std::vector<Case> cases = {
      {"empty.csv", "", "--family M1", "empty.csv:0: no data rows"},
      {"cell.csv", "TIME,CH1\n0,0\n2e-7,x1\n", "--family M1", "cell.csv:3: voltage column: 'x1' is not a number"},
      {"nan.csv", "TIME,CH1\n0,0\n2e-7,NaN\n", "--family M1", "nan.csv:3: voltage column: 'NaN' is not finite"},
      {"inf.csv", "TIME,CH1\n0,0\n2e-7,-inf\n", "--family M1", "inf.csv:3:"},
      {"back.csv", "TIME,CH1\n0,0\n2e-7,0\n1e-7,0\n", "--family M1", "back.csv:4: time does not increase"},
      {"uneven.csv", "TIME,CH1\n0,0\n2e-7,0\n4e-7,0\n7e-7,0\n8e-7,0\n", "--family M1", "uneven.csv:5: uneven sampling"},
      {"short.csv", "TIME,CH1\n0,0\n2e-7,0\n4e-7,0.1\n", "--family M1", "short.csv: too short"},
      {"trunc.wav", wav.substr(0, 3000), "--family M1", "trunc.wav: byte 36: truncated"},
      {"family.csv", ok, "--family M9", "option --family: unknown code family 'M9'"},
      {"rate.csv", ok, "--family M1", ""},  // sanity: the good file decodes (exit 0 or 1, not 2)
      {"ext.txt", ok, "--family M1", "ext.txt: unknown capture type '.txt'; valid: .csv"},
      {"noext", ok, "--family M1", "noext: has no file extension; valid: .csv"},
      {"dir.csv.d", ok, "--family M1", "dir.csv.d: unknown capture type '.d'"},
  };
  for (const auto& k : cases) {
    write(dir + "/" + k.name, k.content);
    const auto before = std::distance(fs::directory_iterator(dir), fs::directory_iterator{});
    const ToolRun r = run_tool("decode " + dir + "/" + k.name + " " + k.args);
    SCOPED_TRACE(k.name + ": " + r.err);
    const auto after = std::distance(fs::directory_iterator(dir), fs::directory_iterator{});
    EXPECT_EQ(before, after) << "no files left behind";
    if (k.expect.empty()) {
      EXPECT_TRUE(r.status == 0 || r.status == 1) << r.status;
      continue;
    }
    EXPECT_EQ(r.status, 2);
    EXPECT_TRUE(r.out.empty());
    EXPECT_NE(r.err.find(k.expect), std::string::npos);
  }
  // The capture's pass runs beside the receiver's setup (decode): when both fail, the capture's
  // error is the one reported (as when the pass came first), at any --jobs.
  {
    Capture f = c;
    f.samples[4321] = std::numeric_limits<double>::infinity();
    write(dir + "/inf32.wav", capture_wav(f, WavFormat::Float32));
    for (const char* jobs : {"1", "2"}) {
      const ToolRun r = run_tool("decode " + dir + "/inf32.wav --family M9 --jobs " + jobs);
      EXPECT_EQ(r.status, 2) << jobs;
      EXPECT_TRUE(r.out.empty()) << jobs;
      EXPECT_NE(r.err.find("inf32.wav: byte "), std::string::npos) << r.err;
      EXPECT_NE(r.err.find("sample 4321 is not finite"), std::string::npos) << r.err;
      EXPECT_EQ(r.err.find("unknown code family"), std::string::npos) << r.err;
    }
  }
  // A sample rate the receiver cannot use (4.9 MS/s: 24.5 samples per carrier cycle).
  std::string odd = "TIME,CH1\n";
  for (int n = 0; n < 3000; ++n) odd += sci(n / 4.9e6) + ",0.01\n";
  write(dir + "/odd.csv", odd);
  const ToolRun r = run_tool("decode " + dir + "/odd.csv --family M1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("integer >= 4"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("; the nearest are 4.8 and 5 MS/s"), std::string::npos) << r.err;
  // every example rate the message gives is one the receiver takes (it once offered 2.5 MS/s,
  // 12.5 samples per cycle)
  const auto eg = r.err.find("(e.g. "), end = r.err.find(" MS/s)", eg);
  ASSERT_NE(eg, std::string::npos) << r.err;
  ASSERT_NE(end, std::string::npos) << r.err;
  std::string list = r.err.substr(eg + 6, end - eg - 6);
  for (auto& ch : list) ch = (ch == ',' ? ' ' : ch);
  std::istringstream words(list);
  int examples = 0;
  for (std::string w; words >> w;) {
    if (w == "or") continue;
    const double per_cycle = std::stod(w) * 1e6 / 200e3;
    EXPECT_EQ(per_cycle, std::round(per_cycle)) << w << " MS/s in: " << r.err;
    EXPECT_GE(per_cycle, 4.0) << w << " MS/s in: " << r.err;
    ++examples;
  }
  EXPECT_GE(examples, 3) << r.err;
}

// Captures carry their metadata (issue 14, section 5): decode uses it unless an option
// overrides it, and says which it used.
TEST(DecodeCli, SimulatedCaptureMetadataGivesTheRightDistanceWithDefaultOptions) {
  const testing_support::ScratchDir scratch("capture_meta", ::testing::TempDir());
  const std::string dir = scratch.str();
  // Air at 25 C: c = 346.4 m/s, not decode's default 340 (1.9 % = 19 mm at 1 m).
  write(dir + "/m.yaml",
        "name: meta\nmedium: {temperature_c: 25, relative_humidity: 50, pressure_kpa: 101.325}\n"
        "transducers: {}\ngeometry:\n  distances_m: [1.0]\nexcitation:\n  family: Gold4\n  codes: [5]\n"
        "noise:\n  noise_v: 0.002\n  seed: 4\n");
  const ToolRun sim = run_tool("simulate " + dir + "/m.yaml --out " + dir + "/out --write-captures --quiet --json");
  ASSERT_EQ(sim.status, 0) << sim.err;
  const double c = nlohmann::json::parse(sim.out)["speed_of_sound"].get<double>();
  ASSERT_GT(c, 345.0);
  const std::string stem = dir + "/out/captures/Gold4_1000mm_r1_j5";
  const Capture k = read_capture(stem + ".csv");
  ASSERT_TRUE(k.meta.speed_of_sound && k.meta.family && k.meta.code_sent && k.meta.true_distance_m && k.meta.scene);
  EXPECT_EQ(*k.meta.family, "Gold4");
  EXPECT_EQ(*k.meta.code_sent, 5);
  EXPECT_EQ(*k.meta.scene, "meta");
  EXPECT_NEAR(*k.meta.speed_of_sound, c, 1e-9 * c);
  EXPECT_DOUBLE_EQ(*k.meta.true_distance_m, 1.0);
  for (const char* ext : {".csv", ".wav"}) {
    SCOPED_TRACE(ext);
    const ToolRun dec = run_tool("decode " + stem + ext + " --json");  // no --family, no c
    ASSERT_EQ(dec.status, 0) << dec.err;
    const auto j = nlohmann::json::parse(dec.out);
    EXPECT_NE(j["speed_of_sound_source"].get<std::string>().find("capture metadata"), std::string::npos);
    EXPECT_NE(j["family_source"].get<std::string>().find("capture metadata"), std::string::npos);
    EXPECT_NEAR(j["speed_of_sound"].get<double>(), c, 1e-9 * c);
    ASSERT_EQ(j["detections"].size(), 1u) << dec.out;
    EXPECT_EQ(j["detections"][0]["code"], 5);
    EXPECT_NEAR(j["detections"][0]["distance_m"].get<double>(), 1.0, 1e-3);
    EXPECT_GT(j["detections"][0]["u"].get<double>(), 0.0);  // eq. 10 with the code the metadata names
    // An option overrides the metadata, and says so: 340 m/s puts it ~18 mm short.
    const ToolRun o = run_tool("decode " + stem + ext + " --json --speed-of-sound 340");
    ASSERT_EQ(o.status, 0) << o.err;
    const auto jo = nlohmann::json::parse(o.out);
    EXPECT_EQ(jo["speed_of_sound_source"], "option --speed-of-sound");
    EXPECT_LT(jo["detections"][0]["distance_m"].get<double>(), 0.99);
  }
  // Text mode names the sources on stderr.
  const ToolRun t = run_tool("decode " + stem + ".wav");
  EXPECT_EQ(t.status, 0);
  EXPECT_NE(t.err.find("from capture metadata"), std::string::npos) << t.err;
  // A bad sidecar is refused with file and key.
  write(dir + "/out/captures/Gold4_1000mm_r1_j5.json", "{\"speed_of_sound\": 5}");
  const ToolRun bad = run_tool("decode " + stem + ".wav");
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(bad.out.empty());
  EXPECT_NE(bad.err.find("Gold4_1000mm_r1_j5.json: key speed_of_sound"), std::string::npos) << bad.err;
}

// Several channels (an oscilloscope's CH1..CHn columns, a multi-channel WAV): --channel N
// reads one; the file's count is reported; a channel the file lacks is refused.
namespace {

// A 16-bit PCM WAV of interleaved channels (frame i: ch[0][i], ch[1][i], ...).
std::string wav16(const std::vector<std::vector<double>>& ch, std::uint32_t rate) {
  const std::size_t n = ch[0].size(), c = ch.size();
  std::string out;
  auto put = [&](std::uint64_t v, int b) {
    for (int i = 0; i < b; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  const auto data = static_cast<std::uint32_t>(n * c * 2);
  out += "RIFF";
  put(36 + data, 4);
  out += "WAVEfmt ";
  put(16, 4);
  put(1, 2);
  put(c, 2);
  put(rate, 4);
  put(rate * c * 2, 4);
  put(c * 2, 2);
  put(16, 2);
  out += "data";
  put(data, 4);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < c; ++k) {
      put(static_cast<std::uint64_t>(static_cast<std::int64_t>(std::lround(ch[k][i] * 32768.0))), 2);
    }
  }
  return out;
}

}  // namespace

TEST(Capture, ChannelsOfAMultiColumnCsvAndAMultiChannelWav) {
  // CSV: time, three channels, each separator style; column N + 1 is channel N.
  for (const char* sep : {",", ";", "\t", "  "}) {
    SCOPED_TRACE(std::string("separator '") + sep + "'");
    std::string text = "TIME" + std::string(sep) + "CH1" + sep + "CH2" + sep + "CH3\n";
    for (int n = 0; n < 6; ++n) {
      text += sci(n * 2e-7) + sep + sci(0.001 * n) + sep + sci(-0.25 * n) + sep + sci(7.0 + n) + "\n";
    }
    for (int ch = 1; ch <= 3; ++ch) {
      const Capture c = parse_capture_csv(text, "scope.csv", {.channel = ch});
      EXPECT_EQ(c.channel, ch);
      EXPECT_EQ(c.channels, 3);
      ASSERT_EQ(c.samples.size(), 6u);
      for (int n = 0; n < 6; ++n) {
        const double want = ch == 1 ? 0.001 * n : ch == 2 ? -0.25 * n : 7.0 + n;
        EXPECT_DOUBLE_EQ(c.samples[static_cast<std::size_t>(n)], want) << "channel " << ch << " row " << n;
      }
    }
    try {
      (void)parse_capture_csv(text, "scope.csv", {.channel = 4});
      ADD_FAILURE() << "channel 4 of a 3-channel CSV was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("scope.csv:2: channel 4"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("valid 1..3"), std::string::npos) << e.what();
    }
  }
  // A row shorter than the channel read is refused at its line; one channel 1 does not need is fine.
  const std::string ragged = "0,1,2\n2e-7,3\n4e-7,5,6\n";
  EXPECT_EQ(parse_capture_csv(ragged, "r.csv", {.channel = 1}).samples.size(), 3u);
  try {
    (void)parse_capture_csv(ragged, "r.csv", {.channel = 2});
    ADD_FAILURE() << "a row without channel 2 was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("r.csv:2: channel 2"), std::string::npos) << e.what();
  }
  EXPECT_EQ(parse_capture_csv("0,1,nan\n2e-7,3,4\n", "n.csv", {.channel = 1}).samples.size(), 2u);  // channel 1 ignores column 3
  try {
    (void)parse_capture_csv("0,1,nan\n2e-7,3,4\n", "n.csv", {.channel = 2});
    ADD_FAILURE() << "NaN in channel 2 was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("n.csv:1: channel 2 column: 'nan' is not finite"), std::string::npos)
        << e.what();
  }

  // WAV: three interleaved 16-bit channels.
  std::vector<std::vector<double>> ch(3);
  for (int n = 0; n < 50; ++n) {
    ch[0].push_back(0.5 * std::sin(0.3 * n));
    ch[1].push_back(-0.25);
    ch[2].push_back(n / 64.0);
  }
  const std::string bytes = wav16(ch, 5000000);
  for (int k = 1; k <= 3; ++k) {
    const Capture c = parse_capture_wav(bytes, "daq.wav", {.channel = k});
    EXPECT_EQ(c.channels, 3);
    EXPECT_EQ(c.channel, k);
    ASSERT_EQ(c.samples.size(), 50u);
    for (std::size_t n = 0; n < 50; ++n) {
      EXPECT_NEAR(c.samples[n], ch[static_cast<std::size_t>(k - 1)][n], 1.0 / 32768) << "channel " << k;
    }
  }
  try {
    (void)parse_capture_wav(bytes, "daq.wav", {.channel = 4});
    ADD_FAILURE() << "channel 4 of a 3-channel WAV was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("daq.wav: byte 36: channel 4 is out of range"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("valid 1..3"), std::string::npos) << e.what();
  }
}

// decode --channel: the burst is on channel 2, channel 1 holds only noise. The default reads
// channel 1 and finds nothing (and says which channel of how many it read); --channel 2 finds
// the bursts; the JSON carries both; a channel the file lacks exits 2 with nothing on stdout.
TEST(DecodeCli, ChannelPicksTheColumnOrWavChannelThatHoldsTheSignal) {
  const testing_support::ScratchDir scratch("capture_channel", ::testing::TempDir());
  const std::string dir = scratch.str();
  write(dir + "/m.yaml",
        "name: chan\ntransducers: {}\ngeometry:\n  distances_m: [0.5]\nexcitation:\n  family: M1\n  codes: [2]\n"
        "noise:\n  noise_v: 0.001\n  seed: 3\n");
  const ToolRun sim = run_tool("simulate " + dir + "/m.yaml --out " + dir + "/out --write-captures --quiet");
  ASSERT_EQ(sim.status, 0) << sim.err;
  const Capture k = read_capture(dir + "/out/captures/M1_500mm_r1_j2.wav");
  double peak = 0;
  for (double v : k.samples) peak = std::max(peak, std::abs(v));
  ASSERT_GT(peak, 0.0);
  std::vector<std::vector<double>> ch(2);
  unsigned s = 12345;
  for (double v : k.samples) {
    s = s * 1103515245u + 12345u;
    ch[0].push_back(0.01 * ((s >> 16) % 2001 - 1000.0) / 1000.0);  // noise only
    ch[1].push_back(0.5 * v / peak);
  }
  write(dir + "/two.wav", wav16(ch, static_cast<std::uint32_t>(k.sample_rate)));
  std::string csv = "TIME,CH1,CH2\n";
  for (std::size_t n = 0; n < ch[0].size(); ++n) {
    csv += sci(static_cast<double>(n) / k.sample_rate) + "," + sci(ch[0][n]) + "," + sci(ch[1][n]) + "\n";
  }
  write(dir + "/two.csv", csv);
  for (const char* ext : {".wav", ".csv"}) {
    SCOPED_TRACE(ext);
    const std::string f = dir + "/two" + ext;
    const ToolRun one = run_tool("decode " + f + " --family M1");
    EXPECT_EQ(one.status, 1) << one.out << one.err;  // noise on channel 1: no burst passes the gate
    EXPECT_NE(one.out.find("channel 1 of 2"), std::string::npos) << one.out;
    const ToolRun two = run_tool("decode " + f + " --family M1 --channel 2 --json");
    ASSERT_EQ(two.status, 0) << two.err;
    const auto j = nlohmann::json::parse(two.out);
    EXPECT_EQ(j["channel"], 2);
    EXPECT_EQ(j["channels"], 2);
    ASSERT_EQ(j["detections"].size(), 1u) << two.out;
    EXPECT_EQ(j["detections"][0]["code"], 2);
    EXPECT_NEAR(j["detections"][0]["distance_m"].get<double>(), 0.5, 2e-3);
    const ToolRun bad = run_tool("decode " + f + " --family M1 --channel 3");
    EXPECT_EQ(bad.status, 2);
    EXPECT_TRUE(bad.out.empty()) << bad.out;
    EXPECT_NE(bad.err.find("channel 3"), std::string::npos) << bad.err;
    EXPECT_NE(bad.err.find("valid 1..2"), std::string::npos) << bad.err;
  }
}

// A given sample rate: a CSV of one column of samples (numpy.savetxt of an array) reads at it
// from t = 0; without one it is refused, saying how to give it; a CSV with a time column refuses
// one (its time sets the rate); a WAV's header rate is replaced by it.
TEST(Capture, AGivenSampleRateReadsACsvOfSamplesAloneAndReplacesAWavHeadersRate) {
  std::string one = "# numpy.savetxt header\n";
  for (int n = 0; n < 40; ++n) one += sci(0.01 * std::sin(0.7 * n)) + "\n";
  const Capture c = parse_capture_csv(one, "one.csv", {.sample_rate = 2.5e6});
  EXPECT_EQ(c.sample_rate, 2.5e6);
  EXPECT_EQ(c.t0, 0.0);
  EXPECT_EQ(c.channels, 1);
  EXPECT_EQ(c.file_rate, 0.0);
  ASSERT_EQ(c.samples.size(), 40u);
  for (int n = 0; n < 40; ++n) EXPECT_NEAR(c.samples[static_cast<std::size_t>(n)], 0.01 * std::sin(0.7 * n), 1e-11);
  auto refused = [](const std::string& text, const CaptureRead& how, const std::string& want) {
    try {
      (void)parse_capture_csv(text, "x.csv", how);
      ADD_FAILURE() << "accepted; expected: " << want;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
    }
  };
  refused(one, {}, "x.csv:2: expected 'time,voltage', found one column (a CSV of samples alone is read with its "
                   "sample rate given");
  refused(one, {.channel = 2, .sample_rate = 2.5e6}, "x.csv:2: channel 2 is out of range: the rows have 1 channel");
  refused("0.1\n0.2\n0.3,0.4\n", {.sample_rate = 1e6}, "x.csv:3: expected one column of samples (as the first data row), found 2");
  refused("0.1\nnan\n", {.sample_rate = 1e6}, "x.csv:2: sample: 'nan' is not finite");
  refused("0,0.1\n2e-7,0.2\n", {.sample_rate = 5e6}, "x.csv:1: a sample rate (5000000 Hz) was given, but the rows have a time column");
  // WAV: the header says 44.1 kHz (a placeholder); the given rate replaces it, the samples are the same.
  Capture w;
  w.sample_rate = 44100;
  w.samples = {0.1, -0.2, 0.3, -0.4};
  const std::string bytes = capture_wav(w, WavFormat::Float32);
  const Capture a = parse_capture_wav(bytes, "w.wav");
  const Capture b = parse_capture_wav(bytes, "w.wav", {.sample_rate = 5e6});
  EXPECT_EQ(a.sample_rate, 44100.0);
  EXPECT_EQ(b.sample_rate, 5e6);
  EXPECT_EQ(b.file_rate, 44100.0);
  EXPECT_EQ(a.samples, b.samples);
}

// decode --sample-rate: the simulated capture written as numpy.savetxt writes an array decodes to
// the same detection as the capture itself; the catalogue's refusals are in test_bad_input.
TEST(DecodeCli, ACsvOfSamplesAloneDecodesWithItsSampleRateGiven) {
  const testing_support::ScratchDir scratch("capture_rate", ::testing::TempDir());
  const std::string dir = scratch.str();
  write(dir + "/m.yaml",
        "name: rate\ntransducers: {}\ngeometry:\n  distances_m: [0.7]\nexcitation:\n  family: M1\n  codes: [1]\n"
        "noise:\n  noise_v: 0.001\n  seed: 5\n");
  const ToolRun sim = run_tool("simulate " + dir + "/m.yaml --out " + dir + "/out --write-captures --quiet");
  ASSERT_EQ(sim.status, 0) << sim.err;
  const Capture k = read_capture(dir + "/out/captures/M1_700mm_r1_j1.csv");
  std::string one;
  for (double v : k.samples) one += sci(v) + "\n";
  write(dir + "/one.csv", one);
  const ToolRun ref = run_tool("decode " + dir + "/out/captures/M1_700mm_r1_j1.csv --family M1 --json");
  const ToolRun got = run_tool("decode " + dir + "/one.csv --family M1 --json --sample-rate " + sci(k.sample_rate));
  ASSERT_EQ(ref.status, 0) << ref.err;
  ASSERT_EQ(got.status, 0) << got.err;
  const auto jr = nlohmann::json::parse(ref.out), jg = nlohmann::json::parse(got.out);
  EXPECT_EQ(jg["sample_rate_source"], "option --sample-rate");
  EXPECT_EQ(jr["sample_rate_source"], "capture file");
  ASSERT_EQ(jg["detections"].size(), 1u) << got.out;
  ASSERT_EQ(jr["detections"].size(), 1u) << ref.out;
  EXPECT_EQ(jg["detections"][0]["code"], 1);
  // the simulated capture starts at t = 0 too, so the times agree exactly
  EXPECT_EQ(jg["detections"][0]["tof_s"], jr["detections"][0]["tof_s"]);
}

// A capture at 1 MS/s (5 samples per 200 kHz cycle): the receiver cannot decode a noise-free
// burst there, so decode refuses (exit 2, nothing on stdout) naming the rate and what to change.
TEST(DecodeCli, ARateTooLowForTheReceiverIsRefusedNamingTheRate) {
  const testing_support::ScratchDir scratch("capture_1ms", ::testing::TempDir());
  const std::string dir = scratch.str();
  Capture c;
  c.sample_rate = 1e6;
  for (int n = 0; n < 20000; ++n) c.samples.push_back(0.01 * std::sin(0.37 * n * n));
  write(dir + "/slow.wav", capture_wav(c, WavFormat::Pcm16));
  const ToolRun r = run_tool("decode " + dir + "/slow.wav --family Gold4");
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("slow.wav: calibration:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(1 MS/s, 5 samples per carrier cycle); lower receiver.threshold, raise the sample rate"),
            std::string::npos)
      << r.err;
}

// The CSV reader's numbers (a fast path through std::from_chars, strtod for the rest) are
// strtod's: the same value to the bit, and refused exactly when strtod does not read the whole
// cell or reports ERANGE.
TEST(Capture, CsvNumbersAreReadExactlyAsStrtodReadsThem) {
  const std::vector<std::string> cells = {
      "1.234567890e-03", "+1.5e-3", "-0.000000000e+00", "0", ".5", "1.", "1.e5", "-.5E-3", "0x1p-3",
      "1e-310", "4.9e-324", "2.2250738585072014e-308", "1.7976931348623157e308", "1e309", "9007199254740993",
      "1.00000000000000011102230246251565404236316680908203125", "1e", "1e+", "12abc", "0x", "infinity", "-nan",
      "-0", "000.000", "-0e-400", "0.0e+999", "-0.00000000000000000000000", "0e", "-0x1p+2", "00x5", "0.0x1"};
  const testing_support::ScratchDir scratch("capture_num", ::testing::TempDir());
  for (const auto& s : cells) {
    SCOPED_TRACE(s);
    errno = 0;
    char* end = nullptr;
    const double want = std::strtod(s.c_str(), &end);
    const bool ok = end == s.c_str() + s.size() && errno != ERANGE && std::isfinite(want);
    const std::string text = "0," + s + "\n2e-7," + s + "\n4e-7,0\n";
    try {
      const Capture c = parse_capture_csv(text, "n.csv");
      ASSERT_TRUE(ok) << "read a cell strtod refuses";
      EXPECT_EQ(std::memcmp(&c.samples[0], &want, sizeof want), 0) << c.samples[0] << " != " << want;
      // the streamed reader's value (csv_row_value) too
      const fs::path p = scratch.path() / "num.csv";
      write(p.string(), text);
      CaptureSource src(p.string());
      std::vector<double> buf(3);
      ASSERT_EQ(src.read(buf), 3u);
      EXPECT_EQ(std::memcmp(&buf[1], &want, sizeof want), 0);
    } catch (const InputError& e) {
      EXPECT_FALSE(ok) << "refused a cell strtod reads: " << e.what();
    }
  }
}

// The numbers of real exports (and many that are not): random doubles of every magnitude printed
// as %.Ne, %.NE, %.Nf, %.Ng with 0..20 digits, negative, with '+' exponents, short mantissas,
// 19- and 20-digit integers, and 2^53 +- 1: the CSV's value is strtod's, bit for bit (the rows'
// time cells are the plain grid).
TEST(Capture, RandomCsvNumbersAreReadExactlyAsStrtodReadsThem) {
  std::mt19937_64 rng(11);
  std::vector<std::string> cells = {"9007199254740992", "9007199254740993", "9007199254740991", "1234567890123456789",
                                    "12345678901234567890", "0.1e-22", "1e22", "1e23", "1e-22", "1e-23", "-1.5E+3",
                                    "0.000000000000000000001", "2.2250738585072014e-308"};
  char buf[96];
  for (int i = 0; i < 20000; ++i) {
    const double mag = std::ldexp(std::uniform_real_distribution<double>(0.5, 1.0)(rng),
                                  std::uniform_int_distribution<int>(-120, 120)(rng));
    const double v = (rng() & 1) ? -mag : mag;
    const int prec = std::uniform_int_distribution<int>(0, 20)(rng);
    const char* fmt[] = {"%.*e", "%.*E", "%.*f", "%.*g"};
    std::snprintf(buf, sizeof buf, fmt[rng() % 4], prec, v);
    cells.emplace_back(buf);
  }
  // A scope's %.9e (read in one go when its exponent has two digits): decimal exponents -120..120,
  // so every side of the fast path's |k| <= 22 (exponents -13..31) and three-digit exponents.
  for (int i = 0; i < 20000; ++i) {
    const double v = std::uniform_real_distribution<double>(1.0, 10.0)(rng) *
                     std::pow(10.0, std::uniform_int_distribution<int>(-120, 120)(rng));
    std::snprintf(buf, sizeof buf, (rng() & 1) ? "%.9e" : "%.9E", (rng() & 1) ? -v : v);
    cells.emplace_back(buf);
  }
  for (const char* edge : {"0.000000000e+00", "-0.000000000e+00", "9.999999999e+31", "9.999999999e+32", "1.000000000e-13",
                           "1.000000000e-14", "9.007199254e+15", "1.234567890e+05", "1.234567890e+5", "1.234567890e+051"}) {
    cells.emplace_back(edge);
  }
  std::string text;
  for (std::size_t n = 0; n < cells.size(); ++n) text += std::to_string(n) + "," + cells[n] + "\n";
  const Capture c = parse_capture_csv(text, "r.csv", {});
  ASSERT_EQ(c.samples.size(), cells.size());
  const testing_support::ScratchDir scratch("capture_rnd", ::testing::TempDir());
  const fs::path p = scratch.path() / "rnd.csv";
  write(p.string(), text);
  CaptureSource src(p.string());
  std::vector<double> streamed(cells.size());
  ASSERT_EQ(src.read(streamed), cells.size());
  for (std::size_t n = 0; n < cells.size(); ++n) {
    const double want = std::strtod(cells[n].c_str(), nullptr);
    EXPECT_EQ(std::memcmp(&c.samples[n], &want, sizeof want), 0) << cells[n];
    EXPECT_EQ(std::memcmp(&streamed[n], &want, sizeof want), 0) << cells[n];
  }
}
