// Stimulus driver of the HLS C++ receiver (hls/receiver_hls.hpp) for `ranging simulate
// --precision rtl --rtl-simulator hls` (tool/rtl_runner.cpp compiles it at run time against the
// IP folder of any configuration: -I IP, which holds hls/receiver_config.hpp). The C simulation
// rung of the fidelity ladder: it reads tb/verify_driver.cpp's stimulus format and writes the
// events only (the C model has no ports, no valid gaps and no back-pressure: one sample per
// call of Receiver::step, resets where the stimulus asks for one):
//   run NAME                 a run
//   V code arrival score margin   an event (decimal; arrival signed)
//   R                        reset here
//   end <samples> 0 0
#include <cinttypes>
#include <cstdio>
#include <vector>

#include "driver_stimulus.hpp"  // next to this file

#include "hls/receiver_config.hpp"
#include "hls/receiver_hls.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: hls_driver STIMULUS OUTPUT\n");
    return 2;
  }
  std::FILE* in = std::fopen(argv[1], "r");
  std::FILE* out = std::fopen(argv[2], "w");
  if (!in || !out) {
    std::fprintf(stderr, "hls_driver: cannot open %s or %s\n", argv[1], argv[2]);
    return 2;
  }
  using Cfg = ranging_hls::ReceiverConfig;
  constexpr int in_w = static_cast<int>(Cfg::SOS_IN_W);
  static ranging_hls::Receiver<Cfg> rx;  // static: large state
  ranging::tb::DriverRun run;
  int got = 0;
  while ((got = ranging::tb::read_run(in, run)) > 0) {
    const char* name = run.name.c_str();
    const long long reset_at = run.reset_at;
    // Sign-extend the IN_W-bit port values.
    std::vector<std::int64_t> x;
    const std::uint64_t m = std::uint64_t{1} << (in_w - 1);
    for (std::uint64_t u : run.x) x.push_back(static_cast<std::int64_t>(u ^ m) - static_cast<std::int64_t>(m));
    std::fprintf(out, "run %s\n", name);
    rx.reset();
    ranging_hls::EventBeat ev;
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (reset_at >= 0 && i == static_cast<std::size_t>(reset_at)) {
        rx.reset();
        std::fprintf(out, "R\n");
      }
      if (rx.step(x[i], ev)) {
        std::fprintf(out, "V %" PRId64 " %" PRId64 " %" PRIu64 " %" PRIu64 "\n", ev.code, ev.arrival, ev.score, ev.margin);
      }
    }
    std::fprintf(out, "end %zu 0 0\n", x.size());
  }
  std::fclose(out);
  std::fclose(in);
  if (got < 0) {
    std::fprintf(stderr, "hls_driver: run %s: short sample list\n", run.name.c_str());
    return 2;
  }
  return 0;
}
