// The subcommands of `ranging`: what `ranging help` lists and what `ranging NAME --help` says
// above the options (each command adds its options to command_parser(NAME)).
#include "tool/commands.hpp"

#include <stdexcept>

namespace ranging::tool {
namespace {

constexpr Command kCommands[] = {
    {"demo", cmd_demo, "encode every code of a family, send it through a channel, decode it (float and fixed)",
     "Encode every code of a family, send it through a simple channel (delay at the\n"
     "speed of sound, 1/d spreading, resonant transducers, white noise), filter and\n"
     "decode it with the float and the bit-accurate fixed-point receiver, and print per\n"
     "code: sent, decoded, ToF, distance, error, and the paper's u (eq. 12)."},
    {"codes", cmd_codes, "list code families, print their codes (M-sequences, Gold codes)",
     "Print the spreading codes: the paper's families M1..M4 and Gold1..Gold7 "
     "(Tables 1-3), generic families mseq-N and gold-N, or one LFSR m-sequence.\n"
     "Polynomial mask: bit k is the coefficient of x^k (0x13 = x^4 + x + 1).",
     "codes (--list | --family NAME | --degree N [--poly 0xHEX]) [--json]"},
    {"filter", cmd_filter, "design the bandpass filter; print sections and quantized coefficients",
     "Design the bandpass IIR filter (analog prototype -> bandpass -> bilinear, as\n"
     "scipy/MATLAB) and print its second-order sections. Defaults are the paper's\n"
     "spec (section 3.3.1)."},
    {"generate", cmd_generate, "generate the HLS C++ and Verilog of a receiver configuration",
     "Generate the self-contained IP folder of the receiver described by a configuration\n"
     "file: the Verilog top and parameters, copies of every RTL source it needs, the HLS\n"
     "C++ and its configuration header, filelists (files.f: receiver_top, system.f: the\n"
     "ranging system), a README of the ports, a FuseSoC CAPI2 .core file and a GTKWave\n"
     "save file. The output folder is replaced atomically: on error nothing is written."},
    {"simulate", cmd_simulate, "run a scene: channel, receiver, per-measurement CSV and summary JSON",
     "Run a scene (docs/scenes.md): build exactly the channel stages it names, send its\n"
     "codes over its distances and decode them. Writes DIR/measurements.csv (one row per\n"
     "measurement), DIR/summary.json and the effective scene (DIR/scene.yaml, and its\n"
     "receiver configuration DIR/config.yaml: `ranging simulate DIR/scene.yaml` repeats the\n"
     "run); prints the stages built and a summary."},
    {"evaluate", cmd_evaluate, "reproduce the paper's Section 4 evaluation (Tables 4-6, Figures 13-15)",
     "Reproduce the paper's Section 4 from a scene: Table 4 (u_min, Energy_min), Table 5\n"
     "(T_d-max), Table 6 (v_max), Figures 13-15 (PNG via scripts/plot_section4.py) and a\n"
     "generated Markdown document comparing the paper's values with ours."},
    {"decode", cmd_decode, "decode a recorded capture (oscilloscope CSV or WAV)",
     "Decode a capture: oscilloscope CSV (header lines, then rows 'time_s,volts[,more\n"
     "channels]'; ';', tab or space separators too; one column of samples with --sample-rate)\n"
     "or WAV (8/16/24/32-bit PCM, 32/64-bit float; --channel picks one of several), t = 0 at\n"
     "the start of transmission of the first burst. The receiver (bandpass, correlator bank, peak\n"
     "detector) adapts to the file's sample rate (it must be an integer multiple of the\n"
     "200 kHz carrier); its latency and the Pearson references are simulated with the\n"
     "calibrated transducers (docs/scenes.md) unless --references gives recorded ones\n"
     "(DIR/<family>-<j>.csv or .wav); --calibrate corrects the latency with a capture at a\n"
     "known --distance. The Pearson decoder is the paper's matched filter (each reference's\n"
     "best rho over lags within +-L chips).\n"
     "Metadata in the capture (CSV header lines or a sidecar STEM.json, as `simulate\n"
     "--write-captures` writes) supply the family, speed of sound and burst period unless an\n"
     "option overrides them; the output says which was used.\n"
     "Exit status: 0 at least one burst passed the --min-rho gate; 1 nothing passed it\n"
     "(bursts below the gate are still listed, with their rho); 2 bad input."},
    {"doppler", cmd_doppler, "decode rate and ToF bias against a constant line-of-sight speed",
     "Send every code of the scene's family between a fixed TX and an RX moving along the common\n"
     "axis at constant line-of-sight speeds (closing > 0), decode each burst with the scene's\n"
     "receiver and report the decode rate and the ToF bias (docs/results/blade-crossing.md).\n"
     "The scene needs excitation.schedule.period_s (the codes' send times)."},
    {"sweep", cmd_sweep, "design-space sweep: accuracy and cost over axes, Pareto fronts (docs/design-space.md)",
     "Design-space sweep (docs/design-space.md): run the spec's scene in the fixed model at every\n"
     "point of its axes; write DIR/points.csv, DIR/sweep.json, DIR/summary.md and DIR/front.png\n"
     "(Pareto fronts on cost vs distance RMSE and vs decode errors; the default marked).\n"
     "Re-running with the same DIR keeps the points already done (DIR/points/ID.json).\n"
     "`ranging sweep merge --out DIR SHARD_DIR...` merges --shard runs (see its --help)."},
    {"wordlength", cmd_wordlength, "smallest fixed-point widths within an accuracy tolerance (docs/design-space.md)",
     "Word-length optimization (docs/design-space.md): the smallest width of each node of the\n"
     "fixed-point receiver (greedy, node by node, then checked jointly) such that the spec's\n"
     "scene in the fixed model keeps distance RMSE <= rmse_factor x the base's and at most\n"
     "decode_errors errors. Writes DIR/config.yaml (the result), DIR/wordlength.json and\n"
     "DIR/wordlength.md (accuracy and cost beside the base's)."},
    {"stability", cmd_stability, "numerical stability report: guard, headroom, limit cycles, filter structures",
     "Numerical stability report of a receiver configuration: the guard's verdict on the\n"
     "quantized filter (exact pole radii, edge attenuations), overflow headroom per filter\n"
     "and correlator-bank node under its worst-case input, zero-input limit cycles per rounding and overflow\n"
     "mode, and the SOS vs direct-form comparison per filter type. An out-of-spec design\n"
     "is reported, not refused."},
    {"frames", cmd_frames, "decode the board's UART measurement frames (checksum, resync, bad-frame count)",
     "Decode the board's UART stream (17-byte measurement frames, docs/bitstream.md) from FILE\n"
     "or stdin (-): one CSV row per good frame (or --json). Checksums are checked; after a\n"
     "corrupt byte the decoder resyncs on the next 0xA5 0x5A; bad frames are counted."},
    {"verify", cmd_verify, "verify the RTL of a configuration against the golden model, stage by stage",
     "Verify the RTL of a receiver configuration against the golden model, bit for bit and\n"
     "stage by stage (filter, bank framing, chip filter, combiner, weighted power, energy,\n"
     "events). Generates the IP folder into a work folder, builds the Verilated receiver_top\n"
     "there (verilator --build, cached), and runs coded streams of every code of the family\n"
     "at several distances, the full-scale worst case, random input, random valid gaps with\n"
     "back-pressure and a reset mid-stream. Exit status 0: every stage matched; 1: a mismatch\n"
     "(the first is reported: stage, sample, expected, got); 2: bad input."},
    {"bitstream", cmd_bitstream, "build the iCEBreaker bitstream of a configuration (open flow) and program the board",
     "Build the iCEBreaker (iCE40UP5K-SG48) bitstream of the ranging system for a receiver\n"
     "configuration with the open flow (generate, yosys synth_ice40, nextpnr-ice40, icepack,\n"
     "icetime: scripts/build_bitstream.sh), and optionally program the board. The netlists,\n"
     "logs, the .bin and the summary (results/bitstream.json and .md) go into --out; progress\n"
     "goes to stderr, the summary to stdout.\n"
     "Exit status: 0 built (and programmed); 1 no usable bitstream (the design did not place\n"
     "and route, or its Fmax is below the clock), or --check and a target missed; 2 bad input,\n"
     "a missing tool, or --program with no programmer installed or no board attached (checked\n"
     "before anything is built)."},
};

}  // namespace

std::span<const Command> commands() { return kCommands; }

cli::Parser command_parser(const std::string& name) {
  for (const Command& c : kCommands) {
    if (name == c.name) return cli::Parser(std::string("ranging ") + (c.synopsis ? c.synopsis : c.name), c.description);
  }
  throw std::logic_error("command_parser: no command '" + name + "'");
}

}  // namespace ranging::tool
