// Streaming decode (issue 13): SceneSimulator::decode_stream over a capture read in blocks
// (CaptureSource) gives the very detections of decode() over the whole file, for WAV and CSV,
// float and fixed receivers, with blocks that split bursts, T_d searches and the metrics
// window anywhere; `ranging decode --block-samples` prints the same JSON at any block size;
// CaptureSource refuses what read_capture refuses, with the same message.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <limits>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "model/base/error.hpp"
#include "model/sim/capture.hpp"
#include "model/sim/capture_stream.hpp"
#include "model/sim/scene.hpp"
#include "model/sim/scene_simulator.hpp"
#include "tests/process.hpp"
#include "tests/scratch.hpp"

using namespace ranging;
namespace fs = std::filesystem;

namespace {

// Shared by the tests; removed at exit.
fs::path temp_dir() {
  static const testing_support::ScratchDir d("ranging_stream");
  return d.path();
}

// A periodic Gold4 train at 0.3 m with noise (bursts every 0.002 s, 10 bursts, ~110 k samples).
Capture train_capture() {
  const std::string y =
      "medium:\n  temperature_c: 20\ntransducers: {}\ngeometry:\n  distances_m: [0.3]\nexcitation:\n"
      "  family: Gold4\n  schedule:\n    mode: periodic\n    period_s: 0.002\n    bursts: 10\n"
      "noise:\n  noise_v: 0.01\n  seed: 3\nreceiver:\n  precision: float\n";
  SceneSimulator sim(parse_scene(y, "train.yaml"));
  Capture c;
  (void)sim.run("Gold4", {}, [&](const CaptureStream& s) {
    c.sample_rate = s.fs;
    c.samples = *s.volts;
  });
  c.meta.family = "Gold4";
  c.meta.period_s = 0.002;
  c.meta.code_sent = 0;
  c.meta.speed_of_sound = sim.scene().speed();
  return c;
}

const Capture& capture() {
  static const Capture c = train_capture();
  return c;
}

std::string write(const std::string& name, const std::string& bytes) {
  const fs::path p = temp_dir() / name;
  std::ofstream(p, std::ios::binary) << bytes;
  return p.string();
}

Scene decode_scene(const std::string& precision) {
  return parse_scene("name: decode\nsample_rate: 5000000\nmedium:\n  speed_of_sound: 343\ntransducers: {}\n"
                     "geometry:\n  distances_m: [1.0]\nexcitation:\n  family: Gold4\nreceiver:\n  precision: " +
                         precision + "\n",
                     "decode.yaml");
}

void expect_same(const std::vector<Detection>& a, const std::vector<Detection>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    SCOPED_TRACE("detection " + std::to_string(i));
    EXPECT_EQ(a[i].code, b[i].code);
    EXPECT_EQ(a[i].arrival_s, b[i].arrival_s);  // bit for bit
    EXPECT_EQ(a[i].tof_s, b[i].tof_s);
    EXPECT_EQ(a[i].score, b[i].score);
    EXPECT_EQ(a[i].detector_margin, b[i].detector_margin);
    EXPECT_EQ(a[i].rho, b[i].rho);
    EXPECT_EQ(a[i].pearson_code, b[i].pearson_code);
    EXPECT_EQ(a[i].rho_max, b[i].rho_max);
    EXPECT_EQ(a[i].pearson_margin, b[i].pearson_margin);
    EXPECT_EQ(a[i].energy, b[i].energy);
    EXPECT_EQ(a[i].td_s, b[i].td_s);
    EXPECT_EQ(a[i].td_clipped, b[i].td_clipped);
    EXPECT_EQ(a[i].td_noise_limited, b[i].td_noise_limited);
  }
}

void check_file(const std::string& path, const std::string& precision) {
  const Capture whole = read_capture(path);
  SceneSimulator sim(decode_scene(precision));
  const auto ref = sim.decode("Gold4", whole.samples, whole.t0, 0.002);
  ASSERT_GE(ref.size(), 10u) << "every burst of the train is detected";
  std::size_t with_td = 0;
  for (const auto& d : ref) with_td += d.td_s > 0 && !d.rho.empty();
  EXPECT_GE(with_td, 10u);
  CaptureSource src(path);
  EXPECT_EQ(src.size(), whole.samples.size());
  EXPECT_EQ(src.sample_rate(), whole.sample_rate);
  EXPECT_EQ(src.t0(), whole.t0);
  double peak = 0;
  for (double v : whole.samples) peak = std::max(peak, std::abs(v));
  for (std::size_t block : {std::size_t{64}, std::size_t{997}, std::size_t{4096}, std::size_t{1} << 20}) {
    SCOPED_TRACE(path + ", " + precision + ", block " + std::to_string(block));
    expect_same(ref, sim.decode_stream("Gold4", src, 0.002, block));
    // The caller's peak and block scan (decode's clipping scan): the same detections, and the
    // scan sees every sample once, in order.
    std::vector<double> seen;
    expect_same(ref, sim.decode_stream("Gold4", src, 0.002, block, peak,
                                       [&](std::span<const double> x) { seen.insert(seen.end(), x.begin(), x.end()); }));
    EXPECT_EQ(seen, whole.samples);
  }
}

}  // namespace

TEST(StreamingDecode, WavEqualsWholeFileAtEveryBlockSize) {
  const std::string p = write("train.wav", capture_wav(capture(), WavFormat::Float32));
  check_file(p, "float");
  check_file(p, "fixed");
}

// The receiver runs with the bursts' metrics beside it on --jobs threads, a burst's metrics
// waiting until no later event can start before its T_d end (SceneSimulator::set_event_lookback).
// The same detections, bit for bit, at blocks that leave bursts pending across blocks (64: T_d
// searches retried) or none, on 1-3 threads. The derived bound holds: one pass. A bound that
// events break (negative: bursts settle before the events that end their T_d search, and
// samples leave the window before later bursts read them) must send the decode to its second
// pass, which recomputes the metrics with every event known: the same detections again.
TEST(StreamingDecode, ThreadsAndTheSecondPassGiveTheSameDetections) {
  const std::string p = write("jobs.wav", capture_wav(capture(), WavFormat::Float32));
  const Capture whole = read_capture(p);
  for (const std::string precision : {"float", "fixed"}) {
    SceneSimulator sim(decode_scene(precision));
    const auto ref = sim.decode("Gold4", whole.samples, whole.t0, 0.002);
    ASSERT_GE(ref.size(), 10u);
    CaptureSource src(p);
    for (std::optional<long> lookback : {std::optional<long>{}, std::optional<long>{-30000}}) {
      sim.set_event_lookback(lookback);
      for (int jobs : {1, 2, 3}) {
        sim.set_jobs(jobs);
        for (std::size_t block : {std::size_t{64}, std::size_t{997}, std::size_t{1} << 20}) {
          SCOPED_TRACE(precision + ", lookback " + (lookback ? std::to_string(*lookback) : "derived") + ", jobs " +
                       std::to_string(jobs) + ", block " + std::to_string(block));
          // the blocks: min(block, kDecodeFirstBlock), then each twice the last up to `block`
          std::vector<std::size_t> sizes, expected;
          for (std::size_t left = whole.samples.size(), b = std::min(block, SceneSimulator::kDecodeFirstBlock); left > 0;
               b = std::min(block, 2 * b)) {
            expected.push_back(std::min(b, left));
            left -= expected.back();
          }
          expect_same(ref, sim.decode_stream("Gold4", src, 0.002, block, {},
                                             [&](std::span<const double> x) { sizes.push_back(x.size()); }));
          EXPECT_EQ(sizes, expected) << "the scan sees each block once";
          // one block holds every event before any burst settles: nothing to break then
          EXPECT_EQ(sim.decode_passes(), lookback && expected.size() > 1 ? 2 : 1);
        }
      }
    }
  }
}

// Scenes that name some metrics or none: the stream computes what decode() computes and leaves
// the rest NaN as it does (bitwise: NaN fields compare by their bits), with or without the
// window of the filtered stream, on 1 and 2 threads.
TEST(StreamingDecode, OnlyTheNamedMetricsAsDecodeComputesThem) {
  const std::string p = write("metrics.wav", capture_wav(capture(), WavFormat::Float32));
  const Capture whole = read_capture(p);
  auto bits = [](double v) {
    std::uint64_t u;
    std::memcpy(&u, &v, sizeof u);
    return u;
  };
  for (const char* metrics : {"[]", "[td]", "[energy]", "[pearson]", "[td, energy]"}) {
    for (const char* precision : {"float", "fixed"}) {
      SceneSimulator sim(parse_scene("name: decode\nsample_rate: 5000000\nmedium:\n  speed_of_sound: 343\ntransducers: {}\n"
                                     "geometry:\n  distances_m: [1.0]\nexcitation:\n  family: Gold4\nreceiver:\n  precision: " +
                                         std::string(precision) + "\n  metrics: " + metrics + "\n",
                                     "decode.yaml"));
      const auto ref = sim.decode("Gold4", whole.samples, whole.t0, 0.002);
      ASSERT_GE(ref.size(), 10u);
      CaptureSource src(p);
      for (int jobs : {1, 2}) {
        sim.set_jobs(jobs);
        for (std::size_t block : {std::size_t{997}, std::size_t{1} << 20}) {
          SCOPED_TRACE(std::string(metrics) + " " + precision + ", jobs " + std::to_string(jobs) + ", block " +
                       std::to_string(block));
          const auto got = sim.decode_stream("Gold4", src, 0.002, block);
          ASSERT_EQ(got.size(), ref.size());
          for (std::size_t i = 0; i < ref.size(); ++i) {
            EXPECT_EQ(got[i].arrival_s, ref[i].arrival_s);
            EXPECT_EQ(bits(got[i].td_s), bits(ref[i].td_s)) << i;
            EXPECT_EQ(bits(got[i].energy), bits(ref[i].energy)) << i;
            EXPECT_EQ(bits(got[i].rho_max), bits(ref[i].rho_max)) << i;
            EXPECT_EQ(got[i].rho, ref[i].rho) << i;
          }
          const bool named_td = std::string(metrics).find("td") != std::string::npos;
          EXPECT_EQ(std::isnan(got[0].td_s), !named_td);
        }
      }
    }
  }
}

// Captures with nothing to find: noise alone, silence, a stream shorter than a template, the
// first burst cut by the start: the stream's detections are decode()'s (none, or the same).
TEST(StreamingDecode, EmptyNoiseAndCutCapturesAsDecode) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> g(0, 0.01);
  std::vector<std::pair<std::string, std::vector<double>>> cases;
  cases.emplace_back("noise", std::vector<double>(60000));
  for (double& v : cases.back().second) v = g(rng);
  cases.emplace_back("silence", std::vector<double>(5000, 0.0));
  cases.emplace_back("short", std::vector<double>(capture().samples.begin(), capture().samples.begin() + 700));
  cases.emplace_back("cut", std::vector<double>(capture().samples.begin() + 2500, capture().samples.end()));
  for (const auto& [name, x] : cases) {
    Capture c;
    c.sample_rate = 5e6;
    c.samples = x;
    const std::string p = write(name + ".wav", capture_wav(c, WavFormat::Float64));
    for (const std::string precision : {"float", "fixed"}) {
      SceneSimulator sim(decode_scene(precision));
      const auto ref = sim.decode("Gold4", x, 0, 0.002);
      CaptureSource src(p);
      for (int jobs : {1, 2}) {
        sim.set_jobs(jobs);
        SCOPED_TRACE(name + " " + precision + ", jobs " + std::to_string(jobs));
        expect_same(ref, sim.decode_stream("Gold4", src, 0.002, 4096));
      }
    }
  }
}

TEST(StreamingDecode, Pcm16WavAndCsvEqualWholeFile) {
  check_file(write("train16.wav", capture_wav(capture(), WavFormat::Pcm16, 0.5)), "fixed");
  // the formats other simulators write (numpy int32 / float64, 8-bit audio)
  check_file(write("train32.wav", capture_wav(capture(), WavFormat::Pcm32, 0.5)), "fixed");
  check_file(write("train64.wav", capture_wav(capture(), WavFormat::Float64)), "float");
  check_file(write("train8.wav", capture_wav(capture(), WavFormat::Pcm8, 0.5)), "float");
  Capture c = capture();
  c.t0 = -2e-5;  // a scope's pre-trigger
  check_file(write("train.csv", capture_csv(c)), "float");
  // the same rows separated by ';' and by tabs (the stream reads the value as the scan splits)
  for (const char sep : {';', '\t'}) {
    std::string text = capture_csv(c);
    std::replace(text.begin(), text.end(), ',', sep);
    check_file(write(sep == ';' ? "train_semi.csv" : "train_tab.csv", text), "float");
  }
}

// The scan handed to the constructor (decode's peak) sees every sample once, in order, as
// read() gives it: in the validation pass (CSV, float WAV) or an extra read (PCM WAV).
TEST(StreamingDecode, TheOpenScanSeesTheSamplesReadGives) {
  Capture c = capture();
  c.samples.resize(9000);  // a few of the CSV's 4096-row scan blocks
  for (const char* name : {"scan.csv", "scan16.wav", "scan32f.wav", "scan64f.wav"}) {
    const std::string n = name;
    const std::string bytes = n.ends_with(".csv")  ? capture_csv(c)
                              : n == "scan16.wav" ? capture_wav(c, WavFormat::Pcm16, 0.5)
                              : n == "scan32f.wav" ? capture_wav(c, WavFormat::Float32)
                                                   : capture_wav(c, WavFormat::Float64);
    const std::string p = write(name, bytes);
    std::vector<double> seen;
    CaptureSource src(p, {}, [&](std::span<const double> x) { seen.insert(seen.end(), x.begin(), x.end()); });
    EXPECT_EQ(seen, read_capture(p).samples) << name;
    EXPECT_EQ(seen.size(), src.size()) << name;
  }
}

namespace {
// n samples at 1 MS/s, uniform in [-0.9, 0.9) from seed.
Capture uniform_capture(std::size_t n, std::uint64_t seed) {
  Capture c;
  c.sample_rate = 1e6;
  std::mt19937_64 rng(seed);
  c.samples.resize(n);
  for (double& v : c.samples) v = std::uniform_real_distribution<double>(-0.9, 0.9)(rng);
  return c;
}
}  // namespace

// The scan in parts (decode --jobs): a WAV's samples in consecutive runs of whole 65536-sample
// blocks, part p's before part p + 1's, each part's blocks in order and those of the one-part
// scan; more parts than blocks leave the rest unused. A CSV's rows are cut into byte ranges of
// whole lines (at least 64 KiB each; 70000 rows are 2.2 MB), each part's rows in blocks of at
// most 4096.
TEST(StreamingDecode, TheOpenScanInPartsSeesEveryBlockOnce) {
  const Capture c = uniform_capture(3 * 65536 + 1234, 5);
  Capture small = c;
  small.samples.resize(70000);
  const std::vector<std::pair<std::string, std::string>> files = {
      {"parts32f.wav", capture_wav(c, WavFormat::Float32)},
      {"parts16.wav", capture_wav(c, WavFormat::Pcm16, 1.0)},
      {"parts.csv", capture_csv(small)}};
  for (const auto& [name, bytes] : files) {
    const std::string p = write(name, bytes);
    const std::vector<double> whole = read_capture(p).samples;
    for (std::size_t parts : {1, 2, 3, 4, 9}) {
      std::vector<std::vector<std::vector<double>>> seen(parts);  // part -> its blocks (one thread each)
      CaptureSource src(
          p, {}, [&](std::size_t part, std::span<const double> x) { seen.at(part).emplace_back(x.begin(), x.end()); },
          parts);
      std::vector<double> all;
      std::vector<std::size_t> sizes;
      std::size_t used = 0;
      for (const auto& part : seen) {
        used += !part.empty();
        for (const auto& b : part) {
          sizes.push_back(b.size());
          all.insert(all.end(), b.begin(), b.end());
        }
      }
      EXPECT_EQ(all, whole) << name << " parts " << parts;
      if (name.ends_with(".wav")) {
        EXPECT_EQ(sizes, (std::vector<std::size_t>{65536, 65536, 65536, 1234})) << name << " parts " << parts;
        EXPECT_EQ(used, std::min<std::size_t>(parts, 4)) << name;
      } else {
        EXPECT_EQ(used, parts) << name;
        for (const std::size_t b : sizes) EXPECT_LE(b, 4096u) << name;
        if (parts == 1) {
          EXPECT_EQ(sizes.front(), 4096u) << "one part: the blocks of 4096 rows";
        }
      }
      std::vector<double> again(whole.size());  // the samples still read from the start
      EXPECT_EQ(src.read(again), whole.size());
      EXPECT_EQ(again, whole);
    }
  }
}

// A CSV opened in parts (each part's rows checked on a thread of its own; time must increase
// across the cuts too) accepts what read_capture accepts, with the same samples, rate and start,
// and refuses what it refuses with its message (the first error in the file, its line): bad
// cells, time that does not increase, an uneven grid, an empty line, at rows around every cut
// of 2, 3 and 4 parts, the first row after the header and the last; a truncated Record Length,
// a blank last line; valid: CRLF lines, no newline at the end, a 2.5 MB header line.
TEST(StreamingDecode, ACsvInPartsAcceptsAndRefusesAsOnePass) {
  const Capture c = uniform_capture(9000, 8);  // 290 kB: up to 4 parts
  const std::string text = capture_csv(c);
  std::vector<std::string> lines;
  for (std::size_t b = 0, e; (e = text.find('\n', b)) != std::string::npos; b = e + 1) lines.push_back(text.substr(b, e - b));
  const std::size_t head = lines.size() - c.samples.size();  // lines before the first data row
  auto join = [](const std::vector<std::string>& ls, const std::string& eol = "\n") {
    std::string t;
    for (const auto& l : ls) t += l + eol;
    return t;
  };
  auto time_cell = [&](std::size_t row) { return lines[head + row].substr(0, lines[head + row].find(',')); };
  std::vector<std::pair<std::string, std::string>> cases = {
      {"valid", text},
      {"crlf", join(lines, "\r\n")},
      {"no_final_newline", text.substr(0, text.size() - 1)},
      {"truncated", join(std::vector<std::string>(lines.begin(), lines.end() - 1))},
      {"blank_last_line", text + "\n"}};
  {
    std::vector<std::string> ls = lines;
    ls.insert(ls.begin() + 1, "Comment," + std::string(2500000, 'x'));
    cases.emplace_back("long_header_line", join(ls));
  }
  std::vector<std::size_t> rows = {1, c.samples.size() - 1};
  for (std::size_t np : {2, 3, 4}) {
    for (std::size_t p = 1; p < np; ++p) {
      const std::size_t r = 1 + (c.samples.size() - 1) * p / np;
      for (std::size_t k = r - 2; k <= r + 2; ++k) rows.push_back(k);
    }
  }
  for (const std::size_t k : rows) {
    const std::string at = std::to_string(k);
    auto edit = [&](const std::string& kind, const std::string& line) {
      std::vector<std::string> ls = lines;
      ls[head + k] = line;
      cases.emplace_back(kind + at, join(ls));
    };
    edit("bad_value", time_cell(k) + ",abc");
    edit("nan", time_cell(k) + ",nan");
    edit("trailing_text", time_cell(k) + ",0.5x");  // a number, then more in its cell
    edit("time_text", time_cell(k) + "s,0.5");
    edit("time_repeats", time_cell(k - 1) + ",0.5");
    char t[64];
    std::snprintf(t, sizeof t, "%.9e,0.5", (static_cast<double>(k) + 0.4) / c.sample_rate);
    edit("uneven", t);
    std::vector<std::string> ls = lines;
    ls.insert(ls.begin() + static_cast<std::ptrdiff_t>(head + k), "");
    cases.emplace_back("empty_line" + at, join(ls));
  }
  std::size_t refused = 0;
  for (const auto& [name, bytes] : cases) {
    const std::string p = write("cut_" + name + ".csv", bytes);
    std::string want;
    Capture whole;
    try {
      whole = read_capture(p);
    } catch (const InputError& e) {
      want = e.what();
    }
    refused += !want.empty();
    for (std::size_t parts : {1, 2, 3, 4})
    for (std::size_t keep : {std::size_t{0}, CaptureRead{}.csv_keep_rows}) {
      SCOPED_TRACE(name + ", parts " + std::to_string(parts) + ", keep " + std::to_string(keep));
      std::vector<std::vector<double>> seen(parts);
      std::string got;
      try {
        CaptureSource src(
            p, {.csv_keep_rows = keep}, [&](std::size_t part, std::span<const double> x) { seen.at(part).insert(seen[part].end(), x.begin(), x.end()); },
            parts);
        std::vector<double> all;
        for (const auto& s : seen) all.insert(all.end(), s.begin(), s.end());
        EXPECT_EQ(all, whole.samples);
        EXPECT_EQ(src.sample_rate(), whole.sample_rate);
        EXPECT_EQ(src.t0(), whole.t0);
        std::vector<double> again(whole.samples.size() + 1);
        EXPECT_EQ(src.read(again), whole.samples.size());
        again.pop_back();
        EXPECT_EQ(again, whole.samples);
      } catch (const InputError& e) {
        got = e.what();
      }
      EXPECT_EQ(got, want);
    }
  }
  EXPECT_EQ(refused, cases.size() - 4) << "every case but the 4 valid ones is refused";
  // A column of samples alone at a given rate (27000 rows, 270 kB): the same samples, or the
  // same refusal.
  std::string column;
  for (int r = 0; r < 3; ++r) {
    for (const double v : c.samples) column += std::to_string(v) + "\n";
  }
  const std::size_t mid = column.size() / 2;
  const std::size_t cut = column.find('\n', mid) + 1;
  for (const auto& [name, bytes] : std::vector<std::pair<std::string, std::string>>{
           {"column", column}, {"column_bad", column.substr(0, cut) + "x\n" + column.substr(cut)}}) {
    const std::string p = write(name + ".csv", bytes);
    const CaptureRead how{.channel = 1, .sample_rate = 1e6};
    std::string want, got;
    Capture whole;
    try {
      whole = read_capture(p, how);
    } catch (const InputError& e) {
      want = e.what();
    }
    EXPECT_EQ(want.empty(), name == "column") << want;
    for (std::size_t parts : {1, 2, 4}) {
      try {
        CaptureSource src(p, how, [](std::size_t, std::span<const double>) {}, parts);
        std::vector<double> all(whole.samples.size());
        EXPECT_EQ(src.read(all), whole.samples.size());
        EXPECT_EQ(all, whole.samples) << name << " parts " << parts;
        EXPECT_EQ(src.sample_rate(), 1e6);
      } catch (const InputError& e) {
        got = e.what();
      }
      EXPECT_EQ(got, want) << name << " parts " << parts;
    }
  }
}

// The open's quick reading of plain rows (a number right after each separator) and its general
// reading (spaces before or after, quotes, '+', '.5', tabs) mix in one file: every channel of a 3-channel CSV,
// with ',' or ';' and '\n' or "\r\n", rows of either kind anywhere (the first one too), gives
// strtod's value of each cell's number, through read_capture and CaptureSource in 1 to 4 parts
// (the scan and read() alike, read() from the values the open kept or from the file again).
TEST(StreamingDecode, PlainAndDecoratedRowsReadAsStrtodReadsThem) {
  const std::size_t n = 12000;  // ~0.6 MB: 4 parts
  std::mt19937_64 rng(11);
  for (const char sep : {',', ';'}) {
    for (const std::string eol : {"\n", "\r\n"}) {
      for (const int mixed : {0, 1}) {
        std::string text = std::string("TIME") + sep + "CH1" + sep + "CH2" + sep + "CH3" + eol;
        std::vector<std::vector<double>> want(3);
        for (std::size_t r = 0; r < n; ++r) {
          char t[32];
          std::snprintf(t, sizeof t, "%.9e", static_cast<double>(r) * 2e-7);
          std::string row = t;
          for (int ch = 0; ch < 3; ++ch) {
            char v[32];
            const double x = std::uniform_real_distribution<double>(-1, 1)(rng);
            std::snprintf(v, sizeof v, ch == 1 ? "%.17g" : "%.6e", x);
            std::string num = v;
            // decorated forms of the same number (general reading); kind 0 is plain
            const int kind = mixed && (r == 0 || rng() % 5 == 0) ? static_cast<int>(1 + rng() % 6) : 0;
            if (kind == 3 && num[0] != '-') num.insert(0, 1, '+');
            if (kind == 4 && num.rfind("0.", 0) == 0) num.erase(0, 1);  // ".123"
            if (kind == 4 && num.rfind("-0.", 0) == 0) num.erase(1, 1);  // "-.123"
            want[static_cast<std::size_t>(ch)].push_back(std::strtod(num.c_str(), nullptr));
            row += sep;
            if (kind == 1 || kind == 2 || kind == 5) row += kind == 1 ? ' ' : kind == 2 ? '"' : '\t';
            row += num;
            if (kind == 1 || kind == 2 || kind == 6) row += kind == 2 ? '"' : ' ';  // 6: a trailing space alone
          }
          text += row + eol;
        }
        const std::string name = std::string("mix_") + (sep == ',' ? "comma" : "semi") + (eol.size() == 2 ? "_crlf" : "") +
                                 (mixed ? "_mixed" : "_plain") + ".csv";
        const std::string p = write(name, text);
        for (int ch = 1; ch <= 3; ++ch) {
          const std::vector<double>& w = want[static_cast<std::size_t>(ch - 1)];
          SCOPED_TRACE(name + " channel " + std::to_string(ch));
          const Capture whole = read_capture(p, {.channel = ch});
          EXPECT_EQ(whole.samples, w);
          EXPECT_EQ(whole.sample_rate, 5e6);
          for (std::size_t parts : {1, 2, 3, 4})
          for (std::size_t keep : {std::size_t{0}, n, CaptureRead{}.csv_keep_rows}) {  // read() parses or serves
            SCOPED_TRACE("parts " + std::to_string(parts) + ", keep " + std::to_string(keep));
            std::vector<std::vector<double>> seen(parts);
            CaptureSource src(
                p, {.channel = ch, .csv_keep_rows = keep},
                [&](std::size_t part, std::span<const double> x) { seen.at(part).insert(seen[part].end(), x.begin(), x.end()); },
                parts);
            std::vector<double> all;
            for (const auto& s : seen) all.insert(all.end(), s.begin(), s.end());
            EXPECT_EQ(all, w);
            std::vector<double> again(n + 1);
            EXPECT_EQ(src.read(again), n);
            again.pop_back();
            EXPECT_EQ(again, w);
            src.rewind();  // and again, in blocks
            std::vector<double> blocks, block(1000);
            for (std::size_t k; (k = src.read(block)) > 0;) blocks.insert(blocks.end(), block.begin(), block.begin() + static_cast<long>(k));
            EXPECT_EQ(blocks, w);
          }
        }
      }
    }
  }
}

// Whatever the parts, the open pass reports the file's first invalid sample, with read_capture's
// message (each part stops at its own first; the first part's error is the one rethrown).
TEST(StreamingDecode, TheOpenScanInPartsReportsTheFirstInvalidSample) {
  Capture c;
  c.sample_rate = 1e6;
  c.samples.assign(4 * 65536, 0.25);
  const std::string wav = capture_wav(c, WavFormat::Float32);
  auto poison = [](std::string w, std::size_t k, std::uint32_t bits) {  // sample k := the float of bits
    const std::size_t at = w.size() - 4 * (4 * 65536 - k);  // the data chunk ends the file
    for (int i = 0; i < 4; ++i) w[at + static_cast<std::size_t>(i)] = static_cast<char>((bits >> (8 * i)) & 0xff);
    return w;
  };
  const std::uint32_t qnan = 0x7fc00000u, inf = 0x7f800000u;
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"two_bad.wav", poison(poison(wav, 70000, qnan), 250000, inf)},
      {"late_bad.wav", poison(wav, 250000, inf)},
      {"first_bad.wav", poison(poison(wav, 0, inf), 3 * 65536, qnan)}};
  for (const auto& [name, bytes] : bad) {
    const std::string p = write(name, bytes);
    std::string whole;
    try {
      (void)read_capture(p);
    } catch (const InputError& e) {
      whole = e.what();
    }
    ASSERT_FALSE(whole.empty()) << name;
    for (std::size_t parts : {1, 2, 3, 4}) {
      std::string streamed;
      try {
        CaptureSource s(p, {}, [](std::size_t, std::span<const double>) {}, parts);
      } catch (const InputError& e) {
        streamed = e.what();
      }
      EXPECT_EQ(streamed, whole) << name << " parts " << parts;
    }
  }
}

// The open in two steps (decode prepares its receiver meanwhile): the header's accessors at
// once, then finish() runs the pass the one-step constructor runs, with the same blocks, the
// same first invalid sample and the same samples read after; reading before finish(), or
// finishing twice, is a programming error.
TEST(StreamingDecode, TheDeferredPassIsTheOpenPassRunLater) {
  const Capture c = uniform_capture(2 * 65536 + 999, 6);
  Capture small = c;
  small.samples.resize(20000);
  Capture bad = c;
  bad.samples[70001] = std::numeric_limits<double>::quiet_NaN();
  const std::vector<std::pair<std::string, std::string>> files = {
      {"deferred32f.wav", capture_wav(c, WavFormat::Float32)},
      {"deferred16.wav", capture_wav(c, WavFormat::Pcm16, 1.0)},
      {"deferred.csv", capture_csv(small)},
      {"deferred_nan.wav", capture_wav(bad, WavFormat::Float64)}};
  for (const auto& [name, bytes] : files) {
    const std::string p = write(name, bytes);
    for (std::size_t parts : {1, 2, 3}) {
      SCOPED_TRACE(name + " parts " + std::to_string(parts));
      using Seen = std::vector<std::vector<std::vector<double>>>;
      Seen now(parts), later(parts);
      std::string now_error, later_error;
      std::optional<CaptureSource> one;
      try {
        one.emplace(p, CaptureRead{}, [&](std::size_t k, std::span<const double> x) { now[k].emplace_back(x.begin(), x.end()); },
                    parts);
      } catch (const InputError& e) {
        now_error = e.what();
      }
      CaptureSource two(p, {}, [&](std::size_t k, std::span<const double> x) { later[k].emplace_back(x.begin(), x.end()); },
                        parts, CaptureSource::Deferred{});
      const bool csv = name.ends_with(".csv");
      if (!csv) {  // nothing of the samples yet
        for (const auto& part : later) EXPECT_TRUE(part.empty());
      }
      std::vector<double> x(100);
      EXPECT_THROW((void)two.read(x), std::logic_error);
      EXPECT_THROW(two.rewind(), std::logic_error);
      EXPECT_EQ(two.size(), csv ? small.samples.size() : c.samples.size());
      EXPECT_EQ(two.sample_rate(), 1e6);
      try {
        two.finish();
      } catch (const InputError& e) {
        later_error = e.what();
      }
      EXPECT_EQ(later_error, now_error);
      EXPECT_EQ(later, now);
      if (!now_error.empty()) {
        EXPECT_NE(now_error.find("sample 70001 is not finite"), std::string::npos) << now_error;
        continue;
      }
      std::vector<double> a(two.size()), b(two.size());
      EXPECT_EQ(two.read(a), a.size());
      EXPECT_EQ(one->read(b), b.size());
      EXPECT_EQ(a, b);
      EXPECT_EQ(a, read_capture(p).samples);
      EXPECT_THROW(two.finish(), std::logic_error);
    }
  }
}

TEST(StreamingDecode, SamplesAndMetadataAsReadCapture) {
  for (const char* name : {"meta.wav", "meta.csv"}) {
    Capture c = capture();
    const std::string p = write(name, std::string(name).ends_with(".wav") ? capture_wav(c, WavFormat::Pcm24, 1.0)
                                                                           : capture_csv(c));
    const Capture whole = read_capture(p);
    CaptureSource src(p);
    std::vector<double> all, block(333);
    for (int pass = 0; pass < 2; ++pass) {  // rewind starts over
      all.clear();
      src.rewind();
      for (std::size_t k; (k = src.read(block)) > 0;) all.insert(all.end(), block.begin(), block.begin() + static_cast<long>(k));
      EXPECT_EQ(all, whole.samples) << name;
    }
    EXPECT_EQ(src.meta().family, whole.meta.family);
    EXPECT_EQ(src.meta().period_s, whole.meta.period_s);
    EXPECT_EQ(src.meta().source, whole.meta.source);
  }
}

// Every channel of a 3-column CSV (each separator) and of a stereo float WAV streams as
// read_capture reads it; a channel the file lacks is refused with read_capture's message.
TEST(StreamingDecode, EveryChannelStreamsAsReadCaptureReadsIt) {
  std::string csv = "TIME,CH1,CH2,CH3\n";
  for (int n = 0; n < 1000; ++n) {
    char row[128];
    std::snprintf(row, sizeof row, "%.9e,%.6e,%.6e,%.6e\n", n * 2e-7, std::sin(0.1 * n), -0.5 * std::cos(0.2 * n),
                  n / 1000.0);
    csv += row;
  }
  std::vector<std::pair<std::string, std::string>> files = {{"ch.csv", csv}};
  for (const char sep : {';', '\t', ' '}) {
    std::string t = csv;
    std::replace(t.begin(), t.end(), ',', sep);
    files.emplace_back(std::string("ch_") + (sep == ';' ? "semi" : sep == '\t' ? "tab" : "space") + ".csv", t);
  }
  // stereo 32-bit float WAV: frames of (a, b)
  std::string wav = capture_wav(capture(), WavFormat::Float32);
  {
    const std::string body = wav.substr(44);
    std::string stereo;
    for (std::size_t i = 0; i + 4 <= body.size(); i += 4) {
      stereo += body.substr(i, 4);
      float x;
      std::memcpy(&x, body.data() + i, 4);
      x = -2.0f * x;
      char b[4];
      std::memcpy(b, &x, 4);
      stereo.append(b, 4);
    }
    auto put32 = [&](std::size_t at, std::uint32_t v) {
      for (int k = 0; k < 4; ++k) wav[at + static_cast<std::size_t>(k)] = static_cast<char>((v >> (8 * k)) & 0xff);
    };
    wav = wav.substr(0, 44) + stereo;
    put32(4, static_cast<std::uint32_t>(wav.size() - 8));
    wav[22] = 2;                                                   // channels
    put32(28, static_cast<std::uint32_t>(capture().sample_rate) * 8);  // byte rate
    wav[32] = 8;                                                   // block align
    put32(40, static_cast<std::uint32_t>(stereo.size()));
  }
  files.emplace_back("stereo.wav", wav);
  for (const auto& [name, bytes] : files) {
    const std::string p = write(name, bytes);
    const int channels = name.ends_with(".wav") ? 2 : 3;
    for (int ch = 1; ch <= channels; ++ch) {
      SCOPED_TRACE(name + " channel " + std::to_string(ch));
      const Capture whole = read_capture(p, {.channel = ch});
      CaptureSource src(p, {.channel = ch});
      EXPECT_EQ(src.channels(), channels);
      EXPECT_EQ(whole.channels, channels);
      std::vector<double> all, block(97);
      for (std::size_t k; (k = src.read(block)) > 0;) all.insert(all.end(), block.begin(), block.begin() + static_cast<long>(k));
      EXPECT_EQ(all, whole.samples);
      if (ch == 2 && name.ends_with(".wav")) {
        const Capture first = read_capture(p, {.channel = 1});
        ASSERT_EQ(first.samples.size(), whole.samples.size());
        for (std::size_t n = 0; n < first.samples.size(); ++n) ASSERT_EQ(whole.samples[n], -2.0 * first.samples[n]);
      }
    }
    std::string a, b;
    try {
      (void)read_capture(p, {.channel = channels + 1});
    } catch (const InputError& e) {
      a = e.what();
    }
    try {
      CaptureSource s(p, {.channel = channels + 1});
    } catch (const InputError& e) {
      b = e.what();
    }
    EXPECT_NE(a.find("valid 1.." + std::to_string(channels)), std::string::npos) << name << ": " << a;
    EXPECT_EQ(a, b) << name;
  }
}

TEST(StreamingDecode, RefusesWhatReadCaptureRefusesWithTheSameMessage) {
  Capture c;
  c.sample_rate = 1e6;
  c.samples = {0.1, 0.2, 0.3, 0.4};
  std::string csv = capture_csv(c);
  std::string uneven = csv;
  uneven.replace(uneven.find("2.000000000e-06"), 15, "2.100000000e-06");
  std::string wav = capture_wav(c, WavFormat::Float32);
  std::string nan = wav;
  const std::uint32_t qnan = 0x7fc00000u;
  for (int i = 0; i < 4; ++i) nan[44 + 8 + static_cast<std::size_t>(i)] = static_cast<char>((qnan >> (8 * i)) & 0xff);
  std::string truncated = wav.substr(0, wav.size() - 3);
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"uneven.csv", uneven}, {"nan.wav", nan}, {"trunc.wav", truncated}, {"empty.wav", ""},
      {"rows.csv", "TIME,CH1\n0,1\n1e-6\n"}, {"x.txt", "1"}};
  for (const auto& [name, bytes] : bad) {
    const std::string p = write(name, bytes);
    std::string whole, streamed;
    try {
      (void)read_capture(p);
    } catch (const InputError& e) {
      whole = e.what();
    }
    try {
      CaptureSource s(p);
    } catch (const InputError& e) {
      streamed = e.what();
    }
    EXPECT_FALSE(whole.empty()) << name;
    EXPECT_EQ(whole, streamed) << name;
  }
  try {
    CaptureSource s((temp_dir() / "missing.wav").string());
    FAIL() << "a missing file is refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no such file"), std::string::npos) << e.what();
  }
}

// decode --json writes its detections' array on several threads, each element indented into
// place: the text must be the very bytes nlohmann's dump(2) gives for the document, with more
// than one chunk of elements (the 10-burst train tiled to over 512 bursts), on 1 and 2 threads.
TEST(StreamingDecode, ToolJsonIsTheDocumentsOwnDump) {
  Capture c = capture();
  const std::vector<double> one = c.samples;
  for (int k = 1; k < 53; ++k) c.samples.insert(c.samples.end(), one.begin(), one.end());
  const std::string p = write("tiled.wav", capture_wav(c, WavFormat::Float32));
  (void)write("tiled.json", capture_meta_json(c.meta));
  std::string first;
  for (const char* jobs : {"1", "2"}) {
    const auto r = testing_support::run_tool("decode \"" + p + "\" --json --jobs " + jobs);
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_GT(j["detections"].size(), 512u);
    EXPECT_EQ(j.dump(2) + "\n", r.out) << "jobs " << jobs;
    if (first.empty()) first = r.out;
    EXPECT_EQ(r.out, first) << "jobs " << jobs;
  }
}

TEST(StreamingDecode, ToolPrintsTheSameDetectionsAtAnyBlockSize) {
  Capture c = capture();
  const std::string p = write("tool.wav", capture_wav(c, WavFormat::Float32));
  (void)write("tool.json", capture_meta_json(c.meta));
  auto run = [&](const std::string& block) {
    const auto r = testing_support::run_tool("decode \"" + p + "\" --json --block-samples " + block);
    EXPECT_EQ(r.status, 0) << r.err;
    auto j = nlohmann::json::parse(r.out);
    return std::make_pair(j["detections"], j["below_gate"]);
  };
  const auto big = run("1048576"), small = run("64"), threads = run("4096 --jobs 2");
  EXPECT_GE(big.first.size(), 10u);
  EXPECT_EQ(big, small);
  EXPECT_EQ(big, threads);
  const auto bad = testing_support::run_tool("decode \"" + p + "\" --block-samples 10");
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(bad.out.empty());
  EXPECT_NE(bad.err.find("--block-samples"), std::string::npos) << bad.err;
}
