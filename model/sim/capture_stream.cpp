#include "model/sim/capture_stream.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "model/base/error.hpp"
#include "model/base/parallel.hpp"
#include "model/base/input_file.hpp"

namespace ranging {

namespace {
constexpr std::size_t kWavBlockBytes = std::size_t{1} << 20;
}

CaptureSource::CaptureSource(const std::string& path, const CaptureRead& how,
                             const std::function<void(std::span<const double>)>& scan)
    : CaptureSource(path, how, scan ? PartScan([&scan](std::size_t, std::span<const double> x) { scan(x); }) : PartScan(),
                    1) {}

CaptureSource::CaptureSource(const std::string& path, const CaptureRead& how, const PartScan& part_scan,
                             std::size_t parts)
    : CaptureSource(path, how, part_scan, parts, Deferred{}) {
  finish();
}

CaptureSource::CaptureSource(const std::string& path, const CaptureRead& how, const PartScan& part_scan,
                             std::size_t parts, Deferred)
    : path_(path) {
  const auto scan = [&](std::span<const double> x) { part_scan(0, x); };  // a CSV: one part
  std::vector<double> block;  // scan's samples
  std::string ext;
  if (const auto dot = path.find_last_of('.'); dot != std::string::npos) ext = path.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return std::tolower(ch); });
  if (ext != "csv" && ext != "wav") {
    throw InputError(path + ": unknown capture type '." + ext + "'; valid: .csv (oscilloscope export), .wav");
  }
  csv_ = ext == "csv";
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    (void)read_input_file(path, "capture file", 0);  // the missing-file / folder / unreadable message
    throw InputError(path + ": not a regular file; a capture is read twice (decode streams it)");
  }
  in_.open(path, std::ios::binary);
  if (!in_) throw InputError(path + ": cannot open the capture file: " + std::strerror(errno));
  const std::size_t file_size = static_cast<std::size_t>(fs::file_size(path, ec));
  if (csv_) {
    CsvCaptureScan rows(path, how);
    std::string line;
    double t = 0, v = 0;
    while (std::getline(in_, line)) {
      if (!rows.line(line, t, v) || !part_scan) continue;
      block.push_back(v);
      if (block.size() == 4096) {
        scan(block);
        block.clear();
      }
    }
    if (in_.bad()) throw InputError(path + ": cannot read the capture file");
    rows.finish();
    if (part_scan && !block.empty()) scan(block);
    // Second pass: every row on the uniform grid. The rows are known to be well formed now, and
    // every line from the first data row on is one (an empty line among them was refused), so
    // only the time cell is read, as read() reads a cell.
    in_.clear();
    in_.seekg(0);
    if (rows.has_time()) {
      std::size_t n = 0, lineno = 0;
      while (std::getline(in_, line)) {
        if (++lineno < rows.first_data_line()) continue;
        rows.check_grid(n++, csv_row_value(line, 0), lineno);
      }
    }
    rate_ = rows.sample_rate();
    t0_ = rows.t0();
    n_ = rows.rows();
    meta_ = rows.meta();
    first_data_line_ = rows.first_data_line();
    channels_ = rows.channels();
    cell_ = rows.value_cell();
    file_rate_ = rows.has_time() ? rate_ : 0;
  } else {
    wav_ = parse_wav_layout(
        [&](std::size_t at, std::size_t len) {
          std::string b(len, '\0');
          in_.clear();
          in_.seekg(static_cast<std::streamoff>(at));
          in_.read(b.data(), static_cast<std::streamsize>(len));
          b.resize(static_cast<std::size_t>(std::max<std::streamsize>(in_.gcount(), 0)));
          return b;
        },
        file_size, path, how.channel);
    channels_ = static_cast<int>(wav_.channels);
    file_rate_ = wav_.rate;
    rate_ = how.sample_rate > 0 ? how.sample_rate : wav_.rate;
    n_ = wav_.n;
    if (n_ < 2) {  // its one sample's NaN/Inf first (read_capture's order)
      wav_pass(part_scan, 1);
      throw InputError(path + ": byte " + std::to_string(wav_.chunk_at) + ": the data chunk holds fewer than two samples");
    }
    if (wav_.flt || part_scan) {  // finish(): NaN/Inf are refused before anything is decoded
      pending_scan_ = part_scan;
      pending_parts_ = parts;
      pending_ = true;
    }
  }
  merge_capture_sidecar(meta_, path);
  if (!pending_) seek_start();
}

void CaptureSource::finish() {
  if (finished_) throw std::logic_error("CaptureSource::finish: called twice");
  finished_ = true;
  if (!pending_) return;  // a CSV, or an integer WAV without a scan: nothing was deferred
  wav_pass(pending_scan_, pending_parts_);
  pending_ = false;
  seek_start();
}

void CaptureSource::wav_pass(const PartScan& part_scan, std::size_t parts) {
  // Blocks of 2^16 frames; part p reads blocks [p B / P, (p + 1) B / P) through a stream of
  // its own. Each part stops at its first invalid sample; parallel_items rethrows the first
  // part's error, so the file's first invalid sample is the one reported.
  constexpr std::size_t kScan = std::size_t{1} << 16;
  const std::size_t blocks = (n_ + kScan - 1) / kScan;
  const std::size_t np = std::clamp<std::size_t>(parts, 1, std::max<std::size_t>(blocks, 1));
  parallel_items(np, np, [&](std::size_t part, std::size_t) {
    const std::size_t b0 = part * blocks / np, b1 = (part + 1) * blocks / np;
    if (b0 == b1) return;
    std::ifstream own;
    if (part > 0) {
      own.open(path_, std::ios::binary);
      if (!own) throw InputError(path_ + ": cannot open the capture file: " + std::strerror(errno));
    }
    std::ifstream& in = part > 0 ? own : in_;
    in.clear();
    in.seekg(static_cast<std::streamoff>(wav_.body + b0 * kScan * wav_.frame));
    std::string bytes;
    std::vector<double> out(kScan);
    for (std::size_t b = b0; b < b1; ++b) {
      const std::size_t m = std::min(kScan, n_ - b * kScan);
      wav_frames(in, bytes, b * kScan, m, out.data());
      if (part_scan) part_scan(part, std::span<const double>(out.data(), m));
    }
  });
}

CaptureSource::~CaptureSource() = default;

void CaptureSource::rewind() {
  if (!finished_) throw std::logic_error("CaptureSource: rewind() before finish()");
  seek_start();
}

void CaptureSource::seek_start() {
  in_.clear();
  pos_ = 0;
  lineno_ = 0;
  if (csv_) {
    in_.seekg(0);
  } else {
    in_.seekg(static_cast<std::streamoff>(wav_.body));
  }
}

std::size_t CaptureSource::read(std::span<double> out) {
  if (!finished_) throw std::logic_error("CaptureSource: read() before finish()");
  std::size_t k = 0;
  if (csv_) {
    std::string line;
    while (k < out.size() && pos_ < n_ && std::getline(in_, line)) {
      ++lineno_;
      if (lineno_ < first_data_line_) continue;
      // The rows were validated at open: the channel's cell is a finite number.
      out[k++] = csv_row_value(line, cell_);
      ++pos_;
    }
    if (k < out.size() && pos_ < n_) throw InputError(path_ + ": changed while it was read (fewer rows than at open)");
    return k;
  }
  const std::size_t want = std::min(out.size(), n_ - pos_);
  wav_frames(in_, buf_, pos_, want, out.data());
  pos_ += want;
  return want;
}

void CaptureSource::wav_frames(std::ifstream& in, std::string& buf, std::size_t i0, std::size_t m, double* out) const {
  for (std::size_t k = 0; k < m;) {
    const std::size_t frames = std::min(m - k, std::max<std::size_t>(kWavBlockBytes / wav_.frame, 1));
    buf.resize(frames * wav_.frame);
    in.read(buf.data(), static_cast<std::streamsize>(buf.size()));
    if (static_cast<std::size_t>(in.gcount()) != buf.size()) {
      throw InputError(path_ + ": changed while it was read (shorter than its data chunk)");
    }
    wav_samples(buf.data(), frames, wav_, path_, i0 + k, out + k);
    k += frames;
  }
}

}  // namespace ranging
