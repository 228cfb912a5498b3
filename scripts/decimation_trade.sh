#!/usr/bin/env bash
# Measures the receiver's accuracy against its decimation D (the bank's back end runs at fs / D,
# so its multiplies fall as 1/D^2: D times fewer outputs, each with D times fewer chip-filter taps).
# For each D it runs `ranging demo` (both precisions, 100-1000 mm in 100 mm steps) on several
# families and noise levels, and writes RESULTS/decimation-trade.{json,md}.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build"
results="$root/docs/results"
decims="5 10 20 25"
families="M1 M2 Gold1 Gold4 Gold7"
noises="0.002 0.02"
usage() {
  cat <<EOF2
Usage: scripts/decimation_trade.sh [--build-dir DIR] [--results DIR] [--decimations "5 10 20 25"]
                                   [--families "M1 Gold4"] [--noise "0.002 0.02"]
Runs build/tool/ranging demo with configs/default.yaml at each decimation and writes the
largest and rms |distance error| of the fixed-point receiver, decode errors and the smallest
score margin per (D, family, noise) to RESULTS/decimation-trade.json and .md.
EOF2
}
while [[ $# -gt 0 ]]; do
  case "$1" in
    --build-dir) build=$(realpath -m "${2:?}"); shift 2 ;;
    --results) results=$(realpath -m "${2:?}"); shift 2 ;;
    --decimations) decims=${2:?}; shift 2 ;;
    --families) families=${2:?}; shift 2 ;;
    --noise) noises=${2:?}; shift 2 ;;
    -h|--help) usage; exit 0 ;;
    *) usage >&2; echo "decimation_trade: unknown option '$1'" >&2; exit 2 ;;
  esac
done
ranging="$build/tool/ranging"
[[ -x "$ranging" ]] || { echo "decimation_trade: $ranging not found: build it first" >&2; exit 2; }
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
mkdir -p "$results"
for d in $decims; do
  sed -E "s/^  decimation: [0-9]+/  decimation: $d/" "$root/configs/default.yaml" > "$work/d$d.yaml"
  for f in $families; do
    for n in $noises; do
      echo "[trade] D=$d $f noise $n" >&2
      "$ranging" demo --config "$work/d$d.yaml" --family "$f" --noise-rms "$n" --quiet --json \
        --distances 0.1,0.2,0.3,0.4,0.5,0.6,0.7,0.8,0.9,1.0 > "$work/r_${d}_${f}_${n}.json"
    done
  done
done
/usr/bin/python3 - "$work" "$results" "$decims" "$families" "$noises" <<'PY'
import json, math, sys, datetime
work, results, decims, fams, noises = sys.argv[1], sys.argv[2], sys.argv[3].split(), sys.argv[4].split(), sys.argv[5].split()
rows = []
for d in decims:
    for f in fams:
        for n in noises:
            j = json.load(open(f"{work}/r_{d}_{f}_{n}.json"))
            ok = [r for r in j["rows"] if r["fixed"]["decoded"] == r["code"]]
            e = [abs(r["fixed"]["error_m"]) * 1e3 for r in ok]
            rows.append(dict(decimation=int(d), family=f, noise_rms=float(n), codes=len(j["rows"]),
                             decode_errors=j["decode_errors"]["fixed"],
                             max_err_mm=max(e) if e else None,
                             rms_err_mm=math.sqrt(sum(x * x for x in e) / len(e)) if e else None,
                             min_margin=min(r["fixed"]["margin"] for r in j["rows"])))
json.dump({"rows": rows}, open(f"{results}/decimation-trade.json", "w"), indent=1)
with open(f"{results}/decimation-trade.md", "w") as o:
    o.write("# Decimation trade (configs/default.yaml, fixed-point receiver)\n\n")
    o.write(f"Written by `scripts/decimation_trade.sh` on {datetime.date.today()}; do not edit by hand.\n\n")
    o.write("Every code of each family at 100-1000 mm in 100 mm steps (`ranging demo`). The bank's back end "
            "does D times fewer outputs with D times fewer chip-filter taps: its multiply rate falls as 1/D^2.\n\n")
    o.write("| D | family | noise (FS rms) | decode errors | max \\|err\\| (mm) | rms err (mm) | min margin |\n|---|---|---|---|---|---|---|\n")
    for r in rows:
        fmt = lambda v: "-" if v is None else f"{v:.3f}"
        o.write(f"| {r['decimation']} | {r['family']} | {r['noise_rms']} | {r['decode_errors']}/{r['codes']} | "
                f"{fmt(r['max_err_mm'])} | {fmt(r['rms_err_mm'])} | {r['min_margin']:.3f} |\n")
    o.write("\nSummary over families and noise levels:\n\n| D | decode errors | worst max \\|err\\| (mm) | mean rms err (mm) |\n|---|---|---|---|\n")
    for d in decims:
        rs = [r for r in rows if r["decimation"] == int(d)]
        mx = max(r["max_err_mm"] for r in rs if r["max_err_mm"] is not None)
        rm = sum(r["rms_err_mm"] for r in rs if r["rms_err_mm"] is not None) / len(rs)
        o.write(f"| {d} | {sum(r['decode_errors'] for r in rs)} | {mx:.3f} | {rm:.3f} |\n")
print(open(f"{results}/decimation-trade.md").read())
PY
