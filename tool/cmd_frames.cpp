// `ranging frames FILE|-`: decodes the board's UART stream of measurement frames
// (rtl/measurement_uart.v, model/hw/frames.hpp) into CSV or JSON distances. Checksums are
// checked, the decoder resyncs after a corrupt byte, and bad frames, skipped bytes and a
// truncated last frame are counted and reported (stderr, and in the JSON).
#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <iterator>

#include "model/base/error.hpp"
#include "model/hw/frames.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/json_meta.hpp"

namespace ranging::tool {

int cmd_frames(const Args& args) {
  cli::Parser p("ranging frames",
                "Decode the board's UART stream (17-byte measurement frames, docs/bitstream.md) from FILE\n"
                "or stdin (-): one CSV row per good frame (or --json). Checksums are checked; after a\n"
                "corrupt byte the decoder resyncs on the next 0xA5 0x5A; bad frames are counted.");
  p.positional("FILE", "captured bytes (binary), or - for stdin");
  p.flag("--json", "JSON instead of CSV");
  p.flag("--strict", "exit 1 when any frame was bad or truncated");
  if (!p.parse(args)) return 0;
  const std::string path = p.positionals().at(0);
  std::vector<std::uint8_t> bytes;
  if (path == "-") {
    std::cin >> std::noskipws;
    bytes.assign(std::istreambuf_iterator<char>(std::cin), std::istreambuf_iterator<char>());
  } else {
    std::ifstream f(path, std::ios::binary);
    if (!f) throw InputError(path + ": cannot read");
    bytes.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  }
  FrameStats st;
  const auto frames = decode_uart_frames(bytes, st);
  if (p.has("--json")) {
    nlohmann::ordered_json j;
    stamp_build_info(j);
    j["file"] = path;
    j["bytes"] = st.bytes;
    j["frames"] = frames.size();
    j["bad_frames"] = st.bad_frames;
    j["skipped_bytes"] = st.skipped_bytes;
    j["truncated"] = st.truncated;
    j["measurements"] = nlohmann::ordered_json::array();
    for (const auto& f : frames) {
      j["measurements"].push_back({{"offset", f.offset}, {"code", f.code}, {"flags", f.flags},
                                   {"no_burst", (f.flags & 1) != 0}, {"saturated", (f.flags & 2) != 0},
                                   {"adc_overrun", (f.flags & 4) != 0}, {"tof_samples", f.tof_q8 / 256.0},
                                   {"distance_m", f.distance_um * 1e-6}, {"score", f.score / 65536.0},
                                   {"margin", f.margin / 65536.0}});
    }
    std::cout << j.dump(2) << "\n";
  } else {
    std::cout << "offset,code,flags,no_burst,saturated,adc_overrun,tof_samples,distance_m,score,margin\n";
    for (const auto& f : frames) {
      std::printf("%llu,%d,%u,%d,%d,%d,%.8g,%.6f,%.6f,%.6f\n", static_cast<unsigned long long>(f.offset), f.code,
                  static_cast<unsigned>(f.flags), f.flags & 1, (f.flags >> 1) & 1, (f.flags >> 2) & 1,
                  f.tof_q8 / 256.0, f.distance_um * 1e-6, f.score / 65536.0, f.margin / 65536.0);
    }
  }
  if (st.bad_frames || st.truncated || st.skipped_bytes) {
    std::cerr << "ranging frames: " << frames.size() << " good frames, " << st.bad_frames << " bad (checksum), "
              << st.skipped_bytes << " bytes skipped" << (st.truncated ? ", last frame truncated" : "") << "\n";
  }
  return (p.has("--strict") && (st.bad_frames || st.truncated)) ? 1 : 0;
}

}  // namespace ranging::tool
