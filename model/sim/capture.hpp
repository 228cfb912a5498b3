#pragma once
// Recorded received signals ("captures"): an oscilloscope CSV export or a WAV file, read
// with strict validation and written by `ranging simulate --write-captures`.
//
// CSV: optional header lines (anything before the first row whose first cell is a number,
// e.g. a Tektronix export's "Record Length,..." lines and its "TIME,CH1" line), then rows
// "time_s,volts[,more columns ignored]". Time must increase with an even step (every sample
// within 2 % of a step of the uniform grid from the first to the last time); the sample rate
// is the number of steps over the time span. t0 is the time of the first row (the scope's
// pre-trigger makes it negative), t = 0 being the start of transmission of the first burst.
// WAV: RIFF/WAVE, 16- or 24-bit PCM or 32-bit IEEE float (also as WAVE_FORMAT_EXTENSIBLE),
// mono or the first channel of several; t0 = 0; PCM values are read as full-scale fractions.
// Every error is an InputError naming the file and line (CSV) or byte offset (WAV).
#include <cstdint>
#include <string>
#include <vector>

namespace ranging {

struct Capture {
  double sample_rate = 0;        // Hz
  double t0 = 0;                 // time of samples[0], s (0 = start of the first burst)
  std::vector<double> samples;   // volts (CSV, float WAV) or full-scale fractions (PCM WAV)
};

// By extension: .csv or .wav (case-insensitive); anything else is refused.
Capture read_capture(const std::string& path);
Capture parse_capture_csv(const std::string& text, const std::string& origin);
Capture parse_capture_wav(const std::string& bytes, const std::string& origin);

enum class WavFormat { Pcm16, Pcm24, Float32 };

// CSV: a Tektronix-like header ("Model,ranging simulate", "Sample Interval,...", "TIME,CH1")
// then time,volts rows with 9 significant digits. WAV: the sample rate rounded to an integer
// (refused if it is not one); PCM scales by 1/full_scale and saturates, float writes volts.
// write_file_atomic (model/base/atomic_file.hpp) writes a temporary name and renames it.
std::string capture_csv(const Capture& c);
std::string capture_wav(const Capture& c, WavFormat fmt, double full_scale = 1.0);
void write_file_atomic(const std::string& path, const std::string& content);

}  // namespace ranging
