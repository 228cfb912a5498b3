#pragma once
// Reading a capture (model/sim/capture.hpp: oscilloscope CSV or WAV) in blocks, for captures
// longer than memory: CaptureSource validates the whole file when it is opened (the same checks
// and the same error messages as read_capture, in the same order), then read() delivers the
// samples in order, a block at a time, as often as rewind() starts over. Memory is bounded:
// a block, and a CSV's values up to CaptureRead::csv_keep_rows rows (64 MiB by default).
//   WAV: the header is parsed from the file (parse_wav_layout); the samples are read from the
//        data chunk in blocks (one pass to check them for NaN/Inf at open for float WAVs).
//   CSV: open() reads the header up to the first data row, counts the lines after it and reads
//        the last one's time, which predict the row count and the grid's step; then one pass
//        over the rows (CsvCaptureScan: syntax, increasing time, each row on the predicted grid)
//        on up to `parts` threads, each a byte range of whole lines (at least 64 KiB). Only if
//        the prediction does not hold does a second pass check the grid (every row within 2 %
//        of a step). read() serves the values the pass kept (a file of at most csv_keep_rows
//        rows) or parses the rows again. Lines come through one 1 MiB buffer (LineReader). An
//        error in any part sends the file through the one-thread pass, which names the first
//        error and its line as read_capture does.
// The pieces read_capture shares with it (one implementation of every check):
//   CsvCaptureScan  the CSV line grammar, row by row (header lines, metadata keys, strict numbers,
//                   increasing time), then finish() (Record Length, row count, sample rate) and
//                   check_grid() per row;
//   parse_wav_layout / wav_samples the RIFF chunk walk and the samples' decoding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "model/base/aligned.hpp"
#include "model/sim/capture.hpp"

namespace ranging {

// A CSV line's separator: ';' if it has one, else ',' if it has one, else '\0' (runs of tabs
// and spaces). csv_row_value: cell `cell` (0-based: 1 is the first channel after the time) of a
// data row that CsvCaptureScan validated.
char csv_separator(std::string_view line);
double csv_row_value(std::string_view line, int cell = 1);
// The same for a row CsvCaptureScan read the fast way (all_rows_plain()): its cells are split by
// sep alone, and cell `cell` starts right after the cell-th separator with its number.
double csv_plain_cell(std::string_view line, int cell, char sep);

class CsvCaptureScan {
 public:
  // how.channel: the 1-based value column read (column channel + 1 of each row); how.sample_rate:
  // rows of one column are samples at that rate (capture.hpp)
  explicit CsvCaptureScan(std::string origin, const CaptureRead& how = {});
  // One line of the file (without its newline): true for a data row (t, v set).
  bool line(std::string_view text, double& t, double& v);
  // For a reader that cuts the data rows into parts (CaptureSource, on threads): a scan of the
  // rows that follow this one's first data row, with its columns and channel; its rows and line
  // numbers count from the part's first line, and for rows of samples alone its t from 0. An
  // error it throws says only that the part is bad (the reader finds the message by one pass).
  CsvCaptureScan continuation() const;
  // The rows a continuation read, after this scan's: rows, lines and the time span as if this
  // scan had read them (that time increases across is left to check_grid, which implies it).
  void append(const CsvCaptureScan& part);
  void finish();  // after the last line: the file-level checks; sample_rate() and t0() valid after it
  void check_grid(std::size_t n, double t, std::size_t line) const;  // row n (0-based) at `line`
  // check_grid's test: row n's time t within 2 % of a step of the grid t0 + n dt
  static bool on_grid(double t0, double dt, std::size_t n, double t) {
    return !(std::abs(t - (t0 + dt * static_cast<double>(n))) > 0.02 * dt);
  }
  double step() const { return dt_; }  // the grid's step, after finish()
  // Every data row after the first was read the fast way (fast_row): each is split by
  // separator() alone and its cells start with their numbers (csv_plain_cell reads them).
  bool all_rows_plain() const { return sep_ != '\0' && first_plain_ && rows_ > 0 && fast_rows_ == rows_ - 1; }
  char separator() const { return sep_; }
  // false: every row goes the general way (split_cells), none the fast way; a reference reading
  // for the tests and the fuzz target, which compare the two.
  void set_fast_rows(bool on) { fast_ = on; }
  std::size_t lineno() const { return lineno_; }
  std::size_t first_data_line() const { return first_data_line_; }
  std::size_t rows() const { return rows_; }
  double sample_rate() const { return 1.0 / dt_; }
  double t0() const { return t_first_; }
  const CaptureMeta& meta() const { return meta_; }
  int channels() const { return channels_; }  // value columns of the first data row
  bool has_time() const { return !no_time_; }  // false: rows of samples alone (a given rate)
  int value_cell() const { return no_time_ ? channel_ - 1 : channel_; }  // the cell read, 0-based

 private:
  std::string origin_;
  int channel_ = 1, channels_ = 0;
  double given_rate_ = 0;
  bool no_time_ = false;
  CaptureMeta meta_;
  std::size_t fast_rows_ = 0;  // the rows fast_row read
  std::size_t lineno_ = 0, rows_ = 0, first_data_line_ = 0, last_data_line_ = 0, record_line_ = 0;
  bool data_ = false;
  double record_length_ = -1, t_first_ = 0, t_last_ = 0, dt_ = 0;
  std::vector<std::string_view> cells_;  // line()'s cells of the current line (views into it)
  char sep_ = '\0';  // the first data row's separator (',' or ';'; '\0': whitespace, or samples alone)
  // A data row after the first in the common form, read without splitting the line: the
  // separator sep_ alone, every cell read a plain number starting with '-' or a digit, no
  // spaces or quotes around them, at most one '\r' at the end. True: the row was read (as the
  // general way reads it, to the same values); false: nothing changed, the general way reads it.
  bool fast_row(std::string_view text, double& t, double& v);
  bool plain_cells(std::string_view text, double& t, double& v) const;  // fast_row's reading of the cells
  bool first_plain_ = false;  // the first data row is one plain_cells reads
  bool fast_ = true;          // set_fast_rows
};

struct WavLayout {
  std::uint32_t rate = 0;
  bool flt = false;
  unsigned bits = 0;
  std::size_t frame = 0;     // bytes per frame (all channels)
  unsigned channels = 1;     // channels per frame
  std::size_t offset = 0;    // byte offset of the channel read within a frame
  std::size_t body = 0;      // byte offset of the first sample
  std::size_t chunk_at = 0;  // byte offset of the data chunk header
  std::size_t n = 0;         // frames
};
// bytes(at, len): len bytes of the file from offset at (fewer at its end).
// channel: 1-based, the one wav_samples reads (InputError at the data chunk if the file lacks it).
WavLayout parse_wav_layout(const std::function<std::string(std::size_t, std::size_t)>& bytes, std::size_t file_size,
                           const std::string& origin, int channel = 1);
// frames consecutive frames from p (frame i0 first) into out, each the layout's channel as a
// full-scale fraction (PCM) or the float value, the format's branch taken once per block;
// InputError naming the frame on NaN/Inf.
void wav_samples(const char* p, std::size_t frames, const WavLayout& w, const std::string& origin, std::size_t i0,
                 double* out);

// The sidecar STEM.json of path (if any) fills what meta lacks (read_capture's rule).
void merge_capture_sidecar(CaptureMeta& meta, const std::string& path);

class LineReader;  // capture_stream.cpp: a file's lines through one buffer

class CaptureSource {
 public:
  // Validates the whole file (InputError); how: as read_capture. scan, when given, sees every
  // sample once, in order, in blocks, before the constructor returns: in the validation pass
  // for the files open reads whole anyway (CSV, float WAV), else in one read at its end (a
  // caller's whole-capture scan, such as decode's peak, without a pass of its own).
  explicit CaptureSource(const std::string& path, const CaptureRead& how = {},
                         const std::function<void(std::span<const double>)>& scan = {});
  // The same with the scan in parts on up to `parts` threads: a WAV's samples are cut into
  // consecutive runs of whole 65536-sample blocks, a CSV's rows into byte ranges of whole lines
  // (at least 64 KiB each), part p's run before part p + 1's, and part p sees its run in order,
  // in blocks (a WAV's: those the one-part scan sees; a CSV's: up to 4096 rows). An invalid
  // sample or row is reported as the one-part pass reports it: the first in the file.
  using PartScan = std::function<void(std::size_t part, std::span<const double>)>;
  CaptureSource(const std::string& path, const CaptureRead& how, const PartScan& scan, std::size_t parts);
  // The same in two steps, so a caller can prepare beside the pass over the samples (decode
  // sets up its receiver meanwhile): this constructor reads a WAV's header and metadata (and its
  // sidecar) only; finish() then runs the WAV's validation pass and the scan, on the calling
  // thread and up to `parts` workers, exactly as the constructor above would have. A CSV's rate
  // and metadata come from its rows, so its whole pass runs here and finish() has nothing left.
  // Until finish() has returned, only the header's accessors below are valid (read() and
  // rewind() throw std::logic_error); they do not change during finish(), so another thread
  // may read them meanwhile. finish() runs once (std::logic_error after).
  struct Deferred {};
  CaptureSource(const std::string& path, const CaptureRead& how, const PartScan& scan, std::size_t parts, Deferred);
  void finish();
  ~CaptureSource();
  int channels() const { return channels_; }  // how many the file has
  double file_rate() const { return file_rate_; }  // the rate the file states (0: none)
  double sample_rate() const { return rate_; }
  double t0() const { return t0_; }
  std::size_t size() const { return n_; }
  const CaptureMeta& meta() const { return meta_; }
  const std::string& path() const { return path_; }
  void rewind();
  // Up to out.size() next samples into out; returns how many (0 at the end).
  std::size_t read(std::span<double> out);

 private:
  std::string path_;
  bool csv_ = false;
  int channels_ = 1, cell_ = 1;
  char plain_sep_ = '\0';  // CSV: every data row plain (CsvCaptureScan::all_rows_plain): its separator
  double rate_ = 0, t0_ = 0, file_rate_ = 0;
  std::size_t n_ = 0, pos_ = 0;
  CaptureMeta meta_;
  WavLayout wav_;
  std::size_t file_size_ = 0, data_at_ = 0;  // CSV: bytes at open, offset of the first data row
  std::ifstream in_;
  std::unique_ptr<LineReader> lines_;  // CSV: read()'s lines, from the first data row
  // A CSV of at most CaptureRead::csv_keep_rows rows: the open pass's values, which read()
  // then serves instead of reading and parsing the rows again (null: read() parses the rows).
  BufferVector<double> kept_;  // (a BufferVector: not zeroed, on huge pages where the kernel has them)
  std::string buf_;
  PartScan pending_scan_;            // Deferred: finish()'s scan
  std::size_t pending_parts_ = 1;
  bool pending_ = false;             // Deferred: the WAV's pass has not run
  bool finished_ = false;            // finish() has run
  void seek_start();  // the next read() gives sample 0
  // The CSV's open pass on the calling thread: every line in order through `rows`, the scan in
  // blocks of 4096 rows (part 0), finish(), the grid check (read_capture's checks and order).
  void csv_pass(CsvCaptureScan& rows, const PartScan& scan);
  // The same with the data rows cut into up to `parts` byte ranges of whole lines, one thread
  // each (part p's rows before part p + 1's); on any error, csv_pass names it.
  void csv_parts(const CaptureRead& how, const PartScan& scan, std::size_t parts);
  void csv_done(const CsvCaptureScan& rows);  // the header's accessors from the finished scan
  // The WAV's pass over every sample (validation of a float WAV, the scan) in parts.
  void wav_pass(const PartScan& scan, std::size_t parts);
  // frames [i0, i0 + m) of the data chunk from `in` (positioned there) into out, through buf
  void wav_frames(std::ifstream& in, std::string& buf, std::size_t i0, std::size_t m, double* out) const;
};

}  // namespace ranging
