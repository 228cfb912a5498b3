// `ranging bitstream`: the iCEBreaker bitstream of any receiver configuration (docs/bitstream.md).
// The configuration is loaded and its system designed here first (every bad key is reported with
// file:line before minutes of synthesis), then scripts/build_bitstream.sh runs the open flow
// (ranging generate -> yosys -> nextpnr-ice40 over --seeds seeds, --jobs at a time -> icepack ->
// icetime) into --out; its progress goes to stderr, the summary (OUT/results/bitstream.{json,md})
// to stdout on success.
//
// --program writes the bitstream into the board's flash with iceprog (fpga-icestorm) or, without
// it, openFPGALoader. The board is probed before the flow starts (iceprog -t reads the flash ID;
// openFPGALoader --detect): with no programmer installed or no board attached, the command fails
// at once with exit status 2 (a request this machine cannot serve, like bad input) and builds
// nothing. --bin FILE programs an existing bitstream without building one.
#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include <nlohmann/json.hpp>

#include "model/base/subprocess.hpp"
#include "model/base/error.hpp"
#include "model/config/receiver_config.hpp"
#include "model/hw/hw_params.hpp"
#include "model/hw/hw_system.hpp"
#include "tool/build_info.hpp"
#include "tool/cli.hpp"
#include "tool/commands.hpp"
#include "tool/options.hpp"
#include "tool/rtl_runner.hpp"
#include "tool/shell.hpp"

namespace ranging::tool {
namespace {

namespace fs = std::filesystem;


int exit_status(int st) { return (st != -1 && WIFEXITED(st)) ? WEXITSTATUS(st) : -1; }

// Runs cmd with stdout and stderr captured; returns the exit status.
int capture(const std::string& cmd, std::string& output) {
  FILE* pipe = ::popen((cmd + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return -1;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) output.append(buf, n);
  return exit_status(::pclose(pipe));
}

bool on_path(const std::string& tool) {
  std::string ignored;
  return capture("command -v " + shell_quote(tool), ignored) == 0;
}

std::string last_line(const std::string& text) {
  std::istringstream is(text);
  std::string line, last;
  while (std::getline(is, line)) {
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  }
  return last.empty() ? "(no output)" : last;
}

struct Programmer {
  std::string name;                  // iceprog or openFPGALoader
  std::string probe, write_prefix;   // shell commands
};

// The programmer to use and a probe that the board answers; InputError (exit 2) otherwise.
Programmer find_board() {
  Programmer p;
  if (on_path("iceprog")) {
    p = {"iceprog", "iceprog -t", "iceprog "};
  } else if (on_path("openFPGALoader")) {
    p = {"openFPGALoader", "openFPGALoader -b ice40_generic --detect", "openFPGALoader -b ice40_generic -f "};
  } else {
    throw InputError("option --program: no programmer found: install iceprog (Debian package fpga-icestorm) or "
                     "openFPGALoader (scripts/install-deps.sh --hardware installs fpga-icestorm)");
  }
  std::string out;
  if (capture(p.probe, out) != 0) {
    throw InputError("option --program: no iCEBreaker board answers (`" + p.probe + "`: " + last_line(out) +
                     "); connect the board by USB (and check its permissions), or build without --program");
  }
  return p;
}

void program(const Programmer& p, const std::string& bin) {
  std::cerr << "[bitstream] " << p.write_prefix << bin << "\n";
  std::string out;
  if (capture(p.write_prefix + shell_quote(bin), out) != 0) {
    throw InputError("option --program: `" + p.write_prefix + bin + "` failed: " + last_line(out));
  }
}

fs::path self_exe() {
  std::error_code ec;
  fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw std::runtime_error("bitstream: cannot find the ranging executable (/proc/self/exe)");
  return p;
}

}  // namespace

int cmd_bitstream(const Args& args) {
  cli::Parser p = command_parser("bitstream");
  add_config_options(p, {.required = true, .writes_effective = true,
                         .config_note = "; its system: section sets clock, UART, speed of sound"});
  p.option("--board", "NAME", "target board; valid: icebreaker", "icebreaker");
  p.option("--seeds", "N", "place and route with nextpnr seeds 1..N and keep the fastest (1-99)", "1");
  p.option("--jobs", "N", "seeds placed and routed at the same time (1-99)", "1");
  p.option("--out", "DIR", "work and report folder (default: $TMPDIR/ranging-bitstream-UID-NAME)");
  p.flag("--check", "exit 1 unless the targets of docs/bitstream.md are met (LUT4, SB_MAC16, EBR, Fmax)");
  p.option("--min-seeds", "K", "with --check: at least K of the seeds must reach 1.1x the clock (1..N)", "1");
  p.flag("--estimates", "also estimate ECP5 and Xilinx 7 resources of this configuration with yosys");
  p.flag("--program", "write the bitstream into the board's flash (iceprog or openFPGALoader)");
  p.option("--bin", "FILE", "with --program: program this bitstream, build nothing");
  if (!p.parse(args)) return 0;
  const std::string board = p.get_or("--board", "icebreaker");
  if (board != "icebreaker") throw InputError("option --board: '" + board + "' is not supported; valid: icebreaker");
  const long long seeds = p.integer("--seeds", 1, 1, 99);
  const long long jobs = p.integer("--jobs", 1, 1, 99);
  const long long min_seeds = p.integer("--min-seeds", 1, 1, 99);
  if (min_seeds > seeds) {
    throw InputError("option --min-seeds: " + std::to_string(min_seeds) + " is more than the " + std::to_string(seeds) +
                     " seed(s) tried; valid: 1.." + std::to_string(seeds) + " (--seeds N)");
  }
  if (p.has("--min-seeds") && !p.has("--check")) throw InputError("option --min-seeds: only with --check");
  const bool do_program = p.has("--program");

  if (p.has("--bin")) {
    if (!do_program) throw InputError("option --bin: only with --program (it names the bitstream to program)");
    if (p.has("--config") || p.has("--set")) throw InputError("option --bin: programs an existing bitstream; give no --config");
    const std::string bin = *p.get("--bin");
    std::error_code ec;
    if (!fs::is_regular_file(bin, ec)) throw InputError("option --bin: no file '" + bin + "'");
    const Programmer prog = find_board();
    program(prog, bin);
    std::cout << "programmed " << bin << " with " << prog.name << "\n";
    return 0;
  }

  const std::string config = p.required("--config");
  Overrides overrides;
  const ReceiverConfig cfg = load_config_options(p, "bitstream", &overrides);
  check_generatable(cfg);
  try {  // the system design (period, UART divider, calibration) before minutes of synthesis
    (void)system_design(design_receiver(cfg));
  } catch (const InputError& e) {
    throw InputError(locate_in_config(config, e.what()));
  }
  const fs::path out = fs::absolute(p.get_or("--out", default_work_dir("bitstream", cfg.name).string()));
  {
    std::error_code ec;
    if (fs::exists(out, ec) && !fs::is_directory(out, ec)) {
      throw InputError("option --out: '" + out.string() + "' exists and is not a folder; expected a folder");
    }
    const fs::path src = fs::weakly_canonical(build_info::kSourceDir);
    const fs::path o = fs::weakly_canonical(out);
    const auto rel = o.lexically_relative(src);
    if (!rel.empty() && *rel.begin() != ".." && !p.has("--out")) {
      throw InputError("option --out: the default '" + out.string() + "' is inside the source tree; give --out");
    }
  }
  Programmer prog;
  if (do_program) prog = find_board();  // fail before the flow, not after it

  fs::create_directories(out);
  std::string config_path = fs::absolute(config).string();
  if (!overrides.empty()) {  // the effective configuration, as generate --set writes it
    config_path = (out / "config.yaml").string();
    std::ofstream f(config_path);
    f << receiver_config_yaml(cfg);
    if (!f) throw InputError("option --out: cannot write " + config_path);
  }
  const fs::path results = out / "results";
  std::error_code ec;
  fs::remove(results / "bitstream.json", ec);
  const std::string script = std::string(build_info::kSourceDir) + "/scripts/build_bitstream.sh";
  std::string cmd = shell_quote(script) + " --config " + shell_quote(config_path) + " --ranging " + shell_quote(self_exe().string()) +
                    " --out " + shell_quote(out.string()) + " --results " + shell_quote(results.string()) + " --seeds " +
                    std::to_string(seeds) + " --jobs " + std::to_string(jobs) + " --no-large";
  if (!p.has("--estimates")) cmd += " --no-others";
  if (p.has("--check")) cmd += " --check --min-seeds " + std::to_string(min_seeds);
  cmd += " 1>&2";  // progress and the script's summary on stderr; ours on stdout
  const int rc = exit_status(run_shell(cmd));
  if (rc == 2 || rc < 0 || !fs::exists(results / "bitstream.json")) {
    throw InputError("the flow failed (scripts/build_bitstream.sh exit status " + std::to_string(rc) +
                     "; its message is above, logs in " + out.string() + ")");
  }
  nlohmann::json summary;
  {
    std::ifstream f(results / "bitstream.json");
    summary = nlohmann::json::parse(f);
  }
  const auto& ic = summary["ice40"];
  const bool met = summary.value("targets_met", false);
  if (rc == 1) {
    std::cerr << "ranging bitstream: targets not met:";
    for (const auto& f : summary["target_failures"]) std::cerr << "\n  " << f.get<std::string>();
    std::cerr << "\n(summary: " << (results / "bitstream.md").string() << ")\n";
    return 1;
  }
  if (rc != 0) throw InputError("scripts/build_bitstream.sh exited with status " + std::to_string(rc));
  const bool routed = ic.value("placed_and_routed", false);
  if (do_program && !routed) {
    throw InputError("option --program: the design was not placed and routed (" +
                     ic.value("nextpnr_error", std::string("nextpnr failed")) + "): nothing to program");
  }
  // Placed and routed, but slower than the clock it must run at: the board would compute wrong
  // results, so it is neither programmed nor reported as built.
  const double fmax = ic.value("fmax_mhz", 0.0), required = ic.value("required_clock_mhz", 0.0);
  const bool too_slow = routed && fmax < required;
  if (do_program && too_slow) {
    throw InputError("option --program: the design reaches Fmax " + std::to_string(fmax) + " MHz, below its " +
                     std::to_string(required) + " MHz clock: not programmed");
  }
  const fs::path bin = out / "ranging_icebreaker.bin";
  if (do_program) program(prog, bin.string());
  std::cout << "configuration " << cfg.name << " (" << config << "), board " << board << "\n"
            << "LUT4 " << ic.value("lut4", 0) << " / 5280, SB_MAC16 " << ic.value("sb_mac16", 0) << " / 8, EBR "
            << ic.value("ebr", 0) << " / 30\n";
  if (routed) {
    std::cout << "placed and routed: Fmax " << ic.value("fmax_mhz", 0.0) << " MHz at "
              << ic.value("required_clock_mhz", 0.0) << " MHz required (seed " << ic.value("nextpnr_seed", 0)
              << " of " << seeds << ")\n";
    if (seeds > 1 && ic.contains("nextpnr_seed_fmax_mhz")) {
      std::map<int, double> by_seed;  // the JSON object's keys sort as text ("10" before "2")
      for (const auto& [k, v] : ic["nextpnr_seed_fmax_mhz"].items()) by_seed[std::stoi(k)] = v.get<double>();
      std::cout << "Fmax per seed (MHz):";
      for (const auto& [k, v] : by_seed) std::cout << " " << k << ": " << v;
      std::cout << "\n";
    }
    std::cout << "bitstream " << bin.string() << "\n";
  } else {
    std::cout << "not placed and routed: " << ic.value("nextpnr_error", std::string("nextpnr failed")) << "\n";
  }
  std::cout << "targets " << (met ? "met" : "not met") << "; summary " << (results / "bitstream.md").string() << "\n";
  if (!routed) {
    std::cerr << "ranging bitstream: no bitstream: the design did not place and route on the iCE40UP5K (LUT4 "
              << ic.value("lut4", 0) << " / 5280; " << ic.value("nextpnr_error", std::string("nextpnr failed"))
              << ")\n";
    return 1;
  }
  if (too_slow) {
    std::cerr << "ranging bitstream: the bitstream does not run at its clock: Fmax " << fmax << " MHz < "
              << required << " MHz required\n";
    return 1;
  }
  if (do_program) std::cout << "programmed with " << prog.name << "\n";
  return 0;
}

}  // namespace ranging::tool
