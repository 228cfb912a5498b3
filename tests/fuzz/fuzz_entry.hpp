#pragma once
// The fuzzed entry points, shared by the libFuzzer targets (tests/fuzz/fuzz_*.cpp) and the
// unit test that replays the seeds and every regression input (tests/test_fuzz_regressions.cpp).
// Contract under test: any input either parses or is refused with ranging::InputError; any
// other exception, a crash, a leak or undefined behaviour is a bug.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>
#include <unistd.h>

#include "model/base/error.hpp"
#include "model/config/receiver_config.hpp"
#include "model/hw/frames.hpp"
#include "model/sim/capture.hpp"
#include "model/sim/capture_stream.hpp"
#include "model/sim/scene.hpp"
#include "model/study/sweep.hpp"
#include "tests/scratch.hpp"

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

// Besides the contract: the streamed reader (CaptureSource, model/sim/capture_stream.hpp) reads
// the bytes from a file as the whole-file parser reads them, in one part and in two (a CSV's
// header-then-parts path; a WAV's samples in two runs): the same samples, rate and start, or the
// same message (its origin aside). A disagreement aborts (a finding).
inline void streamed_agrees(const std::string& bytes, const std::string& ext, const Capture& whole,
                            const std::string& want) {
  static const testing_support::ScratchDir scratch("ranging-fuzz-capture");
  const std::string path = (scratch.path() / ("fuzz." + ext)).string();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  for (const std::size_t parts : {std::size_t{1}, std::size_t{2}})
  for (const std::size_t keep : {std::size_t{0}, CaptureRead{}.csv_keep_rows}) {  // read() parses again, or not
    std::string got;
    try {
      std::vector<std::vector<double>> part(parts);  // the open's scan, part by part (a thread each)
      CaptureSource src(
          path, CaptureRead{.csv_keep_rows = keep}, [&](std::size_t k, std::span<const double> x) { part[k].insert(part[k].end(), x.begin(), x.end()); },
          parts);
      std::vector<double> seen;
      for (const auto& s : part) seen.insert(seen.end(), s.begin(), s.end());
      std::vector<double> x(src.size() + 1);
      x.resize(src.read(x));
      if (x != whole.samples || seen != whole.samples || src.sample_rate() != whole.sample_rate || src.t0() != whole.t0) {
        throw std::logic_error("CaptureSource reads other samples than the whole-file parser");
      }
    } catch (const InputError& e) {
      got = e.what();
      if (got.starts_with(path)) got = "fuzz." + ext + got.substr(path.size());
    }
    if (got != want) throw std::logic_error("CaptureSource: '" + got + "', the whole-file parser: '" + want + "'");
  }
}

// The rows of text read the general way only (CsvCaptureScan::set_fast_rows(false)), as
// parse_capture_csv reads them otherwise: the samples, or the message.
inline std::vector<double> csv_general_way(const std::string& text, std::string& error) {
  std::vector<double> t, v;
  try {
    CsvCaptureScan scan("fuzz.csv", {});
    scan.set_fast_rows(false);
    std::vector<std::size_t> lines;
    std::size_t b = 0;
    double tv = 0, vv = 0;
    while (b < text.size()) {  // std::getline's lines
      const std::size_t e = std::min(text.find('\n', b), text.size());
      if (scan.line(std::string_view(text).substr(b, e - b), tv, vv)) {
        t.push_back(tv);
        v.push_back(vv);
        lines.push_back(scan.lineno());
      }
      b = e + 1;
    }
    scan.finish();
    for (std::size_t n = 0; n < t.size(); ++n) scan.check_grid(n, t[n], lines[n]);
  } catch (const InputError& e) {
    error = e.what();
  }
  return v;
}

// Besides the contract: the fast reading of plain rows agrees with the general way (the same
// samples or the same message), and the streamed reader with the whole-file parser.
inline int capture_csv(const std::uint8_t* data, std::size_t size) {
  const std::string text = text_of(data, size);
  Capture whole;
  std::string want;
  try {
    whole = parse_capture_csv(text, "fuzz.csv");
  } catch (const InputError& e) {
    want = e.what();
  }
  std::string general_error;
  const std::vector<double> general = csv_general_way(text, general_error);
  if (general_error != want || (want.empty() && general != whole.samples)) {
    throw std::logic_error("the fast rows: '" + want + "', the general way: '" + general_error + "'");
  }
  streamed_agrees(text, "csv", whole, want);
  return 0;
}

inline int capture_wav(const std::uint8_t* data, std::size_t size) {
  const std::string bytes = text_of(data, size);
  Capture whole;
  std::string want;
  try {
    whole = parse_capture_wav(bytes, "fuzz.wav");
  } catch (const InputError& e) {
    want = e.what();
  }
  streamed_agrees(bytes, "wav", whole, want);
  return 0;
}

// UART frame decoder (model/hw/frames.cpp) on any byte stream. Besides not crashing, the
// decoder's own contract is checked: every frame it returns starts with the sync at its offset
// and re-encodes to the very bytes of the stream there, frames do not overlap, the counters
// account for no more bytes than the stream holds, and a stream of only whole frames decodes
// back to them. A violation aborts (a finding).
inline int uart_frames(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  FrameStats st;
  const std::vector<UartFrame> frames = decode_uart_frames(bytes, st);
  if (st.bytes != size) throw std::logic_error("FrameStats.bytes != stream size");
  std::uint64_t end = 0;
  for (const UartFrame& f : frames) {
    if (f.offset < end || f.offset + kUartFrameBytes > size) throw std::logic_error("frame outside the stream or overlapping");
    const std::vector<std::uint8_t> enc = encode_uart_frame(f);
    if (enc.size() != kUartFrameBytes || !std::equal(enc.begin(), enc.end(), data + f.offset))
      throw std::logic_error("decoded frame does not re-encode to the stream's bytes");
    end = f.offset + kUartFrameBytes;
  }
  if (frames.size() * kUartFrameBytes + st.skipped_bytes > size) throw std::logic_error("bytes counted twice");
  // Round trip: the decoded frames, encoded back to back, decode to themselves with nothing skipped.
  std::vector<std::uint8_t> clean;
  for (const UartFrame& f : frames) {
    const auto e = encode_uart_frame(f);
    clean.insert(clean.end(), e.begin(), e.end());
  }
  FrameStats st2;
  const auto again = decode_uart_frames(clean, st2);
  if (again.size() != frames.size() || st2.bad_frames != 0 || st2.skipped_bytes != 0 || st2.truncated)
    throw std::logic_error("clean stream of decoded frames does not decode back");
  return 0;
}

// Sweep spec (model/study/sweep.cpp load_sweep_spec, then the point list). The spec is a file
// whose config: and scene: are resolved relative to it, so each input is written to a private
// folder that holds copies of configs/default.yaml (as default.yaml) and
// sweeps/smoke-scene.yaml (as smoke-scene.yaml); source_dir is the repository.
inline int sweep_spec(const std::uint8_t* data, std::size_t size, const std::string& source_dir) {
  namespace fs = std::filesystem;
  // The folder is removed at exit (a function-local static).
  static const testing_support::ScratchDir scratch("ranging-fuzz-sweep");
  static const fs::path dir = [&] {
    const fs::path d = scratch.path();
    fs::copy_file(fs::path(source_dir) / "configs/default.yaml", d / "default.yaml", fs::copy_options::overwrite_existing);
    fs::copy_file(fs::path(source_dir) / "sweeps/smoke-scene.yaml", d / "smoke-scene.yaml", fs::copy_options::overwrite_existing);
    return d;
  }();
  const fs::path spec = dir / "spec.yaml";
  {
    std::ofstream out(spec, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  }
  try {
    const study::SweepSpec s = study::load_sweep_spec(spec.string());
    // Expand the points only when the grid is of a reasonable size (a spec may legitimately
    // ask for millions of points; that is not a parser bug).
    double n = 1;
    for (const auto& a : s.axes) n *= static_cast<double>(a.values.size());
    if (n <= 5000 && s.points <= 5000) (void)study::sweep_points(s);
  } catch (const InputError&) {
  }
  return 0;
}

}  // namespace ranging::fuzz
