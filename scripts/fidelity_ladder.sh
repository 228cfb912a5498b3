#!/bin/bash
# The fidelity ladder (issue 11 section 5): one scene's input through the simulation levels
# `ranging simulate` offers (float model, fixed model, and with --precision rtl every stream also
# through the fixed model and a hardware simulation whose events must be identical: Verilator RTL,
# the Verilated iCE40 post-synthesis netlist (--rtl-simulator postsynth), Icarus Verilog RTL
# (--rtl-simulator icarus), the HLS C++ in C simulation (--rtl-simulator hls), the Verilated RTL
# under the SystemC kernel (--rtl-simulator systemc)), timed; samples/s = samples of the received streams / wall seconds of the run (the RTL level
# includes its fixed-model pass; the Verilator build is done by an untimed warm-up run); deviation of the
# events (ToF) from the fixed model and from the truth (distance error). Writes OUT.md, OUT.json
# ({"levels": [{"name", "samples_per_s", "max_deviation", ...}]}).
#   scripts/fidelity_ladder.sh [SCENE] [OUT_PREFIX]   (default sweeps/smoke-scene.yaml, docs/results/fidelity-ladder)
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
ranging=${RANGING:-$root/build/tool/ranging}
scene=${1:-$root/sweeps/smoke-scene.yaml}
prefix=${2:-$root/docs/results/fidelity-ladder}
work=$(mktemp -d "${TMPDIR:-/tmp}/ranging-ladder.XXXXXX")
trap 'rm -rf "$work"' EXIT
# The Verilated receiver is built at run time in $TMPDIR/ranging-simulate-...: a private TMPDIR
# (the default folder may hold another tree's build), and one untimed warm-up run builds it.
export TMPDIR="$work/tmp"
mkdir -p "$TMPDIR"
# Untimed warm-ups build the Verilated RTL and netlist (Icarus compiles in seconds: timed).
for sim in verilator postsynth systemc; do
  "$ranging" simulate "$scene" --precision rtl --rtl-simulator $sim --out "$work/warmup-$sim" --quiet > "$work/warmup.log" 2>&1 ||
    { cat "$work/warmup.log" >&2; echo "fidelity_ladder: the $sim warm-up failed" >&2; exit 1; }
done
for level in float fixed hls rtl systemc postsynth icarus; do
  case $level in
    float|fixed) args=(--precision "$level") ;;
    rtl) args=(--precision rtl --rtl-simulator verilator) ;;
    *) args=(--precision rtl --rtl-simulator "$level") ;;
  esac
  t0=$(date +%s.%N)
  "$ranging" simulate "$scene" "${args[@]}" --out "$work/$level" --write-captures --quiet > "$work/$level.log" 2>&1 ||
    { cat "$work/$level.log" >&2; echo "fidelity_ladder: $level failed" >&2; exit 1; }
  t1=$(date +%s.%N)
  echo "$t0 $t1" > "$work/$level.time"
done
/usr/bin/python3 - "$work" "$prefix" "$(realpath --relative-to="$root" "$scene")" <<'PY'
import csv, glob, json, sys
work, prefix, scene = sys.argv[1:4]
def rows(level):
    return list(csv.DictReader(open(f"{work}/{level}/measurements.csv")))
def samples(level):
    n = 0
    for f in glob.glob(f"{work}/{level}/captures/*.csv"):
        n += max(0, sum(1 for _ in open(f)) - 1)
    return n
fixed = rows("fixed")
levels = []
names = {"float": "float model", "fixed": "fixed model", "rtl": "Verilator RTL (events compared with the fixed model)",
         "postsynth": "post-synthesis iCE40 netlist, Verilated (events compared with the fixed model)",
         "icarus": "Icarus Verilog RTL (events compared with the fixed model)",
         "hls": "HLS C++ C simulation (events compared with the fixed model)",
         "systemc": "SystemC: Verilated RTL as an SC_MODULE (events compared with the fixed model)"}
for level in ("float", "fixed", "hls", "rtl", "systemc", "postsynth", "icarus"):
    r = rows(level)
    t0, t1 = map(float, open(f"{work}/{level}.time").read().split())
    dev = max(abs(float(a["tof_s"] or "nan") - float(b["tof_s"] or "nan")) for a, b in zip(r, fixed))
    truth = max(abs(float(a["error_m"])) for a in r if a["error_m"] not in ("", "nan"))
    wrong = sum(1 for a in r if a["code_decoded"] != a["code_sent"])
    summ = json.load(open(f"{work}/{level}/summary.json"))
    hw = summ.get("rtl")
    if hw is not None and not hw["pass"]:
        sys.exit(f"fidelity_ladder: {level}: the hardware events differ from the fixed model's: {hw['first_mismatch']}")
    levels.append({"name": names[level], "precision": level, "samples_per_s": samples(level) / (t1 - t0),
                   "samples": samples(level), "seconds": t1 - t0, "max_deviation": dev,
                   "max_deviation_unit": "s (ToF, from the fixed model)", "max_error_from_truth_m": truth,
                   "decode_errors": wrong, "measurements": len(r),
                   "hardware_events_compared": hw["events_compared"] if hw else None,
                   "hardware_mismatches": hw["mismatches"] if hw else None})
not_run = []
doc = {"scene": scene, "levels": levels, "not_measured": not_run}
json.dump(doc, open(prefix + ".json", "w"), indent=1)
L = ["# Fidelity ladder (issue 11 section 5)\n",
     f"Scene `{scene}`; produced by `scripts/fidelity_ladder.sh` (wall time of `ranging simulate --precision P` "
     "on the shared 2-core machine, so the speeds are rough).\n",
     "The hardware levels run every stream through the fixed model too and compare their events with it "
     "(a mismatch fails the script); their samples/s include that fixed-model pass.\n",
     "| level | samples/s | samples | seconds | max ToF deviation from fixed (s) | max error from truth (m) | decode errors | hardware events compared / mismatches |",
     "|---|---|---|---|---|---|---|---|"]
for l in levels:
    L.append(f"| {l['name']} | {l['samples_per_s']:.3g} | {l['samples']} | {l['seconds']:.1f} | {l['max_deviation']:.3g} | "
             f"{l['max_error_from_truth_m']:.3g} | {l['decode_errors']}/{l['measurements']} | "
             + ("--" if l["hardware_events_compared"] is None else f"{l['hardware_events_compared']} / {l['hardware_mismatches']}") + " |")
L.append("\nEvery level of issue 11 section 5 is measured. Reproduce: `scripts/fidelity_ladder.sh " + scene + "`.")
open(prefix + ".md", "w").write("\n".join(L) + "\n")
PY
echo "fidelity ladder: $prefix.md, $prefix.json"
