#!/bin/bash
# The fidelity ladder (issue 11 section 5): one scene's input through the simulation levels
# `ranging simulate` offers (float model, fixed model, Verilator RTL: --precision rtl runs every
# stream through the fixed model and the Verilated receiver, whose events must be identical),
# timed; samples/s = samples of the received streams / wall seconds of the run (the RTL level
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
"$ranging" simulate "$scene" --precision rtl --out "$work/warmup" --quiet > "$work/warmup.log" 2>&1 ||
  { cat "$work/warmup.log" >&2; echo "fidelity_ladder: the RTL warm-up failed" >&2; exit 1; }
for level in float fixed rtl; do
  t0=$(date +%s.%N)
  "$ranging" simulate "$scene" --precision "$level" --out "$work/$level" --write-captures --quiet > "$work/$level.log" 2>&1 ||
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
names = {"float": "float model", "fixed": "fixed model", "rtl": "Verilator RTL (events compared with the fixed model)"}
for level in ("float", "fixed", "rtl"):
    r = rows(level)
    t0, t1 = map(float, open(f"{work}/{level}.time").read().split())
    dev = max(abs(float(a["tof_s"] or "nan") - float(b["tof_s"] or "nan")) for a, b in zip(r, fixed))
    truth = max(abs(float(a["error_m"])) for a in r if a["error_m"] not in ("", "nan"))
    wrong = sum(1 for a in r if a["code_decoded"] != a["code_sent"])
    levels.append({"name": names[level], "precision": level, "samples_per_s": samples(level) / (t1 - t0),
                   "samples": samples(level), "seconds": t1 - t0, "max_deviation": dev,
                   "max_deviation_unit": "s (ToF, from the fixed model)", "max_error_from_truth_m": truth,
                   "decode_errors": wrong, "measurements": len(r)})
not_run = ["HLS C-sim", "SystemC (verilator --sc)", "Icarus", "post-synthesis netlist"]
doc = {"scene": scene, "levels": levels, "not_measured": not_run}
json.dump(doc, open(prefix + ".json", "w"), indent=1)
L = ["# Fidelity ladder (issue 11 section 5)\n",
     f"Scene `{scene}`; produced by `scripts/fidelity_ladder.sh` (wall time of `ranging simulate --precision P` "
     "on the shared 2-core machine, so the speeds are rough).\n",
     "| level | samples/s | samples | seconds | max ToF deviation from fixed (s) | max error from truth (m) | decode errors |",
     "|---|---|---|---|---|---|---|"]
for l in levels:
    L.append(f"| {l['name']} | {l['samples_per_s']:.3g} | {l['samples']} | {l['seconds']:.1f} | {l['max_deviation']:.3g} | "
             f"{l['max_error_from_truth_m']:.3g} | {l['decode_errors']}/{l['measurements']} |")
L.append("\nNot measured yet (no entry in the JSON): " + ", ".join(not_run) + ".")
open(prefix + ".md", "w").write("\n".join(L) + "\n")
PY
echo "fidelity ladder: $prefix.md, $prefix.json"
