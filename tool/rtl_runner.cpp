#include "tool/rtl_runner.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>

#include "model/base/subprocess.hpp"
#include "model/base/error.hpp"
#include "model/hw/hw_generator.hpp"
#include "model/hw/hw_params.hpp"
#include "model/hw/ip_package.hpp"
#include "tool/build_info.hpp"
#include "tool/shell.hpp"

namespace ranging::tool {
namespace {

namespace fs = std::filesystem;


std::string read(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

int shell(const std::string& cmd) {
  const int st = run_shell(cmd);
  return (st != -1 && WIFEXITED(st)) ? WEXITSTATUS(st) : -1;
}

// FNV-1a, 64 bit: the build cache key (stable across runs, unlike std::hash).
std::uint64_t fnv1a(const std::string& s, std::uint64_t h = 1469598103934665603ull) {
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

// A hex port value (most significant digit first) as little-endian 64-bit words.
struct Bits {
  std::vector<std::uint64_t> w;
  explicit Bits(const std::string& hex) {
    int shift = 0;
    std::uint64_t cur = 0;
    for (auto it = hex.rbegin(); it != hex.rend(); ++it) {
      const char c = *it;
      const std::uint64_t d = c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10;
      cur |= d << shift;
      shift += 4;
      if (shift == 64) {
        w.push_back(cur);
        cur = 0;
        shift = 0;
      }
    }
    if (shift) w.push_back(cur);
  }
  std::uint64_t get(int lo, int width) const {
    std::uint64_t r = 0;
    for (int b = 0; b < width; ++b) {
      const int i = lo + b;
      const std::size_t k = static_cast<std::size_t>(i / 64);
      if (k < w.size() && ((w[k] >> (i % 64)) & 1u)) r |= std::uint64_t{1} << b;
    }
    return r;
  }
  std::int64_t sget(int lo, int width) const {
    const std::uint64_t v = get(lo, width);
    if (width >= 64) return static_cast<std::int64_t>(v);
    const std::uint64_t m = std::uint64_t{1} << (width - 1);
    return static_cast<std::int64_t>(v ^ m) - static_cast<std::int64_t>(m);
  }
};

}  // namespace

fs::path default_work_dir(const std::string& what, const std::string& config_name) {
  const char* t = std::getenv("TMPDIR");
  const fs::path base = (t && *t) ? fs::path(t) : fs::path("/tmp");
  std::string safe;
  for (char c : config_name) safe += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') ? c : '_';
  // The project's source folder is part of the key: two checkouts (or installs) never share a
  // Verilator build whose make rules name the other's testbench sources.
  std::uint32_t h = 2166136261u;  // FNV-1a of kSourceDir
  for (char c : std::string(build_info::kSourceDir)) h = (h ^ static_cast<unsigned char>(c)) * 16777619u;
  char tag[9];
  std::snprintf(tag, sizeof tag, "%08x", h);
  return base / ("ranging-" + what + "-" + std::to_string(::getuid()) + "-" + safe + "-" + tag);
}

RtlReceiver::RtlReceiver(const ReceiverDesign& design, const RtlBuildOptions& options)
    : design_(design), opt_(options) {
  const auto mods = hardware_parameters(design);
  auto value = [&](const char* mod, const char* name) {
    for (const auto& m : mods) {
      if (m.module == mod) return static_cast<int>(m.value(name));
    }
    throw std::logic_error(std::string("no module ") + mod);
  };
  in_w_ = value("bandpass_sos", "IN_W");
  data_w_ = value("bandpass_sos", "DATA_W");
  sections_ = value("bandpass_sos", "SECTIONS");
  chip_w_ = value("correlator_bank", "CHIP_W");
  corr_w_ = value("correlator_bank", "CORR_W");
  time_w_ = value("correlator_bank", "TIME_W");
  code_w_ = value("peak_detector", "CODE_W");
  frac_w_ = value("peak_detector", "FRAC_W");
  score_w_ = value("peak_detector", "SCORE_W");

  const std::string src = build_info::kSourceDir;
  if (opt_.rtl_dir.empty()) opt_.rtl_dir = src + "/rtl";
  const fs::path work = fs::absolute(opt_.work_dir);
  opt_.work_dir = work;
  std::error_code ec;
  fs::create_directories(work, ec);
  if (ec) throw InputError("--out: cannot create " + work.string() + ": " + ec.message());
  lock_.fd = ::open((work / ".lock").c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0644);
  if (lock_.fd < 0 || ::flock(lock_.fd, LOCK_EX) != 0) {
    throw InputError("--out: cannot lock " + (work / ".lock").string() + ": " + std::strerror(errno));
  }

  // 1. The IP folder of this configuration (the user's RTL when --rtl is given).
  auto files = generate_hardware_files(design, opt_.origin);
  add_ip_package(files, design, opt_.rtl_dir, src + "/hls", build_info::kVersion, opt_.rtl_option);
  write_hardware_files(files, (work / "ip").string());

  // 2. The Verilated driver, rebuilt only when a source or the command changes.
  const bool sc = opt_.simulator == "systemc";
  const fs::path driver_src = fs::path(src) / (sc ? "tb/verify_driver_sc.cpp" : "tb/verify_driver.cpp");
  if (!fs::exists(driver_src)) throw InputError("cannot find the testbench source " + driver_src.string());
  if (shell("command -v verilator >/dev/null 2>&1") != 0) {
    throw InputError("verilator is not installed (Debian: apt-get install verilator)");
  }
  if (opt_.simulator != "verilator" && opt_.simulator != "postsynth" && opt_.simulator != "icarus" &&
      opt_.simulator != "hls" && opt_.simulator != "systemc") {
    throw InputError("simulator '" + opt_.simulator + "': valid are verilator, postsynth, icarus, hls, systemc");
  }
  if (opt_.simulator == "icarus") {
    build_icarus(work);
    return;
  }
  if (opt_.simulator == "hls") {
    build_hls(work);
    return;
  }
  const bool gates = opt_.simulator == "postsynth";
  const fs::path obj = work / (gates ? "obj-postsynth" : sc ? "obj-systemc" : "obj");
  std::string sc_env;
  if (sc) {
    // Debian's libsystemc-dev: headers in /usr/include, the library in the multiarch folder.
    const char* inc = std::getenv("SYSTEMC_INCLUDE");
    const char* lib = std::getenv("SYSTEMC_LIBDIR");
    const std::string inc_dir = inc && *inc ? inc : "/usr/include";
    const std::string lib_dir = lib && *lib ? lib : "/usr/lib/x86_64-linux-gnu";
    if (!fs::exists(fs::path(inc_dir) / "systemc.h")) {
      throw InputError("SystemC is not installed (" + inc_dir + "/systemc.h; Debian: apt-get install libsystemc-dev)");
    }
    sc_env = "SYSTEMC_INCLUDE=" + shell_quote(inc_dir) + " SYSTEMC_LIBDIR=" + shell_quote(lib_dir) + " ";
  }
  driver_ = obj / "verify_driver";
  std::string sources = "-f files.f";
  std::string netlist_cmd;
  if (gates) {
    // The netlist as scripts/build_bitstream.sh synthesizes it; yosys' iCE40 cell models.
    if (shell("command -v yosys >/dev/null 2>&1") != 0) {
      throw InputError("yosys is not installed (Debian: apt-get install yosys)");
    }
    // yosys' data folder (cells_sim.v) next to its binary: BIN/../share/yosys (yosys-config is
    // in yosys-dev, which the flow does not need).
    std::string datdir;
    {
      const char* path = std::getenv("PATH");
      std::istringstream dirs(path ? path : "/usr/bin");
      for (std::string d; std::getline(dirs, d, ':');) {
        if (!d.empty() && fs::exists(fs::path(d) / "yosys")) {
          const fs::path share = fs::weakly_canonical(fs::path(d) / "yosys").parent_path().parent_path() / "share/yosys";
          if (fs::exists(share / "ice40/cells_sim.v")) datdir = share.string();
          break;
        }
      }
    }
    if (datdir.empty()) throw InputError("cannot find yosys' ice40/cells_sim.v (BIN/../share/yosys next to yosys)");
    std::string reads;
    std::istringstream fl(read(work / "ip/files.f"));
    for (std::string line; std::getline(fl, line);) {
      if (!line.empty()) reads += "read_verilog -defer -I. " + line + "; ";
    }
    netlist_cmd = "cd " + shell_quote((work / "ip").string()) + " && yosys -q -l ../postsynth-yosys.log -p '" + reads +
                  "hierarchy -top receiver_top; synth_ice40 -dsp -top receiver_top; write_verilog -noattr "
                  "../receiver_top_syn.v' > /dev/null 2>&1";
    sources = "-DNO_ICE40_DEFAULT_ASSIGNMENTS ../receiver_top_syn.v " + shell_quote(datdir + "/ice40/cells_sim.v");
  }
  const std::string cmd = "cd " + shell_quote((work / "ip").string()) + " && " + sc_env + "verilator " +
                          std::string(sc ? "--sc -CFLAGS -DSC_CPLUSPLUS=201703L" : "--cc") +
                          " --exe --build -j 2 -Wno-fatal -Wno-lint -Wno-style" +
                          std::string(gates ? " --no-timing" : "") +
                          " --x-assign unique --x-initial unique -O3 -CFLAGS -O1" +
                          std::string(opt_.trace ? " --trace-fst" : "") + " " + sources +
                          " --top-module receiver_top --Mdir " + shell_quote(obj.string()) +
                          " -o verify_driver " + shell_quote(driver_src.string());
  std::uint64_t key = fnv1a(netlist_cmd + cmd + read(driver_src));
  for (const char* h : {"tb/verilator_harness.hpp", "tb/bits.hpp", "tb/driver_stimulus.hpp"}) {
    key = fnv1a(read(fs::path(src) / h), key);
  }
  std::istringstream list(read(work / "ip/files.f"));
  for (std::string line; std::getline(list, line);) key = fnv1a(read(work / "ip" / line), key);
  const std::string stamp = std::to_string(key);
  const fs::path stamp_file = obj / ".ranging-stamp";
  if (fs::exists(driver_) && read(stamp_file) == stamp) return;
  const fs::path log = work / "build.log";
  if (!opt_.quiet) {
    std::cerr << "building the Verilated " << (gates ? "post-synthesis netlist" : "receiver_top") << " of '"
              << design.config.name << "' in " << work.string()
              << (gates ? " (yosys synth_ice40 and verilator --build: a few minutes) ..."
                        : " (verilator --build: about 1-2 minutes) ...") << std::flush;
  }
  const auto t0 = std::chrono::steady_clock::now();
  fs::remove(stamp_file, ec);
  const int rc = shell((netlist_cmd.empty() ? "" : "(" + netlist_cmd + ") && ") + cmd + " > " + shell_quote(log.string()) + " 2>&1");
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!opt_.quiet) std::cerr << (rc == 0 ? " done" : " failed") << " in " << static_cast<int>(build_seconds_) << " s\n";
  if (rc != 0 || !fs::exists(driver_)) {
    std::string first;
    std::istringstream ls(read(log));
    for (std::string line; std::getline(ls, line);) {
      if (line.find("%Error") != std::string::npos || line.find("error:") != std::string::npos) {
        first = line;
        break;
      }
    }
    throw InputError(opt_.rtl_option + ": the Verilated receiver does not build from the RTL in " + opt_.rtl_dir + " (" +
                     (first.empty() ? "see the log" : first) + "); log: " + log.string());
  }
  std::ofstream(stamp_file) << stamp;
  rebuilt_ = true;
}

// Icarus Verilog: the RTL of the IP folder with a generated testbench (the Verilog twin of
// tb/verify_driver.cpp: the same stimulus and output formats, so run() decodes both alike).
void RtlReceiver::build_icarus(const fs::path& work) {
  if (shell("command -v iverilog >/dev/null 2>&1 && command -v vvp >/dev/null 2>&1") != 0) {
    throw InputError("Icarus Verilog is not installed (Debian: apt-get install iverilog)");
  }
  const int arrival_w = time_w_ + frac_w_ + 1, event_w = code_w_ + arrival_w + 2 * score_w_;
  auto wire = [](int w, const char* name) { return "  wire [" + std::to_string(w - 1) + ":0] " + name + ";\n"; };
  std::ostringstream tb;
  tb << "// Generated by tool/rtl_runner.cpp (ranging simulate --rtl-simulator icarus): drives\n"
        "// receiver_top with the stimulus of tb/verify_driver.cpp and writes its output format.\n"
        "`timescale 1ns/1ps\nmodule ranging_icarus_tb;\n"
        "  reg clk = 0, rst = 1, s_valid = 0, m_ready = 0;\n"
        "  reg [" << in_w_ - 1 << ":0] s_data = 0;\n"
     << wire(event_w, "m_data") << wire(data_w_, "f_data") << wire(sections_ * data_w_, "f_sections")
     << wire(static_cast<int>(design_.layout.weighted_bits), "b_weighted") << wire(code_w_, "b_code")
     << wire(static_cast<int>(design_.layout.energy_bits), "b_energy") << wire(time_w_, "b_index")
     << wire(chip_w_, "b_chip_re") << wire(chip_w_, "b_chip_im") << wire(corr_w_, "b_corr_re")
     << wire(corr_w_, "b_corr_im")
     << "  wire s_ready, m_valid, f_valid, b_valid, b_last;\n"
        "  receiver_top dut(.clk(clk), .rst(rst), .s_axis_tdata(s_data), .s_axis_tvalid(s_valid),\n"
        "    .s_axis_tready(s_ready), .m_axis_tdata(m_data), .m_axis_tvalid(m_valid), .m_axis_tready(m_ready),\n"
        "    .dbg_filter_valid(f_valid), .dbg_filter_data(f_data), .dbg_filter_sections(f_sections),\n"
        "    .dbg_bank_valid(b_valid), .dbg_weighted(b_weighted), .dbg_code(b_code), .dbg_last(b_last),\n"
        "    .dbg_energy(b_energy), .dbg_index(b_index), .dbg_chip_re(b_chip_re), .dbg_chip_im(b_chip_im),\n"
        "    .dbg_corr_re(b_corr_re), .dbg_corr_im(b_corr_im));\n"
        "  integer fin, fout, rc, vp, rp, seed, reset_at, quiet, n, cadence, i, next, idle, silent, cycles, beat, offer;\n"
        "  integer late, due;\n"
        "  reg [8*64-1:0] name;\n"
        "  reg [" << in_w_ - 1 << ":0] x [0:" << (1 << 20) - 1 << "];\n"
        "  reg [" << 8 * 1024 - 1 << ":0] stim_path, out_path;\n"
        "  task tick; begin #5 clk = 1; #5 clk = 0; end endtask\n"
        "  task do_reset; begin s_valid = 0; m_ready = 0; rst = 1; repeat (4) tick; rst = 0; end endtask\n"
        "  initial begin\n"
        "    if (!$value$plusargs(\"stim=%s\", stim_path) || !$value$plusargs(\"out=%s\", out_path)) begin\n"
        "      $display(\"usage: vvp sim +stim=FILE +out=FILE\"); $finish_and_return(2); end\n"
        "    fin = $fopen(stim_path, \"r\"); fout = $fopen(out_path, \"w\");\n"
        "    if (fin == 0 || fout == 0) begin $display(\"cannot open the stimulus or output\"); $finish_and_return(2); end\n"
        "    while ($fscanf(fin, \" run %s %d %d %d %d %d %d %d\", name, vp, rp, seed, reset_at, quiet, n, cadence) == 8) begin\n"
        "      for (i = 0; i < n; i = i + 1) rc = $fscanf(fin, \"%d\", x[i]);\n"
        "      $fwrite(fout, \"run %0s\\n\", name);\n"
        "      do_reset; next = 0; cycles = 0; idle = 0; silent = 0; late = 0; due = 0;\n"
        "      while (next < n || silent < quiet) begin\n"
        "        if (reset_at >= 0 && next == reset_at) begin do_reset; $fwrite(fout, \"R\\n\"); reset_at = -1; end\n"
        "        offer = (next < n) && (cadence > 0 ? cycles >= due : (($random(seed) & 32'h7fffffff) % 1000000 < vp));\n"
        "        s_valid = offer; if (offer) s_data = x[next];\n"
        "        m_ready = (($random(seed) & 32'h7fffffff) % 1000000 < rp);\n"
        "        #1; beat = 0;\n"
        "        if (offer && s_ready) begin next = next + 1; idle = 0;\n"
        "          if (cadence > 0) begin if (cycles > due) late = late + 1; due = due + cadence; end end\n"
        "        if (f_valid) begin $fwrite(fout, \"F %h %h\\n\", f_data, f_sections); beat = 1; end\n"
        "        if (b_valid) begin $fwrite(fout, \"B %h %h %h %h %h %h %h %h %h\\n\", b_code, b_last, b_weighted,\n"
        "            b_energy, b_index, b_chip_re, b_chip_im, b_corr_re, b_corr_im); beat = 1; end\n"
        "        if (m_valid && m_ready) begin $fwrite(fout, \"E %h\\n\", m_data); beat = 1; end\n"
        "        #4 clk = 1; #5 clk = 0;\n"
        "        cycles = cycles + 1;\n"
        "        silent = (beat || next < n) ? 0 : silent + 1;\n"
        "        if (next < n) begin idle = idle + 1; if (idle > 200000) begin $fwrite(fout, \"S %0d\\n\", next); quiet = 0; n = next; end end\n"
        "      end\n"
        "      $fwrite(fout, \"end %0d %0d %0d\\n\", next, cycles, late);\n"
        "    end\n"
        "    $fclose(fout); $finish;\n"
        "  end\n"
        "endmodule\n";
  const fs::path obj = work / "obj-icarus";
  fs::create_directories(obj);
  const fs::path tb_file = obj / "ranging_icarus_tb.v";
  const std::string cmd = "cd " + shell_quote((work / "ip").string()) + " && iverilog -g2012 -o " +
                          shell_quote((obj / "sim").string()) + " -s ranging_icarus_tb -f files.f " + shell_quote(tb_file.string());
  std::uint64_t key = fnv1a(cmd + tb.str());
  std::istringstream list(read(work / "ip/files.f"));
  for (std::string line; std::getline(list, line);) key = fnv1a(read(work / "ip" / line), key);
  driver_ = obj / "sim";
  const fs::path stamp_file = obj / ".ranging-stamp";
  if (fs::exists(driver_) && read(stamp_file) == std::to_string(key)) return;
  std::ofstream(tb_file) << tb.str();
  const fs::path log = work / "build-icarus.log";
  const int rc = shell(cmd + " > " + shell_quote(log.string()) + " 2>&1");
  if (rc != 0 || !fs::exists(driver_)) {
    throw InputError(opt_.rtl_option + ": Icarus does not compile the RTL in " + opt_.rtl_dir + "; log: " + log.string());
  }
  std::ofstream(stamp_file) << key;
  rebuilt_ = true;
}

// The HLS C++ of the IP folder (hls/*.hpp and this configuration's receiver_config.hpp),
// compiled with the host compiler around tb/hls_driver.cpp.
void RtlReceiver::build_hls(const fs::path& work) {
  const std::string src = build_info::kSourceDir;
  const fs::path driver_src = fs::path(src) / "tb/hls_driver.cpp";
  if (!fs::exists(driver_src)) throw InputError("cannot find the driver source " + driver_src.string());
  const char* cxx_env = std::getenv("CXX");
  const std::string cxx = cxx_env && *cxx_env ? cxx_env : "c++";
  const fs::path obj = work / "obj-hls";
  fs::create_directories(obj);
  driver_ = obj / "hls_driver";
  const std::string cmd = shell_quote(cxx) + " -std=c++20 -O2 -I " + shell_quote((work / "ip").string()) + " -o " +
                          shell_quote(driver_.string()) + " " + shell_quote(driver_src.string());
  std::uint64_t key = fnv1a(cmd + read(driver_src) + read(fs::path(src) / "tb/driver_stimulus.hpp"));
  for (const auto& e : fs::directory_iterator(work / "ip/hls")) key = fnv1a(read(e.path()), key);
  const fs::path stamp_file = obj / ".ranging-stamp";
  if (fs::exists(driver_) && read(stamp_file) == std::to_string(key)) return;
  const fs::path log = work / "build-hls.log";
  if (shell(cmd + " > " + shell_quote(log.string()) + " 2>&1") != 0 || !fs::exists(driver_)) {
    throw InputError("the HLS C++ of this configuration does not compile (" + cxx + "); log: " + log.string());
  }
  std::ofstream(stamp_file) << key;
  rebuilt_ = true;
}

RtlReceiver::Lock::~Lock() {
  if (fd >= 0) ::close(fd);  // releases the flock
}

std::vector<RtlResult> RtlReceiver::run(const std::vector<RtlStimulus>& stimuli) const {
  const fs::path dir = opt_.work_dir / "runs";
  fs::create_directories(dir);
  const fs::path stim = dir / "stimulus.txt", out = dir / "taps.txt";
  {
    std::ofstream f(stim);
    const std::uint64_t mask = (std::uint64_t{1} << in_w_) - 1;
    for (const auto& s : stimuli) {
      if (opt_.simulator == "icarus") {  // integer probabilities (per million) for $fscanf %d
        if (s.x.size() > (std::size_t{1} << 20)) throw InputError("icarus: a stream of more than 2^20 samples");
        f << "run " << s.name << " " << std::llround(s.valid_prob * 1e6) << " " << std::llround(s.ready_prob * 1e6)
          << " " << (s.seed & 0x7fffffff) << " " << s.reset_at << " 50000 " << s.x.size() << " " << s.cadence << "\n";
      } else {
        f << "run " << s.name << " " << s.valid_prob << " " << s.ready_prob << " " << s.seed << " " << s.reset_at
          << " 50000 " << s.x.size() << " " << s.cadence << "\n";
      }
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        f << (static_cast<std::uint64_t>(s.x[i]) & mask) << ((i + 1) % 16 == 0 ? "\n" : " ");
      }
      f << "\n";
    }
    if (!f) throw InputError("cannot write " + stim.string());
  }
  std::string env = "RANGING_TRACE_DIR=" + shell_quote(opt_.work_dir.string()) + " ";
  if (opt_.trace) env += "RANGING_TRACE=1 ";
  const std::string run_cmd = opt_.simulator == "icarus"
                                  ? "vvp -n " + shell_quote(driver_.string()) + " +stim=" + shell_quote(stim.string()) + " +out=" +
                                        shell_quote(out.string()) + " > " + shell_quote((dir / "vvp.log").string()) + " 2>&1"
                                  : env + shell_quote(driver_.string()) + " " + shell_quote(stim.string()) + " " + shell_quote(out.string());
  const int rc = shell(run_cmd);
  if (rc != 0) throw std::runtime_error("the Verilated driver failed (status " + std::to_string(rc) + ")");

  std::vector<RtlResult> results;
  std::ifstream f(out);
  for (std::string line; std::getline(f, line);) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "run") {
      results.emplace_back();
      ls >> results.back().name;
      results.back().segments.emplace_back();
      continue;
    }
    if (results.empty()) throw std::runtime_error("driver output: no run header");
    RtlResult& r = results.back();
    RtlSegment& seg = r.segments.back();
    if (tag == "F") {
      std::string d, s;
      ls >> d >> s;
      RtlFilterBeat b;
      b.data = Bits(d).sget(0, data_w_);
      const Bits sb(s);
      for (int k = 0; k < sections_; ++k) b.sections.push_back(sb.sget(k * data_w_, data_w_));
      seg.filter.push_back(std::move(b));
    } else if (tag == "B") {
      std::string code, last, q, e, idx, cre, cim, kre, kim;
      ls >> code >> last >> q >> e >> idx >> cre >> cim >> kre >> kim;
      RtlBankBeat b;
      b.code = static_cast<int>(Bits(code).get(0, code_w_));
      b.last = Bits(last).get(0, 1) != 0;
      b.weighted = Bits(q).get(0, design_.layout.weighted_bits);
      b.energy = Bits(e).get(0, design_.layout.energy_bits);
      b.index = static_cast<std::int64_t>(Bits(idx).get(0, time_w_));
      b.chip_re = Bits(cre).sget(0, chip_w_);
      b.chip_im = Bits(cim).sget(0, chip_w_);
      b.corr_re = Bits(kre).sget(0, corr_w_);
      b.corr_im = Bits(kim).sget(0, corr_w_);
      seg.bank.push_back(b);
    } else if (tag == "E") {
      std::string t;
      ls >> t;
      const Bits b(t);
      const int arrival_w = time_w_ + frac_w_ + 1;
      EventFixed ev;
      ev.code = static_cast<int>(b.get(0, code_w_));
      ev.arrival = b.sget(code_w_, arrival_w);
      ev.score = b.get(code_w_ + arrival_w, score_w_);
      ev.margin = b.get(code_w_ + arrival_w + score_w_, score_w_);
      seg.events.push_back(ev);
    } else if (tag == "V") {  // an event from the HLS driver, in decimal fields
      EventFixed ev;
      std::uint64_t score = 0, margin = 0;
      ls >> ev.code >> ev.arrival >> score >> margin;
      ev.score = score;
      ev.margin = margin;
      seg.events.push_back(ev);
    } else if (tag == "R") {
      r.segments.emplace_back();
    } else if (tag == "S") {
      r.stalled = true;
    } else if (tag == "end") {
      ls >> r.samples_taken >> r.cycles >> r.late;
    }
  }
  if (results.size() != stimuli.size()) throw std::runtime_error("driver output: runs missing");
  return results;
}

}  // namespace ranging::tool
