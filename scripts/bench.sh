#!/usr/bin/env bash
# Every speed figure of issue 13 from one run (benchmarks, never pass/fail tests):
#   the golden model per stage, fixed and float (bench/bench_model), MS/s and x real time;
#   the bandpass kernel vs scipy.signal.sosfilt on the same design and input
#     (scripts/bench_sosfilt.py) and vs SystemC sc_fixed / sc_fix (bench/bench_fixed_point);
#   the Verilator RTL of receiver_top vs the model (tb/bench_receiver_top);
#   and the ratios. Rates are per second of CPU time (one core), so a busy machine does not
#   scale them down.
#   scripts/bench.sh [BUILD_DIR]      (default build/; configured with hardware and bench ON)
set -euo pipefail
cd "$(dirname "$0")/.."
B=${1:-build}
PY=/usr/bin/python3
if [[ ! -d $B ]]; then
  echo "bench.sh: $B is not a build directory; configure it first (README.md)" >&2
  exit 2
fi
targets=(ranging bench_model bench_fixed_point)
cmake --build "$B" --target help 2>/dev/null | grep -q bench_receiver_top && targets+=(bench_receiver_top)
cmake --build "$B" -j2 --target "${targets[@]}" >/dev/null
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
"$B"/tool/ranging filter --json >"$T/sos.json"
"$B"/bench/bench_model --benchmark_min_time=0.5 --benchmark_format=json >"$T/model.json" 2>/dev/null
"$B"/bench/bench_fixed_point --benchmark_min_time=0.5 --benchmark_format=json >"$T/fixed.json" 2>/dev/null
$PY scripts/bench_sosfilt.py "$T/sos.json" >"$T/sosfilt.txt"
if [[ -x $B/tb/bench_receiver_top ]]; then
  "$B"/tb/bench_receiver_top 2 >"$T/rtl.txt"
else
  echo "not built (configure with -DRANGING_BUILD_HARDWARE=ON)" >"$T/rtl.txt"
fi
$PY - "$T" <<'PYEOF'
import json, re, sys
t = sys.argv[1]
def rates(name):
    return {b["name"]: b["items_per_second"] for b in json.load(open(f"{t}/{name}.json"))["benchmarks"]}
m, f = rates("model"), rates("fixed")
sos = dict(l.split() for l in open(f"{t}/sosfilt.txt"))
fs = 5e6
print("Golden model, default configuration (configs/default.yaml), one core:")
print(f"  {'stage':34s} {'MS/s':>8s} {'ns/sample':>10s} {'x real time':>12s}")
def row(label, r):
    print(f"  {label:34s} {r/1e6:8.2f} {1e9/r:10.2f} {r/fs:12.1f}")
for prec in ("Fixed", "Float"):
    bp, bank, rx = m[f"BM_{prec}Bandpass"], m[f"BM_{prec}Bank"], m[f"BM_{prec}Receiver"]
    row(f"{prec.lower()} bandpass", bp)
    row(f"{prec.lower()} correlator bank", bank)
    det_ns = 1e9/rx - 1e9/bp - 1e9/bank
    print(f"  {prec.lower() + ' detector (receiver - others)':34s} {'':8s} {det_ns:10.2f}")
    row(f"{prec.lower()} receiver (all stages)", rx)
row("fixed receiver, per-sample API", m["BM_FixedReceiverPerSample"])
print(f"  float / fixed receiver: {m['BM_FloatReceiver'] / m['BM_FixedReceiver']:.2f}")
print()
k, kt = f["BM_BandpassFixed"], f["BM_FixedType"]
sc, scf = f["BM_ScFixed"], f["BM_ScFix"]
s4, s1m = float(sos["sosfilt_4096"]) * 1e6, float(sos["sosfilt_1048576"]) * 1e6
print(f"Bandpass kernel ({sos['sections']} sections, 4096-sample 200 kHz sine), MS/s:")
print(f"  ours, bit-exact fixed (execute_raw per sample)  {k/1e6:8.2f}")
print(f"  ours, bit-exact fixed (execute_block)           {f['BM_BandpassFixedBlock']/1e6:8.2f}")
print(f"  ours, execute_block on the receiver's input     {m['BM_FixedBandpass']/1e6:8.2f}  (22953 samples)")
print(f"  ranging::Fixed type                             {kt/1e6:8.2f}")
print(f"  sc_fixed<16,2,SC_RND,SC_SAT>                    {sc/1e6:8.2f}")
print(f"  sc_fix (runtime parameters)                     {scf/1e6:8.2f}")
print(f"  scipy.signal.sosfilt float64, 4096 samples      {s4/1e6:8.2f}")
print(f"  scipy.signal.sosfilt float64, 1 M samples       {s1m/1e6:8.2f}")
kb = f["BM_BandpassFixedBlock"]
print(f"  ratios: block kernel / sosfilt (4096) {kb/s4:.2f}, / sosfilt (1 M) {kb/s1m:.2f}, "
      f"/ sc_fixed {kb/sc:.0f}; per-sample kernel / sc_fixed {k/sc:.0f}")
print()
print("Verilator RTL (tb/bench_receiver_top):")
for line in open(f"{t}/rtl.txt"):
    print("  " + line.rstrip())
PYEOF
