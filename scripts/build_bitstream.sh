#!/usr/bin/env bash
# Builds the iCEBreaker (iCE40UP5K-SG48) bitstream of the ranging system for one configuration
# with the open flow and writes the resource/timing summary (docs/bitstream.md):
#   ranging generate -> yosys synth_ice40 -dsp -> nextpnr-ice40 -> icepack -> icetime
#   + resource estimates with yosys synth_ecp5 and synth_xilinx (default and large configs)
#   -> RESULTS/bitstream.json and RESULTS/bitstream.md
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
config="$root/configs/default.yaml"
large="$root/configs/large.yaml"
build="$root/build"
out=""
results=""
check=0
others=1
breakdown=0
seeds=1
min_seeds=1
jobs=1
ranging=""
margin=1.10

usage() {
  cat <<'EOF'
Usage: scripts/build_bitstream.sh [options]

Builds the ranging system (rtl/ranging_system.v + the generated receiver) for the iCEBreaker
(iCE40UP5K-SG48) with yosys, nextpnr-ice40, icepack and icetime, and writes the summary
(LUT4, DFF, SB_MAC16, EBR, SPRAM, required clock, Fmax, slack; ECP5 and Xilinx estimates) to
RESULTS/bitstream.json and RESULTS/bitstream.md.

Options:
  --config FILE     receiver configuration (default: configs/default.yaml)
  --large FILE      second configuration for the ECP5/Xilinx estimates (default: configs/large.yaml,
                    skipped with a note when absent)
  --no-large        no second configuration (no large-configuration estimates)
  --build-dir DIR   CMake build folder holding tool/ranging (default: build)
  --ranging FILE    the ranging tool (default: BUILD/tool/ranging)
  --out DIR         work folder for generated files, netlists, logs and the .bin
                    (default: BUILD/bitstream)
  --results DIR     where the summary goes (default: OUT/results; the committed summary:
                    --results docs/results, as the `bitstream` build target does)
  --no-others       skip the ECP5 and Xilinx estimates
  --breakdown       also synthesize without flattening and list the iCE40 resources per module
  --seeds N         place and route with nextpnr seeds 1..N and keep the fastest (default 1;
                    each try takes 1-3 minutes; the summary names the seed)
  --jobs N          place and route up to N seeds at the same time (default 1)
  --check           exit 1 unless the design meets the targets: <= 5280 LUT4, <= 8 SB_MAC16,
                    <= 30 EBR, <= 4 SPRAM, placed and routed, Fmax >= 1.1 x the system clock
                    on at least K of the seeds (--min-seeds)
  --min-seeds K     how many of the seeds tried must reach 1.1 x the clock (default 1: the
                    best one; the ctest entry asks 4 of 5, issue 18)
  -h, --help        this text
Tools (PATH): yosys, nextpnr-ice40, icepack, icetime; /usr/bin/python3 for the summary.
EOF
}

die() { echo "build_bitstream: $*" >&2; exit 2; }

while [[ $# -gt 0 ]]; do
  case "$1" in
    --config) config=$(realpath "${2:?--config needs a FILE}"); shift 2 ;;
    --large) large=$(realpath -m "${2:?--large needs a FILE}"); shift 2 ;;
    --no-large) large=""; shift ;;
    --ranging) ranging=$(realpath -m "${2:?--ranging needs a FILE}"); shift 2 ;;
    --jobs) jobs="${2:?--jobs needs N}"; shift 2
            [[ "$jobs" =~ ^[1-9][0-9]?$ ]] || die "--jobs: N must be 1..99, got '$jobs'" ;;
    --build-dir) build=$(realpath -m "${2:?--build-dir needs a DIR}"); shift 2 ;;
    --out) out=$(realpath -m "${2:?--out needs a DIR}"); shift 2 ;;
    --results) results=$(realpath -m "${2:?--results needs a DIR}"); shift 2 ;;
    --no-others) others=0; shift ;;
    --breakdown) breakdown=1; shift ;;
    --check) check=1; shift ;;
    --seeds) seeds="${2:?--seeds needs N}"; shift 2
             [[ "$seeds" =~ ^[1-9][0-9]?$ ]] || die "--seeds: N must be 1..99, got '$seeds'" ;;
    --min-seeds) min_seeds="${2:?--min-seeds needs K}"; shift 2
             [[ "$min_seeds" =~ ^[1-9][0-9]?$ ]] || die "--min-seeds: K must be 1..99, got '$min_seeds'" ;;
    -h|--help) usage; exit 0 ;;
    *) usage >&2; die "unknown option '$1'" ;;
  esac
done

[[ -f "$config" ]] || die "--config: no file $config"
((min_seeds <= seeds)) || die "--min-seeds $min_seeds: more than the $seeds seed(s) tried (--seeds N)"
out=${out:-"$build/bitstream"}
results=${results:-"$out/results"}
for t in yosys nextpnr-ice40 icepack icetime; do
  command -v "$t" >/dev/null || die "$t not found on PATH (scripts/install-deps.sh installs the FPGA tools)"
done
py=/usr/bin/python3
[[ -x "$py" ]] || die "/usr/bin/python3 not found"
ranging=${ranging:-"$build/tool/ranging"}
[[ -x "$ranging" ]] || die "$ranging not found: build it first (cmake --build $build --target ranging)"

receiver_rtl=("$root/rtl/fx_quantize.v" "$root/rtl/bandpass_sos.v" "$root/rtl/correlator_bank.v" "$root/rtl/peak_detector.v")
system_rtl=("$root/rtl/adc_interface.v" "$root/rtl/tx_scheduler.v" "$root/rtl/tof_distance.v"
            "$root/rtl/uart_tx.v" "$root/rtl/measurement_uart.v" "$root/rtl/ranging_system.v")
for f in "${receiver_rtl[@]}" "${system_rtl[@]}"; do
  [[ -f "$f" ]] || die "missing RTL $f"
done
board="$root/boards/icebreaker"
pcf="$board/icebreaker.pcf"

mkdir -p "$out" "$results"
log() { echo "[bitstream] $*"; }

# Generated files of a configuration into $1 (receiver + system top).
generate() {
  local cfg=$1 dir=$2 origin
  origin=$(realpath --relative-to="$root" "$cfg")
  "$ranging" generate --config "$cfg" --out "$dir" --origin "$origin" >"$dir.log" 2>&1 ||
    { cat "$dir.log" >&2; die "ranging generate failed for $cfg"; }
}

log "generating $(realpath --relative-to="$root" "$config")"
gen="$out/generated"
generate "$config" "$gen"
# The real-time rule (model/hw/realtime.hpp, manifest.json): a design whose stages cannot keep
# pace with the ADC at the configured clock is refused for the bitstream.
rt_refusal=$($py -c "import json; r = json.load(open('$gen/manifest.json'))['real_time']; print('' if r['real_time'] else r['summary'])")
[ -z "$rt_refusal" ] || die "$(realpath --relative-to="$root" "$config") is not a real-time design: $rt_refusal"
sources=("${receiver_rtl[@]}" "$gen/rtl/receiver_top.v" "${system_rtl[@]}" "$gen/rtl/ranging_system_top.v")

# --- iCE40 -----------------------------------------------------------------------------------
log "yosys synth_ice40 -dsp (log: $out/yosys_ice40.log)"
read_cmd=""
for f in "${sources[@]}"; do read_cmd+="read_verilog -defer $f; "; done
# The board top includes the generated PLL settings (rtl/ice40_pll.vh).
read_cmd+="read_verilog -defer -I$gen/rtl $board/ice40_top.v; "
t0=$(date +%s)
if ! nice yosys -q -l "$out/yosys_ice40.log" -p "$read_cmd hierarchy -top ice40_top; \
    synth_ice40 -dsp -top ice40_top -json $out/ice40_top.json; \
    tee -o $out/stat_ice40.txt stat; write_verilog -noattr $out/ice40_top_syn.v" >/dev/null; then
  die "yosys failed: see $out/yosys_ice40.log"
fi
yosys_s=$(( $(date +%s) - t0 ))

clk_mhz=$($py -c "import json,sys; print(json.load(open('$gen/system.json'))['clk_hz']/1e6)")
freq=$($py -c "print(round($clk_mhz*$margin, 3))")
pnr_ok=0
best_seed=0
best_mhz=-1
t0=$(date +%s)
# Seeds are placed and routed in parallel, up to --jobs at a time; the fastest routed one wins
# (ties: the lowest seed).
pnr_seed() {
  local seed=$1 sd="$out/seed-$1"
  mkdir -p "$sd"
  if nice nextpnr-ice40 --up5k --package sg48 --pcf "$pcf" --json "$out/ice40_top.json" \
      --asc "$sd/ice40_top.asc" --freq "$freq" --report "$sd/nextpnr_report.json" \
      --timing-allow-fail --seed "$seed" >"$sd/nextpnr.log" 2>&1; then
    touch "$sd/ok"
  fi
}
running=0
seed_fmax=""   # "seed:MHz" of every seed (0 when nextpnr failed), for the summary
for ((seed = 1; seed <= seeds; seed++)); do
  rm -rf "$out/seed-$seed"
  log "nextpnr-ice40 --up5k --package sg48 --freq $freq --seed $seed (log: $out/seed-$seed/nextpnr.log)"
  pnr_seed "$seed" &
  running=$((running + 1))
  if ((running >= jobs)); then wait -n || true; running=$((running - 1)); fi
done
wait
for ((seed = 1; seed <= seeds; seed++)); do
  sd="$out/seed-$seed"
  if [[ -f "$sd/ok" ]]; then
    # the last "Max frequency" line is the routed design's
    mhz=$(grep -o "Max frequency for clock 'clk': [0-9.]*" "$sd/nextpnr.log" | tail -1 | awk '{print $NF}')
    mhz=${mhz:-0}
    log "  seed $seed: Fmax $mhz MHz"
    seed_fmax+="$seed:$mhz "
    if [[ $pnr_ok == 0 ]] || awk -v a="$mhz" -v b="$best_mhz" 'BEGIN{exit !(a > b)}'; then
      pnr_ok=1; best_seed=$seed; best_mhz=$mhz
    fi
  else
    log "  seed $seed: nextpnr failed"
    seed_fmax+="$seed:0 "
    [[ $pnr_ok == 0 && $seed == 1 ]] && cp "$sd/nextpnr.log" "$out/nextpnr.log"   # keep the failure for the summary
  fi
done
if [[ $pnr_ok == 1 ]]; then
  for f in ice40_top.asc nextpnr_report.json nextpnr.log; do cp "$out/seed-$best_seed/$f" "$out/$f"; done
  [[ $seeds -gt 1 ]] && log "best of $seeds seeds: seed $best_seed ($best_mhz MHz)"
fi
pnr_s=$(( $(date +%s) - t0 ))
bin=""
if [[ $pnr_ok == 1 ]]; then
  log "icepack"
  icepack "$out/ice40_top.asc" "$out/ranging_icebreaker.bin" || die "icepack failed"
  bin="$out/ranging_icebreaker.bin"
  log "icetime"
  # icetime's pcf reader takes neither set_io options (-nowarn) nor trailing comments.
  sed -e 's/#.*//' -e 's/-nowarn //' "$pcf" | awk 'NF' >"$out/icetime.pcf"
  icetime -d up5k -P sg48 -p "$out/icetime.pcf" -c "$clk_mhz" -t "$out/ice40_top.asc" >"$out/icetime.log" 2>&1 || true
else
  log "nextpnr failed (the design does not fit or route): see $out/nextpnr.log"
fi

# --- per-module iCE40 resources (no flattening: slightly above the flattened totals) -----------
rm -f "$out/stat_modules.txt"
if [[ $breakdown == 1 ]]; then
  log "yosys synth_ice40 -dsp -noflatten (per-module resources)"
  rc=""
  for f in "${sources[@]}"; do rc+="read_verilog -defer $f; "; done
  nice yosys -q -l "$out/yosys_modules.log" -p "$rc hierarchy -top ranging_system_top; \
      synth_ice40 -dsp -noflatten -top ranging_system_top; tee -q -o $out/stat_modules.txt stat" >/dev/null ||
    die "yosys (per-module) failed: see $out/yosys_modules.log"
fi

# --- ECP5 and Xilinx estimates -----------------------------------------------------------------
estimate() {  # family cfg_tag gen_dir
  local fam=$1 tag=$2 dir=$3 rc=""
  for f in "${receiver_rtl[@]}" "$dir/rtl/receiver_top.v" "${system_rtl[@]}" "$dir/rtl/ranging_system_top.v"; do
    rc+="read_verilog -defer $f; "
  done
  log "yosys synth_$fam ($tag)"
  nice yosys -q -l "$out/yosys_${fam}_$tag.log" -p "$rc hierarchy -top ranging_system_top; \
      synth_$fam -top ranging_system_top; tee -o $out/stat_${fam}_$tag.txt stat" >/dev/null ||
    echo "failed" >"$out/stat_${fam}_$tag.txt"
}
if [[ $others == 1 ]]; then
  estimate ecp5 default "$gen"
  estimate xilinx default "$gen"
  if [[ -n "$large" && -f "$large" ]]; then
    generate "$large" "$out/generated-large"
    estimate ecp5 large "$out/generated-large"
    estimate xilinx large "$out/generated-large"
  else
    log "no large configuration ${large:-(--no-large)}: large-configuration estimates skipped"
  fi
fi

# --- summary -----------------------------------------------------------------------------------
$py - "$out" "$results" "$gen/system.json" "$bin" "$pnr_ok" "$clk_mhz" "$freq" "$check" \
    "$(realpath --relative-to="$root" "$config")" "$yosys_s" "$pnr_s" "$root" "$best_seed" "$seeds" \
    "$seed_fmax" "$min_seeds" <<'EOF'
import json, os, re, sys, datetime
out, results, sysjson, binpath, pnr_ok, clk, freq, check, cfg, ys, ps, root, seed, seeds, sfm, min_seeds = sys.argv[1:17]
min_seeds = int(min_seeds)
pnr_ok, clk, freq, check = pnr_ok == "1", float(clk), float(freq), check == "1"

def cells(path):
    if not os.path.exists(path):
        return None
    text = open(path).read()
    if text.strip() == "failed":
        return "failed"
    # the last (top, flattened) statistics block
    block = text.split("=== design hierarchy ===")[-1] if "design hierarchy" in text else text
    counts = {}
    for m in re.finditer(r"^\s+(\$?[A-Za-z_][\w$]*)\s+(\d+)\s*$", block, re.M):
        counts[m.group(1)] = counts.get(m.group(1), 0) + int(m.group(2))
    return counts

def rel(p):
    return os.path.relpath(p, root) if p else None

ice = cells(os.path.join(out, "stat_ice40.txt")) or {}
s = json.load(open(sysjson))
summary = {
    "generated_by": "scripts/build_bitstream.sh",
    "date": datetime.date.today().isoformat(),
    "config": cfg,
    "device": "iCE40UP5K-SG48 (iCEBreaker)",
    "system": {k: s[k] for k in ("clk_hz", "fs", "clk_div", "period_t_samples", "measurement_rate_hz", "baud")},
    "ice40": {
        "lut4": ice.get("SB_LUT4", 0),
        "dff": sum(v for k, v in ice.items() if k.startswith("SB_DFF")),
        "carry": ice.get("SB_CARRY", 0),
        "sb_mac16": ice.get("SB_MAC16", 0),
        "ebr": ice.get("SB_RAM40_4K", 0),
        "spram": ice.get("SB_SPRAM256KA", 0),
        "unmapped_multipliers": sum(v for k, v in ice.items() if k.startswith("$mul") or k.startswith("$macc")),
        "limits": {"lut4": 5280, "sb_mac16": 8, "ebr": 30, "spram": 4},
        "required_clock_mhz": clk,
        "nextpnr_target_mhz": freq,
        "nextpnr_seed": int(seed) if pnr_ok else None,
        "nextpnr_seeds_tried": int(seeds),
        # Fmax of every seed tried (0: nextpnr failed)
        "nextpnr_seed_fmax_mhz": {k: float(m) for k, m in (t.split(":") for t in sfm.split())},
        "placed_and_routed": pnr_ok,
        "bitstream": rel(binpath) if binpath else None,
        "yosys_seconds": int(ys), "nextpnr_seconds": int(ps),
    },
}
ic = summary["ice40"]
# how many seeds reach the nextpnr target freq = 1.1 x the clock (--check --min-seeds)
ic["nextpnr_seeds_at_target"] = sum(m >= freq - 1e-9 for m in ic["nextpnr_seed_fmax_mhz"].values())
if pnr_ok:
    rep = json.load(open(os.path.join(out, "nextpnr_report.json")))
    util = rep.get("utilization", {})
    ic["logic_cells"] = util.get("ICESTORM_LC", {}).get("used")
    fm = rep.get("fmax", {})
    best = None
    for name, v in fm.items():
        if best is None or v["achieved"] < best[1]["achieved"]:
            best = (name, v)
    if best:
        ic["fmax_mhz"] = round(best[1]["achieved"], 2)
        ic["fmax_clock"] = best[0]
        ic["slack_ns"] = round(1e3 / clk - 1e3 / best[1]["achieved"], 3)
        ic["margin_percent"] = round((best[1]["achieved"] / clk - 1) * 100, 1)
    it = os.path.join(out, "icetime.log")
    if os.path.exists(it):
        text = open(it).read()
        m = re.search(r"Total path delay:\s*([\d.]+)\s*ns\s*\(([\d.]+)\s*MHz\)", text)
        if m:
            ic["icetime_path_ns"] = float(m.group(1))
            ic["icetime_fmax_mhz"] = float(m.group(2))
        else:  # say why (a missing chip database: Debian's fpga-icestorm-chipdb)
            lines = [l for l in text.splitlines() if l.strip() and not l.startswith("//")]
            ic["icetime_error"] = lines[-1] if lines else "icetime gave no path delay"
else:
    log = open(os.path.join(out, "nextpnr.log")).read()
    errs = [l for l in log.splitlines() if "ERROR" in l]
    ic["nextpnr_error"] = errs[-1] if errs else "nextpnr failed"

def fam_summary(fam, counts):
    if counts is None:
        return None
    if counts == "failed":
        return {"status": "yosys failed"}
    if fam == "ecp5":
        return {"lut4": counts.get("LUT4", 0),
                "ff": counts.get("TRELLIS_FF", 0),
                "dsp_mult18": counts.get("MULT18X18D", 0),
                "bram_dp16kd": counts.get("DP16KD", 0),
                "lutram_dpr16x4": counts.get("TRELLIS_DPR16X4", 0)}
    return {"lut": sum(v for k, v in counts.items() if re.fullmatch(r"LUT\d", k)),
            "ff": sum(v for k, v in counts.items() if re.fullmatch(r"FD[A-Z]{1,2}", k)),
            "dsp48e1": counts.get("DSP48E1", 0),
            "ramb18": counts.get("RAMB18E1", 0), "ramb36": counts.get("RAMB36E1", 0),
            "lutram": sum(v for k, v in counts.items() if k.startswith("RAM") and "B" not in k[:4])}

modules = {}
mp = os.path.join(out, "stat_modules.txt")
if os.path.exists(mp):
    for block in re.split(r"^=== ", open(mp).read(), flags=re.M)[1:]:
        parts = block.split(" ===", 1)[0].strip().split("\\")
        name = next((x for x in parts if x and not x.startswith("$") and "=" not in x), parts[-1])
        if name == "design hierarchy":
            continue
        c = {}
        for m in re.finditer(r"^\s+(\S+)\s+(\d+)\s*$", block, re.M):
            c[m.group(1)] = c.get(m.group(1), 0) + int(m.group(2))
        modules[name] = {"lut4": c.get("SB_LUT4", 0),
                         "dff": sum(v for k, v in c.items() if k.startswith("SB_DFF")),
                         "sb_mac16": c.get("SB_MAC16", 0), "ebr": c.get("SB_RAM40_4K", 0)}
if modules:
    summary["ice40_modules"] = modules

others = {}
for tag in ("default", "large"):
    for fam in ("ecp5", "xilinx"):
        r = fam_summary(fam, cells(os.path.join(out, f"stat_{fam}_{tag}.txt")))
        if r is not None:
            others.setdefault(tag, {})[fam] = r
summary["other_families"] = others

fails = []
lim = ic["limits"]
for k in ("lut4", "sb_mac16", "ebr", "spram"):
    if ic[k] > lim[k]:
        fails.append(f"{k} {ic[k]} > {lim[k]} (over by {ic[k] - lim[k]}, {100 * (ic[k] / lim[k] - 1):.0f} %)")
if ic["unmapped_multipliers"]:
    fails.append(f"{ic['unmapped_multipliers']} multipliers not mapped to SB_MAC16 (in LUTs)")
if not pnr_ok:
    fails.append("not placed and routed: " + ic["nextpnr_error"])
elif ic.get("fmax_mhz", 0) < clk * 1.1:
    fails.append(f"Fmax {ic.get('fmax_mhz')} MHz < {clk * 1.1:.1f} MHz (required clock + 10 %)")
elif ic["nextpnr_seeds_at_target"] < min_seeds:
    fails.append(f"{ic['nextpnr_seeds_at_target']} of {seeds} seeds reach {freq:.1f} MHz (required clock + 10 %), "
                 f"fewer than --min-seeds {min_seeds}: "
                 + " / ".join(f"seed {k} {m:.2f}" for k, m in ic["nextpnr_seed_fmax_mhz"].items()) + " MHz")
summary["targets_met"] = not fails
summary["target_failures"] = fails

os.makedirs(results, exist_ok=True)
with open(os.path.join(results, "bitstream.json"), "w") as f:
    json.dump(summary, f, indent=2)
    f.write("\n")

def v(x):
    return "-" if x is None else str(x)
md = [f"# Bitstream summary ({cfg})", "",
      f"Written by `scripts/build_bitstream.sh` on {summary['date']}; do not edit by hand.", "",
      f"System: clock {clk:g} MHz, fs {s['fs']/1e6:g} MS/s ({s['clk_div']} clocks per sample), burst period "
      f"{s['period_t_samples']} samples ({s['measurement_rate_hz']:.0f} measurements/s), UART {s['baud']/1e6:g} Mbaud.", "",
      "## iCE40UP5K-SG48 (yosys synth_ice40 -dsp, nextpnr-ice40)", "",
      "| resource | used | available |", "|---|---|---|",
      f"| LUT4 (SB_LUT4) | {ic['lut4']} | 5280 |",
      f"| logic cells (nextpnr) | {v(ic.get('logic_cells'))} | 5280 |",
      f"| DFF | {ic['dff']} | 5280 |",
      f"| SB_CARRY | {ic['carry']} | - |",
      f"| SB_MAC16 | {ic['sb_mac16']} | 8 |",
      f"| EBR (SB_RAM40_4K) | {ic['ebr']} | 30 |",
      f"| SPRAM | {ic['spram']} | 4 |",
      f"| multipliers left in LUTs | {ic['unmapped_multipliers']} | 0 |", "",
      "| timing | value |", "|---|---|",
      f"| required clock | {clk:g} MHz |",
      f"| nextpnr target (--freq) | {freq:g} MHz |",
      f"| nextpnr seed | {seed if pnr_ok else '-'} (best of {seeds}) |",
      "| Fmax of each seed | " + (" / ".join(f"{k}: {m:.2f}" for k, m in ic["nextpnr_seed_fmax_mhz"].items())
                                  or "-") + " MHz |",
      f"| seeds at >= 1.1 x the clock | {ic['nextpnr_seeds_at_target']} of {seeds} |",
      f"| placed and routed | {'yes' if pnr_ok else 'no: ' + ic.get('nextpnr_error', '')} |",
      f"| Fmax (nextpnr) | {v(ic.get('fmax_mhz'))} MHz |",
      f"| slack at the required clock | {v(ic.get('slack_ns'))} ns |",
      f"| margin | {v(ic.get('margin_percent'))} % |",
      (f"| icetime critical path | {v(ic.get('icetime_path_ns'))} ns ({v(ic.get('icetime_fmax_mhz'))} MHz) |"
       if "icetime_error" not in ic else f"| icetime critical path | not run: {ic['icetime_error']} |"),
      f"| bitstream | {v(ic['bitstream'])} |", ""]
if modules:
    md += ["## iCE40 resources per module (synth_ice40 -dsp -noflatten)", "",
           "| module | LUT4 | DFF | SB_MAC16 | EBR |", "|---|---|---|---|---|"]
    for name, r in sorted(modules.items(), key=lambda kv: -kv[1]["lut4"]):
        if r["lut4"] or r["dff"] or r["sb_mac16"] or r["ebr"]:
            md.append(f"| {name} | {r['lut4']} | {r['dff']} | {r['sb_mac16']} | {r['ebr']} |")
    md.append("")
if others:
    md += ["## Other families (yosys estimates of ranging_system_top, no place and route)", "",
           "| configuration | family | LUT | FF | DSP | block RAM |", "|---|---|---|---|---|---|"]
    for tag, fams in others.items():
        for fam, r in fams.items():
            if "status" in r:
                md.append(f"| {tag} | {fam} | {r['status']} | | | |")
            elif fam == "ecp5":
                md.append(f"| {tag} | ECP5 | {r['lut4']} | {r['ff']} | {r['dsp_mult18']} MULT18X18D | {r['bram_dp16kd']} DP16KD |")
            else:
                md.append(f"| {tag} | Xilinx 7 | {r['lut']} | {r['ff']} | {r['dsp48e1']} DSP48E1 | {r['ramb18']} RAMB18 + {r['ramb36']} RAMB36 |")
    if "large" not in others:
        md.append("| large | - | no configs/large.yaml yet | | | |")
    md.append("")
md += ["## Targets", "",
       "Met." if not fails else "Not met:\n\n" + "\n".join(f"- {x}" for x in fails), ""]
with open(os.path.join(results, "bitstream.md"), "w") as f:
    f.write("\n".join(md))
print("\n".join(md))
sys.exit(1 if (check and fails) else 0)
EOF
