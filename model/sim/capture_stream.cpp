#include "model/sim/capture_stream.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

#include "model/base/error.hpp"
#include "model/base/input_file.hpp"

namespace ranging {

namespace {
constexpr std::size_t kWavBlockBytes = std::size_t{1} << 20;
}

CaptureSource::CaptureSource(const std::string& path, const CaptureRead& how,
                             const std::function<void(std::span<const double>)>& scan)
    : path_(path) {
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
      if (!rows.line(line, t, v) || !scan) continue;
      block.push_back(v);
      if (block.size() == 4096) {
        scan(block);
        block.clear();
      }
    }
    if (in_.bad()) throw InputError(path + ": cannot read the capture file");
    rows.finish();
    if (scan && !block.empty()) scan(block);
    // Second pass: every row on the uniform grid (the rows are known to be well formed now).
    in_.clear();
    in_.seekg(0);
    CsvCaptureScan again(path, how);
    std::size_t n = 0;
    while (std::getline(in_, line)) {
      if (again.line(line, t, v)) rows.check_grid(n++, t, again.lineno());
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
    if (wav_.flt || n_ < 2 || scan) {  // NaN/Inf are refused before anything is decoded (read_capture's order)
      rewind();
      block.resize(std::size_t{1} << 16);
      for (std::size_t k; (k = read(block)) > 0;) {
        if (scan) scan(std::span<const double>(block.data(), k));
      }
    }
    if (n_ < 2) throw InputError(path + ": byte " + std::to_string(wav_.chunk_at) + ": the data chunk holds fewer than two samples");
  }
  merge_capture_sidecar(meta_, path);
  rewind();
}

CaptureSource::~CaptureSource() = default;

void CaptureSource::rewind() {
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
  while (k < want) {
    const std::size_t frames = std::min(want - k, std::max<std::size_t>(kWavBlockBytes / wav_.frame, 1));
    buf_.resize(frames * wav_.frame);
    in_.read(buf_.data(), static_cast<std::streamsize>(buf_.size()));
    if (static_cast<std::size_t>(in_.gcount()) != buf_.size()) {
      throw InputError(path_ + ": changed while it was read (shorter than its data chunk)");
    }
    wav_samples(buf_.data(), frames, wav_, path_, pos_, out.data() + k);
    k += frames;
    pos_ += frames;
  }
  return k;
}

}  // namespace ranging
