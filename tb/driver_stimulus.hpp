#pragma once
// The stimulus format of the run-time drivers (tb/verify_driver.cpp, tb/verify_driver_sc.cpp,
// tb/hls_driver.cpp; written by tool/rtl_runner.cpp), read once here:
//   run NAME VALID_PROB READY_PROB SEED RESET_AT QUIET N CADENCE
//   x_0 ... x_{N-1}
// (fields: see tb/verify_driver.cpp), and what the drivers share around it: the command line
// and the loop over runs (driver_main), and the clocked stream of one run (drive_stream).
#include <cinttypes>
#include <cstdint>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace ranging::tb {

struct DriverRun {
  std::string name;
  double valid_prob = 1, ready_prob = 1;
  unsigned long long seed = 0, quiet = 0, cadence = 0;
  long long reset_at = -1;
  std::vector<std::uint64_t> x;  // port values, masked to IN_W bits
};

// 1: a run was read into r; 0: end of the stimulus; -1: a short sample list (r.name says which).
inline int read_run(std::FILE* in, DriverRun& r) {
  char name[256];
  unsigned long long n = 0;
  if (std::fscanf(in, " run %255s %lf %lf %llu %lld %llu %llu %llu", name, &r.valid_prob, &r.ready_prob, &r.seed,
                  &r.reset_at, &r.quiet, &n, &r.cadence) != 8) {
    return 0;
  }
  r.name = name;
  r.x.assign(n, 0);
  for (auto& v : r.x) {
    if (std::fscanf(in, "%" SCNu64, &v) != 1) return -1;
  }
  return 1;
}

// `DRIVER STIMULUS OUTPUT`: opens both files, writes "run NAME" and calls per_run(run, out) for
// every run, then closes them. Returns the exit status (2: usage, a file, a short sample list).
template <class PerRun>
int driver_main(int argc, char** argv, const char* driver, PerRun&& per_run) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s STIMULUS OUTPUT\n", driver);
    return 2;
  }
  std::FILE* in = std::fopen(argv[1], "r");
  std::FILE* out = std::fopen(argv[2], "w");
  if (!in || !out) {
    std::fprintf(stderr, "%s: cannot open %s or %s\n", driver, argv[1], argv[2]);
    if (in) std::fclose(in);
    if (out) std::fclose(out);
    return 2;
  }
  DriverRun run;
  int got = 0;
  while ((got = read_run(in, run)) > 0) {
    std::fprintf(out, "run %s\n", run.name.c_str());
    per_run(run, out);
  }
  std::fclose(out);
  std::fclose(in);
  if (got < 0) {
    std::fprintf(stderr, "%s: run %s: short sample list\n", driver, run.name.c_str());
    return 2;
  }
  return 0;
}

// One run through a clocked stream DUT: the samples offered with random valid gaps (or at the
// run's CADENCE), m ready with READY_PROB, a reset pulsed before sample RESET_AT, until QUIET
// cycles pass without an output beat after the last sample. The DUT is reached through
//   reset()                                    pulse rst (inputs idle)
//   cycle(offer, data, ready, &taken) -> bool  drive the inputs, settle, set taken (the sample
//                                              was accepted), write the output beats, clock
//                                              once; returns whether any beat was written
// Writes R (reset), S (stalled) and the closing "end <taken> <cycles> <late>" line.
template <class Reset, class Cycle>
void drive_stream(const DriverRun& run, std::FILE* out, Reset&& reset, Cycle&& cycle) {
  std::mt19937_64 rng(run.seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::vector<std::uint64_t>& x = run.x;
  long long reset_at = run.reset_at;
  reset();
  std::size_t next = 0;
  std::uint64_t cycles = 0, idle = 0, silent = 0, late = 0, due = 0;
  bool stalled = false;
  while (next < x.size() || silent < run.quiet) {
    if (reset_at >= 0 && next == static_cast<std::size_t>(reset_at)) {
      reset();
      std::fprintf(out, "R\n");
      reset_at = -1;
    }
    const bool offer = next < x.size() && (run.cadence ? cycles >= due : u(rng) < run.valid_prob);
    const bool ready = u(rng) < run.ready_prob;
    bool taken = false;
    const bool beat = cycle(offer, offer ? x[next] : 0, ready, &taken);
    if (offer && taken) {
      ++next;
      idle = 0;
      if (run.cadence) {
        if (cycles > due) ++late;
        due += run.cadence;
      }
    }
    ++cycles;
    silent = (beat || next < x.size()) ? 0 : silent + 1;
    if (next < x.size() && ++idle > 200000) {
      stalled = true;
      break;
    }
  }
  if (stalled) std::fprintf(out, "S %zu\n", next);
  std::fprintf(out, "end %zu %" PRIu64 " %" PRIu64 "\n", next, cycles, late);
}

}  // namespace ranging::tb
