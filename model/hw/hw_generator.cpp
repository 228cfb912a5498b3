#include "model/hw/hw_generator.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "model/base/error.hpp"
#include "model/hw/hw_emit.hpp"
#include "model/hw/hw_params.hpp"
#include "model/hw/realtime.hpp"
#include "model/hw/hw_system.hpp"

namespace ranging {
namespace {

namespace fs = std::filesystem;

std::string banner(const std::string& comment, const std::string& origin) {
  return emit::banner(comment, origin, "docs/hardware.md");
}

std::string hls_config(const std::vector<HwModuleParams>& mods, const std::string& origin) {
  std::ostringstream os;
  os << banner("//", origin) << "#pragma once\n#include <cstdint>\n\nnamespace ranging_hls {\n\n"
     << "// Every width, size and table of the receiver (see hls/receiver_hls.hpp).\n"
     << "struct ReceiverConfig {\n";
  for (const auto& m : mods) {
    os << "  // " << m.module << "\n";
    for (const auto& p : m.params) {
      const std::string name = m.module == "bandpass_sos"     ? "SOS_" + p.name
                               : m.module == "correlator_bank" ? "BANK_" + p.name
                                                               : "DET_" + p.name;
      if (p.element_bits == 0) {
        os << "  static constexpr std::int64_t " << name << " = " << p.elements[0] << ";\n";
      } else {
        os << "  static constexpr std::int64_t " << name << "[" << p.elements.size() << "] = {";
        for (std::size_t i = 0; i < p.elements.size(); ++i) {
          os << (i ? ", " : "") << p.elements[i];
        }
        os << "};\n";
      }
    }
  }
  os << "};\n\n}  // namespace ranging_hls\n";
  return os.str();
}

std::string manifest(const ReceiverDesign& d, const std::vector<HwModuleParams>& mods,
                     const std::string& origin) {
  nlohmann::json j;
  j["generated_from"] = origin;
  j["config"] = d.config.name;
  j["family"] = d.config.family;
  j["architecture"] = d.config.architecture;
  // The real-time budget (model/hw/realtime.hpp): the bitstream flow refuses a design that
  // does not keep pace (scripts/build_bitstream.sh).
  const RealTimeBudget rt = realtime_budget(d);
  j["real_time"] = {{"real_time", rt.real_time},
                    {"clocks_per_sample_available", rt.clocks_per_sample},
                    {"clocks_per_sample_needed", rt.needed_clocks_per_sample()},
                    {"group_clocks", rt.group_clocks},
                    {"bank_back_end_clocks_per_group", rt.bank_back_end_clocks},
                    {"combiner_clocks_per_group", rt.combiner_clocks},
                    {"detector_clocks_per_group", rt.detector_clocks},
                    {"summary", rt.summary()}};
  for (const auto& m : mods) {
    for (const auto& p : m.params) {
      if (p.element_bits == 0) {
        j["modules"][m.module][p.name] = p.elements[0];
      } else {
        j["modules"][m.module][p.name] = p.elements;
      }
    }
  }
  return emit::json_file(j);
}

std::string instance_params(const HwModuleParams& m) {
  return emit::instance_params(emit::verilog_params(m, /*sized=*/true));
}

const HwModuleParams& find(const std::vector<HwModuleParams>& mods, const std::string& name) {
  for (const auto& m : mods) {
    if (m.module == name) return m;
  }
  throw std::logic_error("no module " + name);
}

// The top: stages chained by valid/ready, the event stream out, a debug tap per stage.
std::string verilog_top(const std::vector<HwModuleParams>& mods, const std::string& origin) {
  const auto& sos = find(mods, "bandpass_sos");
  const auto& bank = find(mods, "correlator_bank");
  const auto& det = find(mods, "peak_detector");
  const auto in_w = sos.value("IN_W"), data_w = sos.value("DATA_W"), sections = sos.value("SECTIONS");
  const auto weighted_w = bank.value("WEIGHTED_W");
  const auto energy_w = bank.value("ENERGY_W"), time_w = bank.value("TIME_W");
  const auto chip_w = bank.value("CHIP_W"), corr_w = bank.value("CORR_W");
  const auto code_w = det.value("CODE_W"), frac_w = det.value("FRAC_W"), score_w = det.value("SCORE_W");
  const auto arrival_w = time_w + frac_w + 1;
  const auto event_w = code_w + arrival_w + 2 * score_w;
  // The bank's stream to the detector, tapped as the dbg_<name> ports: one list for the ports,
  // the bank_<name> wires and the assigns.
  struct Tap {
    const char* name;
    std::int64_t width;  // 0: a scalar wire
  };
  const Tap bank_stream[] = {{"weighted", weighted_w}, {"code", code_w}, {"last", 0}, {"energy", energy_w}, {"index", time_w}};
  std::ostringstream os;
  auto declare = [&](const char* kind, const Tap& t, const char* prefix, const char* end) {
    os << "  " << kind << " ";
    if (t.width > 0) os << "[" << t.width - 1 << ":0] ";
    os << prefix << t.name << end << "\n";
  };
  os << banner("//", origin)
     << "//\n"
        "// receiver_top: the coded-ultrasound receiver (docs/architecture.md):\n"
        "//   s_axis (signed ADC samples) -> bandpass_sos -> correlator_bank -> peak_detector -> m_axis (events)\n"
        "// Event word, LSB first: code (" << code_w << " bits, 1-based), arrival (" << arrival_w
     << " bits, signed sample index with " << frac_w << " fraction bits), score (" << score_w
     << " bits, rho^2), margin (" << score_w << " bits).\n"
        "// Back-pressure on m_axis stalls the pipeline back to s_axis_tready: no event is lost.\n"
        "// The dbg_* ports are the stage taps the testbenches compare with the golden model;\n"
        "// each is valid on the cycle its *_valid strobe is high (a completed beat). The bank\n"
        "// streams one beat per code: a decimated output is CODES beats, dbg_code = j (0-based)\n"
        "// with dbg_last on the last; energy, index and chip are the group's on every beat.\n"
        "`default_nettype none\n\n"
        "module receiver_top (\n"
        "  input  wire clk,\n"
        "  input  wire rst,\n"
        "  input  wire signed [" << in_w - 1 << ":0] s_axis_tdata,\n"
        "  input  wire s_axis_tvalid,\n"
        "  output wire s_axis_tready,\n"
        "  output wire [" << event_w - 1 << ":0] m_axis_tdata,\n"
        "  output wire m_axis_tvalid,\n"
        "  input  wire m_axis_tready,\n"
        "  output wire dbg_filter_valid,\n"
        "  output wire signed [" << data_w - 1 << ":0] dbg_filter_data,\n"
        "  output wire [" << sections * data_w - 1 << ":0] dbg_filter_sections,\n"
        "  output wire dbg_bank_valid,\n";
  for (const auto& t : bank_stream) declare("output wire", t, "dbg_", ",");
  os << "  output wire signed [" << chip_w - 1 << ":0] dbg_chip_re,\n"
        "  output wire signed [" << chip_w - 1 << ":0] dbg_chip_im,\n"
        "  output wire signed [" << corr_w - 1 << ":0] dbg_corr_re,\n"
        "  output wire signed [" << corr_w - 1 << ":0] dbg_corr_im\n"
        ");\n\n"
        "  wire signed [" << data_w - 1 << ":0] filter_data;\n"
        "  wire filter_valid, filter_ready;\n"
        "  wire bank_valid, bank_ready;\n";
  for (const auto& t : bank_stream) declare("wire", t, "bank_", ";");
  os << "  wire [" << code_w - 1 << ":0] event_code;\n"
        "  wire signed [" << arrival_w - 1 << ":0] event_arrival;\n"
        "  wire [" << score_w - 1 << ":0] event_score, event_margin;\n\n"
        "  bandpass_sos #(\n" << instance_params(sos) << "  ) u_filter (\n"
        "    .clk(clk), .rst(rst),\n"
        "    .s_data(s_axis_tdata), .s_valid(s_axis_tvalid), .s_ready(s_axis_tready),\n"
        "    .m_data(filter_data), .m_valid(filter_valid), .m_ready(filter_ready),\n"
        "    .m_sections(dbg_filter_sections)\n"
        "  );\n\n"
        "  correlator_bank #(\n" << instance_params(bank) << "  ) u_bank (\n"
        "    .clk(clk), .rst(rst),\n"
        "    .s_data(filter_data), .s_valid(filter_valid), .s_ready(filter_ready),\n"
        "    .m_valid(bank_valid), .m_ready(bank_ready),\n"
        "    .m_weighted(bank_weighted), .m_code(bank_code), .m_last(bank_last),\n"
        "    .m_energy(bank_energy), .m_index(bank_index),\n"
        "    .m_chip_re(dbg_chip_re), .m_chip_im(dbg_chip_im),\n"
        "    .m_corr_re(dbg_corr_re), .m_corr_im(dbg_corr_im)\n"
        "  );\n\n"
        "  peak_detector #(\n" << instance_params(det) << "  ) u_detector (\n"
        "    .clk(clk), .rst(rst),\n"
        "    .s_valid(bank_valid), .s_ready(bank_ready),\n"
        "    .s_weighted(bank_weighted), .s_last(bank_last),\n"
        "    .s_energy(bank_energy), .s_index(bank_index),\n"
        "    .m_valid(m_axis_tvalid), .m_ready(m_axis_tready),\n"
        "    .m_code(event_code), .m_arrival(event_arrival),\n"
        "    .m_score(event_score), .m_margin(event_margin)\n"
        "  );\n\n"
        "  assign m_axis_tdata = {event_margin, event_score, event_arrival, event_code};\n"
        "  assign dbg_filter_valid = filter_valid & filter_ready;\n"
        "  assign dbg_filter_data = filter_data;\n"
        "  assign dbg_bank_valid = bank_valid & bank_ready;\n";
  for (const auto& t : bank_stream) os << "  assign dbg_" << t.name << " = bank_" << t.name << ";\n";
  os << "\n"
        "endmodule\n\n`default_nettype wire\n";
  return os.str();
}

// GTKWave save file: the stages of receiver_top in order, as the testbench names them.
std::string gtkw(const std::vector<HwModuleParams>& mods, const std::string& origin) {
  const auto& sos = find(mods, "bandpass_sos");
  const auto& bank = find(mods, "correlator_bank");
  const auto& det = find(mods, "peak_detector");
  auto bus = [](const std::string& name, std::int64_t w) {
    return "TOP.receiver_top." + name + "[" + std::to_string(w - 1) + ":0]\n";
  };
  // An analog (step) trace, signed, four rows high.
  auto analog = [&](const std::string& name, std::int64_t w) {
    return "@8420\n" + bus(name, w) + "@20000\n-\n-\n-\n";
  };
  std::ostringstream os;
  os << banner("#", origin) << "[*] open with: gtkwave <trace>.fst receiver.gtkw\n"
     << "[timestart] 0\n[size] 1600 1000\n[pos] 0 0\n[sst_width] 1\n[signals_width] 300\n"
     << "@200\n-input samples\n@28\nTOP.receiver_top.s_axis_tvalid\nTOP.receiver_top.s_axis_tready\n"
     << analog("s_axis_tdata", sos.value("IN_W"))
     << "@200\n-bandpass filter\n@28\nTOP.receiver_top.dbg_filter_valid\n"
     << analog("dbg_filter_data", sos.value("DATA_W"))
     << "@200\n-correlator bank\n@28\nTOP.receiver_top.dbg_bank_valid\n"
     << analog("dbg_chip_re", bank.value("CHIP_W")) << analog("dbg_chip_im", bank.value("CHIP_W"))
     << "@22\n" << bus("dbg_code", det.value("CODE_W")) << "@28\nTOP.receiver_top.dbg_last\n@22\n"
     << bus("dbg_weighted", bank.value("WEIGHTED_W"))
     << bus("dbg_energy", bank.value("ENERGY_W")) << bus("dbg_index", bank.value("TIME_W"))
     << "@200\n-events\n@28\nTOP.receiver_top.m_axis_tvalid\nTOP.receiver_top.m_axis_tready\n"
     << "@22\n" << bus("event_code", det.value("CODE_W"))
     << bus("event_arrival", bank.value("TIME_W") + det.value("FRAC_W") + 1)
     << bus("event_score", det.value("SCORE_W")) << bus("event_margin", det.value("SCORE_W"));
  return os.str();
}

}  // namespace

std::map<std::string, std::string> generate_hardware_files(const ReceiverDesign& design,
                                                           const std::string& origin) {
  const auto mods = hardware_parameters(design);
  std::map<std::string, std::string> files;
  for (const auto& m : mods) files["rtl/" + m.module + ".vc"] = emit::vc_file(emit::verilog_params(m, false));
  files["rtl/receiver_top.v"] = verilog_top(mods, origin);
  files["receiver.gtkw"] = gtkw(mods, origin);
  files["hls/receiver_config.hpp"] = hls_config(mods, origin);
  files["manifest.json"] = manifest(design, mods, origin);
  for (const auto& [name, text] : generate_system_files(design, origin)) files[name] = text;
  return files;
}

void write_hardware_files(const std::map<std::string, std::string>& files, const std::string& out_dir) {
  const fs::path out = fs::absolute(out_dir);
  std::random_device rd;
  const fs::path tmp = out.parent_path() / (".tmp-" + out.filename().string() + "-" + std::to_string(rd()));
  std::error_code ec;
  fs::create_directories(out.parent_path(), ec);
  try {
    for (const auto& [name, text] : files) {
      const fs::path p = tmp / name;
      fs::create_directories(p.parent_path());
      std::ofstream f(p, std::ios::binary);
      f << text;
      if (!f) throw InputError("--out: cannot write " + p.string());
    }
    fs::remove_all(out);
    fs::rename(tmp, out);
  } catch (const fs::filesystem_error& e) {
    fs::remove_all(tmp, ec);
    throw InputError(std::string("--out: ") + e.what());
  } catch (...) {
    fs::remove_all(tmp, ec);
    throw;
  }
}

}  // namespace ranging
