#pragma once
// Recorded received signals ("captures"): an oscilloscope CSV export or a WAV file, read
// with strict validation and written by `ranging simulate --write-captures`.
//
// CSV: optional header lines (anything before the first row whose first cell is a number,
// e.g. a Tektronix export's "Record Length,..." lines and its "TIME,CH1" line), then rows
// "time_s,volts[,more channels]" (channel N is column N + 1), or separated by ';', tabs or spaces (a line with a ';' is
// split on ';', else one with a ',' on ',', else on runs of whitespace: numpy.savetxt, SPICE and
// European exports; decimal commas are refused). Time must increase with an even step (every
// sample within 2 % of a step of the uniform grid from the first to the last time); the sample rate
// is the number of steps over the time span. t0 is the time of the first row (the scope's
// pre-trigger makes it negative), t = 0 being the start of transmission of the first burst.
// WAV: RIFF/WAVE, 8-bit (unsigned), 16-, 24- or 32-bit PCM, or 32- or 64-bit IEEE float (also
// as WAVE_FORMAT_EXTENSIBLE), mono or one channel of several (interleaved frames); t0 = 0; PCM values are read
// as full-scale fractions (code / 2^(bits-1), 8-bit as (code - 128) / 128).
// Channels: the readers take a 1-based channel (default 1) and report how many the file has
// (CSV: the value columns of the first data row; every data row must hold the channel read).
// A given sample rate (CaptureRead::sample_rate > 0): a CSV whose rows are one column of samples
// and no time (numpy.savetxt of an array) is read at that rate from t = 0 (without one it is
// refused); a CSV with a time column refuses it (its rate comes from the time); a WAV's header
// rate is replaced by it (a simulator that wrote a placeholder rate).
// Every error is an InputError naming the file and line (CSV) or byte offset (WAV).
//
// Metadata (what `simulate --write-captures` knows about the stream), all optional:
//   CSV header lines "Scene,NAME", "Family,NAME", "Code Sent,J" (0: a periodic train),
//   "True Distance (m),D", "Speed of Sound (m/s),C", "Sample Rate (Hz),FS", "Burst Period (s),T";
//   a sidecar JSON STEM.json beside STEM.csv / STEM.wav with the keys scene, family, code_sent,
//   true_distance_m, speed_of_sound, sample_rate, period_s.
// read_capture() takes the CSV header lines, then fills what they lack from the sidecar (a
// WAV's only source). A value that is malformed or out of range is an InputError naming the
// file, the line or key and the valid range.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace ranging {

struct CaptureMeta {
  std::optional<std::string> scene, family;
  std::optional<int> code_sent;               // 1-based j; 0 = a periodic train of codes 1..eta
  std::optional<double> true_distance_m;      // 0 < d <= 1000
  std::optional<double> speed_of_sound;       // m/s, 100..10000
  std::optional<double> sample_rate;          // Hz, as recorded (the data's own rate is Capture::sample_rate)
  std::optional<double> period_s;             // periodic trains: the burst period
  std::string source;                         // where the metadata came from: "csv header", "FILE.json", both, or ""
  bool empty() const {
    return !scene && !family && !code_sent && !true_distance_m && !speed_of_sound && !sample_rate && !period_s;
  }
};

struct Capture {
  double sample_rate = 0;        // Hz
  double t0 = 0;                 // time of samples[0], s (0 = start of the first burst)
  std::vector<double> samples;   // volts (CSV, float WAV) or full-scale fractions (PCM WAV)
  CaptureMeta meta;
  int channel = 1;               // the channel read (1-based)
  int channels = 1;              // how many the file has
  double file_rate = 0;          // the rate the file states (WAV header, CSV time column; 0: none)
};

// How to read a capture: the channel (1-based) and, when the file does not hold the rate or
// holds a wrong one, the sample rate (Hz; 0: the file's).
struct CaptureRead {
  int channel = 1;
  double sample_rate = 0;
  // CaptureSource: a CSV of at most this many rows keeps the values its open pass read (8 bytes
  // a row: 64 MiB at the default), and read() serves them instead of parsing the rows again;
  // a longer one is read again from the file (memory stays bounded). 0: never kept.
  std::size_t csv_keep_rows = std::size_t{1} << 23;
};

// The sidecar JSON's text for meta, and its parse (InputError naming origin and the key).
std::string capture_meta_json(const CaptureMeta& meta);
CaptureMeta parse_capture_meta_json(const std::string& text, const std::string& origin);

// By extension: .csv or .wav (case-insensitive); anything else is refused. channel: 1-based;
// one the file does not have is an InputError naming the file, the line (CSV) or byte (WAV),
// and the valid range.
Capture read_capture(const std::string& path, const CaptureRead& how = {});
// The capture type by the file name's extension (case-insensitive): true for .csv, false for
// .wav; anything else, or no extension, is an InputError naming the path and the valid ones.
bool capture_is_csv(const std::string& path);
Capture parse_capture_csv(const std::string& text, const std::string& origin, const CaptureRead& how = {});
Capture parse_capture_wav(const std::string& bytes, const std::string& origin, const CaptureRead& how = {});

enum class WavFormat { Pcm8, Pcm16, Pcm24, Pcm32, Float32, Float64 };

// CSV: a Tektronix-like header ("Model,ranging simulate", "Sample Interval,...", "TIME,CH1")
// then time,volts rows with 9 significant digits. WAV: the sample rate rounded to an integer
// (refused if it is not one); PCM scales by 1/full_scale and saturates, float writes volts.
// write_file_atomic (model/base/atomic_file.hpp) writes a temporary name and renames it.
// capture_csv writes c.meta's fields as header lines (before "TIME,CH1").
std::string capture_csv(const Capture& c);
std::string capture_wav(const Capture& c, WavFormat fmt, double full_scale = 1.0);
void write_file_atomic(const std::string& path, const std::string& content);

}  // namespace ranging
