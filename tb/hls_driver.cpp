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
  using Cfg = ranging_hls::ReceiverConfig;
  constexpr int in_w = static_cast<int>(Cfg::SOS_IN_W);
  static ranging_hls::Receiver<Cfg> rx;  // static: large state
  return ranging::tb::driver_main(argc, argv, "hls_driver", [](const ranging::tb::DriverRun& run, std::FILE* out) {
    // Sign-extend the IN_W-bit port values.
    std::vector<std::int64_t> x;
    const std::uint64_t m = std::uint64_t{1} << (in_w - 1);
    for (std::uint64_t u : run.x) x.push_back(static_cast<std::int64_t>(u ^ m) - static_cast<std::int64_t>(m));
    rx.reset();
    ranging_hls::EventBeat ev;
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (run.reset_at >= 0 && i == static_cast<std::size_t>(run.reset_at)) {
        rx.reset();
        std::fprintf(out, "R\n");
      }
      if (rx.step(x[i], ev)) {
        std::fprintf(out, "V %" PRId64 " %" PRId64 " %" PRIu64 " %" PRIu64 "\n", ev.code, ev.arrival, ev.score, ev.margin);
      }
    }
    std::fprintf(out, "end %zu 0 0\n", x.size());
  });
}
