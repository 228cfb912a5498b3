#include "model/sim/capture_stream.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
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
constexpr std::size_t kCsvScanRows = 4096;                   // rows per block of the open's scan
constexpr std::size_t kCsvPartBytes = std::size_t{1} << 16;  // the least bytes of a CSV part

// Part p's stream: part 0 reads through the source's own `in`, another part through `own`.
std::ifstream& part_stream(std::size_t p, std::ifstream& in, std::ifstream& own, const std::string& path) {
  if (p == 0) return in;
  own.open(path, std::ios::binary);
  if (!own) throw InputError(path + ": cannot open the capture file: " + std::strerror(errno));
  return own;
}

// The '\n' bytes in [begin, end) of the file (1 MiB at a time).
std::size_t count_newlines(std::ifstream& in, std::size_t begin, std::size_t end, const std::string& origin) {
  in.clear();
  in.seekg(static_cast<std::streamoff>(begin));
  BufferVector<char> buf(std::min(kWavBlockBytes, end - begin));
  std::size_t n = 0;
  for (std::size_t at = begin; at < end;) {
    const std::size_t want = std::min(buf.size(), end - at);
    in.read(buf.data(), static_cast<std::streamsize>(want));
    if (static_cast<std::size_t>(in.gcount()) != want) {
      if (in.bad()) throw InputError(origin + ": cannot read the capture file");
      throw InputError(origin + ": changed while it was read (shorter than at open)");
    }
    n += static_cast<std::size_t>(std::count(buf.data(), buf.data() + want, '\n'));
    at += want;
  }
  return n;
}

// The open's scan of a CSV part: its rows' values handed on in blocks of kCsvScanRows.
class BlockScan {
 public:
  BlockScan(const CaptureSource::PartScan& scan, std::size_t part) : scan_(scan), part_(part) {}
  void push(double v) {
    if (!scan_) return;
    block_.push_back(v);
    if (block_.size() == kCsvScanRows) flush();
  }
  void flush() {
    if (scan_ && !block_.empty()) scan_(part_, block_);
    block_.clear();
  }

 private:
  const CaptureSource::PartScan& scan_;
  std::size_t part_;
  std::vector<double> block_;
};
}  // namespace

// The lines of bytes [begin, end) of a file, split as std::getline splits them: at each '\n'
// (not part of the line; a '\r' before it is), the last one without a '\n' if the range does not
// end with one. Read through one buffer of 1 MiB (grown for a longer line; a BufferVector: not
// zeroed, on a huge page where the kernel has them); a line is a view into it, valid until the
// next call.
class LineReader {
 public:
  LineReader(std::ifstream& in, std::size_t begin, std::size_t end, const std::string& origin)
      : in_(in), origin_(origin), buf_(kWavBlockBytes), file_(begin), end_(end), offset_(begin) {
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(begin));
  }
  bool next(std::string_view& line) {
    for (;;) {
      const char* b = buf_.data() + at_;
      if (const void* nl = std::memchr(b, '\n', len_ - at_)) {
        const auto n = static_cast<std::size_t>(static_cast<const char*>(nl) - b);
        line = std::string_view(b, n);
        take(n + 1);
        return true;
      }
      if (file_ == end_) {  // the range's last line, without its '\n'
        if (at_ == len_) return false;
        line = std::string_view(b, len_ - at_);
        take(len_ - at_);
        return true;
      }
      refill();
    }
  }
  std::size_t line_at() const { return line_at_; }  // file offset of the line next() gave last
  std::size_t offset() const { return offset_; }    // file offset of the line it gives next

 private:
  std::ifstream& in_;
  const std::string& origin_;
  BufferVector<char> buf_;
  std::size_t at_ = 0, len_ = 0;         // the unread bytes: buf_[at_, len_)
  std::size_t file_, end_, offset_, line_at_ = 0;  // file_: offset of buf_[len_]
  void take(std::size_t n) {
    line_at_ = offset_;
    at_ += n;
    offset_ += n;
  }
  void refill() {  // the partial line to the front, then as many bytes as fit
    std::memmove(buf_.data(), buf_.data() + at_, len_ - at_);
    len_ -= at_;
    at_ = 0;
    if (len_ == buf_.size()) buf_.resize(2 * buf_.size());
    const std::size_t want = std::min(buf_.size() - len_, end_ - file_);
    in_.read(buf_.data() + len_, static_cast<std::streamsize>(want));
    if (static_cast<std::size_t>(in_.gcount()) != want) {
      if (in_.bad()) throw InputError(origin_ + ": cannot read the capture file");
      throw InputError(origin_ + ": changed while it was read (shorter than at open)");
    }
    len_ += want;
    file_ += want;
  }
};

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
  csv_ = capture_is_csv(path);
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
    file_size_ = file_size;
    csv_parts(how, part_scan, parts);
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

void CaptureSource::csv_pass(CsvCaptureScan& rows, const PartScan& scan) {
  LineReader lines(in_, 0, file_size_, path_);
  BlockScan blocks(scan, 0);
  std::string_view line;
  double t = 0, v = 0;
  while (lines.next(line)) {
    if (!rows.line(line, t, v)) continue;
    if (rows.rows() == 1) data_at_ = lines.line_at();
    blocks.push(v);
  }
  rows.finish();
  blocks.flush();
  // Every row on the uniform grid. The rows are known to be well formed now, and every line
  // from the first data row on is one (an empty line among them was refused), so only the time
  // cell is read, as read() reads a cell.
  if (rows.has_time()) {
    LineReader again(in_, data_at_, file_size_, path_);
    for (std::size_t n = 0; again.next(line); ++n) rows.check_grid(n, csv_row_value(line, 0), rows.first_data_line() + n);
  }
  csv_done(rows);
}

void CaptureSource::csv_parts(const CaptureRead& how, const PartScan& scan, std::size_t parts) {
  // The header, up to the first data row, on this thread: the columns, the metadata.
  CsvCaptureScan rows(path_, how);
  LineReader lines(in_, 0, file_size_, path_);
  std::string_view line;
  double t = 0, v0 = 0;
  bool data = false;
  while (!data && lines.next(line)) data = rows.line(line, t, v0);
  if (!data) {  // no data row: finish() says so
    rows.finish();
    throw std::logic_error("CaptureSource: a CSV without data rows passed");
  }
  data_at_ = lines.line_at();
  // The rows after the first: cut at line starts into parts of at least kCsvPartBytes.
  const std::size_t rest = lines.offset();
  const std::size_t np = std::clamp<std::size_t>((file_size_ - rest) / kCsvPartBytes, 1, parts);
  std::vector<std::size_t> cut(np + 1, file_size_);
  cut[0] = rest;
  for (std::size_t p = 1; p < np; ++p) {
    // the first line start at or after `at`: the end of the line that holds byte at - 1
    const std::size_t at = std::max(cut[p - 1], rest + (file_size_ - rest) / np * p);
    LineReader probe(in_, at - 1, file_size_, path_);
    (void)probe.next(line);
    cut[p] = probe.offset();
  }
  // The grid predicted before the pass, so each part checks its rows' times as it reads them
  // instead of a pass of its own after finish(): in a valid file every line from the first data
  // row on is a data row, so part p holds as many rows as it has lines (its '\n's, and the last
  // part its unterminated last line), and the last line's time ends the span. The prediction
  // stands only if the pass agrees: each part read that many rows and finish()'s step is the
  // predicted one, bit for bit (then every row was checked against check_grid's own grid);
  // otherwise (an invalid file, a last line the tail read missed) the grid pass below runs.
  std::vector<std::size_t> lines_in(np, 0);
  double dt_guess = 0;
  const double t_first = t;
  parallel_items(np, np, [&](std::size_t p, std::size_t) {
    std::ifstream own;
    lines_in[p] = count_newlines(part_stream(p, in_, own, path_), cut[p], cut[p + 1], path_);
  });
  std::size_t total = 1;  // the predicted rows
  for (const std::size_t n : lines_in) total += n;
  {
    // the last line: the tail's bytes after its last '\n' but the final one
    const std::size_t tail_at = std::max(rest, file_size_ - std::min<std::size_t>(file_size_, 4096));
    std::string tail(file_size_ - tail_at, '\0');
    in_.clear();
    in_.seekg(static_cast<std::streamoff>(tail_at));
    in_.read(tail.data(), static_cast<std::streamsize>(tail.size()));
    if (static_cast<std::size_t>(in_.gcount()) == tail.size() && !tail.empty()) {
      if (tail.back() == '\n') {
        tail.pop_back();
      } else {
        ++lines_in[np - 1];
        ++total;
      }
      const std::size_t nl = tail.rfind('\n');
      if (rows.has_time() && (nl != std::string::npos || tail_at == rest)) {
        const double t_last = csv_row_value(std::string_view(tail).substr(nl == std::string::npos ? 0 : nl + 1), 0);
        if (total >= 2) dt_guess = (t_last - t_first) / static_cast<double>(total - 1);  // finish()'s step
      }
    }
    if (!(std::isfinite(dt_guess) && dt_guess > 0)) dt_guess = 0;
  }
  std::vector<std::size_t> n0(np, 1);  // predicted row index of each part's first row
  for (std::size_t p = 1; p < np; ++p) n0[p] = n0[p - 1] + lines_in[p - 1];
  // A file of at most how.csv_keep_rows rows keeps the pass's values for read() (kept_[n]: row
  // n's), if the prediction holds (each part read as many rows as it has lines).
  kept_ = {};
  if (total <= how.csv_keep_rows) {
    kept_.resize(total);  // not zeroed: every row's value is written before read() serves it
    kept_[0] = v0;
  }
  // Each part's rows through a continuation of the scan; an error marks the part bad.
  std::vector<CsvCaptureScan> part(np, rows.continuation());
  std::vector<char> bad(np, 0), off_grid(np, 0);
  parallel_items(np, np, [&](std::size_t p, std::size_t) {
    std::ifstream own;
    LineReader lr(part_stream(p, in_, own, path_), cut[p], cut[p + 1], path_);
    BlockScan blocks(scan, p);
    if (p == 0) blocks.push(v0);
    std::string_view ln;
    double tp = 0, vp = 0;
    for (std::size_t n = n0[p];; ++n) {
      try {
        if (!lr.next(ln)) break;
        (void)part[p].line(ln, tp, vp);
      } catch (const InputError&) {
        bad[p] = 1;
        return;
      }
      if (dt_guess > 0 && !CsvCaptureScan::on_grid(t_first, dt_guess, n, tp)) off_grid[p] = 1;
      if (n < kept_.size()) kept_[n] = vp;
      blocks.push(vp);
    }
    blocks.flush();
  });
  // The parts' rows after the first, in order; then the file's checks and the grid, by part.
  // (Time increases across a cut too when every row is within 2 % of a step of its grid point.)
  bool ok = std::find(bad.begin(), bad.end(), 1) == bad.end();
  for (std::size_t p = 0; ok && p < np; ++p) rows.append(part[p]);
  if (ok) {
    try {
      rows.finish();
    } catch (const InputError&) {
      ok = false;
    }
  }
  bool as_predicted = ok && rows.rows() == total;  // every part read as many rows as it has lines
  for (std::size_t p = 0; as_predicted && p < np; ++p) as_predicted = part[p].rows() == lines_in[p];
  if (!as_predicted) kept_ = {};
  const bool grid_checked = as_predicted && dt_guess > 0 && rows.step() == dt_guess &&
                            std::find(off_grid.begin(), off_grid.end(), 1) == off_grid.end();
  if (ok && rows.has_time() && !grid_checked) {
    for (std::size_t p = 1; p < np; ++p) n0[p] = n0[p - 1] + part[p - 1].rows();  // the rows read
    parallel_items(np, np, [&](std::size_t p, std::size_t) {
      std::ifstream own;
      LineReader lr(part_stream(p, in_, own, path_), cut[p], cut[p + 1], path_);
      std::string_view ln;
      try {
        for (std::size_t n = n0[p]; lr.next(ln); ++n) rows.check_grid(n, csv_row_value(ln, 0), 0);
      } catch (const InputError&) {
        bad[p] = 1;
      }
    });
    ok = std::find(bad.begin(), bad.end(), 1) == bad.end();
  }
  if (!ok) {  // the message, as one pass finds it
    CsvCaptureScan again(path_, how);
    csv_pass(again, {});
    throw std::logic_error("CaptureSource: " + path_ + ": a part of the CSV was refused, but not the whole file");
  }
  csv_done(rows);
}

void CaptureSource::csv_done(const CsvCaptureScan& rows) {
  rate_ = rows.sample_rate();
  t0_ = rows.t0();
  n_ = rows.rows();
  meta_ = rows.meta();
  channels_ = rows.channels();
  cell_ = rows.value_cell();
  plain_sep_ = rows.all_rows_plain() ? rows.separator() : '\0';
  file_rate_ = rows.has_time() ? rate_ : 0;
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
    std::ifstream& in = part_stream(part, in_, own, path_);
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
  if (csv_) {
    if (kept_.empty()) lines_ = std::make_unique<LineReader>(in_, data_at_, file_size_, path_);
  } else {
    in_.seekg(static_cast<std::streamoff>(wav_.body));
  }
}

std::size_t CaptureSource::read(std::span<double> out) {
  if (!finished_) throw std::logic_error("CaptureSource: read() before finish()");
  std::size_t k = 0;
  if (csv_ && !kept_.empty()) {
    const std::size_t want = std::min(out.size(), n_ - pos_);
    std::copy_n(kept_.data() + pos_, want, out.data());
    pos_ += want;
    return want;
  }
  if (csv_) {
    std::string_view line;
    if (plain_sep_ != '\0') {
      for (; k < out.size() && pos_ < n_ && lines_->next(line); ++pos_) out[k++] = csv_plain_cell(line, cell_, plain_sep_);
    } else {
      while (k < out.size() && pos_ < n_ && lines_->next(line)) {
        // The rows were validated at open: the channel's cell is a finite number.
        out[k++] = csv_row_value(line, cell_);
        ++pos_;
      }
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
