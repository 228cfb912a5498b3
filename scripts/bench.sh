#!/usr/bin/env bash
# Every speed figure of issue 13 from one run (benchmarks, never pass/fail tests):
#   the golden model per stage, fixed and float (bench/bench_model), MS/s and x real time (also
#   one long stream, whose bandpass runs time-split on the SIMD lanes), and
#     the fixed and float receivers on 8 streams at once (ReceiverFixedBatch / ReceiverFloatBatch,
#     one stream per AVX-512 lane);
#   the bandpass kernel vs scipy.signal.sosfilt on the same design and input
#     (scripts/bench_sosfilt.py) and vs SystemC sc_fixed / sc_fix (bench/bench_fixed_point);
#   the Verilator RTL of receiver_top vs the model (tb/bench_receiver_top, then its clang++
#     builds tb/bench_receiver_top_clang and, profile-guided, tb/bench_receiver_top_pgo: which
#     is faster depends on the CPU);
#   streaming decode of 10 M and 100 M-sample WAV captures and a 2 M-row CSV (/usr/bin/time -v:
#     CPU time, peak RSS; --jobs 2 wall time: median and fastest of BENCH_DECODE_REPEATS, default 5);
#   scenes per sample: default (float, fixed, fixed without metrics) and minimal (summary.json samples_simulated),
#     BENCH_ROUNDS (default 3) interleaved rounds, the median reported;
#   simulate --jobs 1 against --jobs 2 (wall time: the only clock that shows a parallel speedup);
#   and the ratios. Rates are per second of CPU time (one core), so a busy machine does not
#   scale them down. BENCH_DECODE_SAMPLES="1e7 1e8" sets the WAV decode lengths (disk: 4 bytes a
#   sample), BENCH_DECODE_CSV_ROWS="2e6" the CSV's (32 bytes a row).
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
  # The clang++ and profile-guided builds of the same bench (tb/bench.cmake; a sub-build in
  # $B/bench-pgo, a few minutes the first time); when they cannot be built the plain figures
  # stand alone.
  if cmake --build "$B" --target bench_receiver_top_pgo >"$T/pgo.log" 2>&1; then
    for v in clang pgo; do
      if [[ -x $B/tb/bench_receiver_top_$v ]]; then { echo; "$B"/tb/bench_receiver_top_$v 2; } >>"$T/rtl.txt"; fi
    done
  else
    { echo; echo "bench_receiver_top_pgo: not built (last lines of its build):"; tail -n 3 "$T/pgo.log"; } >>"$T/rtl.txt"
  fi
else
  echo "not built (configure with -DRANGING_BUILD_HARDWARE=ON)" >"$T/rtl.txt"
fi
# Streaming decode: a periodic Gold4 train (simulate --write-captures), tiled to N samples.
printf '%s\n' "name: train" "medium: {temperature_c: 20}" "transducers: {}" "geometry: {distances_m: [0.5]}" \
  "excitation: {family: Gold4, schedule: {mode: periodic, period_s: 0.0004, bursts: 27}}" \
  "noise: {noise_v: 0.002, seed: 1}" >"$T/train.yaml"
"$B"/tool/ranging simulate "$T/train.yaml" --out "$T/train" --write-captures --quiet >/dev/null
: >"$T/decode.txt"
decode_bench() {  # N FILE (.wav or .csv, made by scripts/make_long_capture.py)
  local n=$1 f=$2
  $PY scripts/make_long_capture.py "$T/train/captures/Gold4_500mm_r1.wav" "$n" "$f" 9
  /usr/bin/time -v "$B"/tool/ranging decode "$f" --json >"$T/long.out" 2>"$T/long.time"
  # the bursts' metrics on 2 threads (decode --jobs 2, the same output): wall seconds by
  # time.perf_counter (/usr/bin/time counts 10 ms steps, 5 % of a 10 M-sample decode), the median
  # and the fastest of BENCH_DECODE_REPEATS (default 5) runs
  $PY - "$B/tool/ranging" "$f" "${BENCH_DECODE_REPEATS:-5}" >"$T/long2.time" <<'PYEOF'
import subprocess, sys, time
t = []
for _ in range(int(sys.argv[3])):
    a = time.perf_counter()
    subprocess.run([sys.argv[1], "decode", sys.argv[2], "--json", "--jobs", "2"], stdout=subprocess.DEVNULL, check=True)
    t.append(time.perf_counter() - a)
t.sort()
print(t[len(t) // 2], t[0])
PYEOF
  $PY -c '
import json, re, sys
t = open(sys.argv[2]).read()
g = lambda k: float(re.search(k + r".*?: ([0-9.]+)", t).group(1))
cpu = g("User time") + g("System time")
n = float(sys.argv[1])
dets = len(json.load(open(sys.argv[3]))["detections"])
rss = g("Maximum resident set size") / 1024
w2, w2min = (float(v) for v in open(sys.argv[4]).read().split())
print(f"{sys.argv[5]} {n:.0e} {cpu:.3f} {n / cpu / 1e6:.2f} {rss:.1f} {dets} {w2:.3f} {n / w2 / 1e6:.2f} {n / w2min / 1e6:.2f}")
' "$n" "$T/long.time" "$T/long.out" "$T/long2.time" "${f##*.}" >>"$T/decode.txt"
  rm -f "$f" "${f%.*}.json" "$T/long.out"
}
for n in ${BENCH_DECODE_SAMPLES:-1e7 1e8}; do decode_bench "$n" "$T/long.wav"; done
# an oscilloscope CSV (text, 32 bytes a row: 65 MB for the default 2 M rows)
for n in ${BENCH_DECODE_CSV_ROWS:-2e6}; do decode_bench "$n" "$T/long.csv"; done
# Several cores: the default scene's streams (100 repeats: 4500 streams, ~1.5 s on one core, so the one-off
# design and calibration are a small part) on 1 and 2 threads (same output: tests/test_parallel_streams).
for j in 1 2; do
  /usr/bin/time -f "%e %U %S" -o "$T/jobs$j.time" "$B"/tool/ranging simulate scenes/default.yaml \
    --set geometry.repeats=100 --out "$T/jobs$j" --quiet --jobs $j >/dev/null
done
if cmp -s "$T/jobs1/measurements.csv" "$T/jobs2/measurements.csv"; then echo same; else echo DIFFERENT; fi >"$T/jobs.same"
# Scenes per sample (only the stages and metrics each names): CPU seconds of a long run minus a
# 1-repeat run over the samples between them (summary.json samples_simulated), so the one-off
# design and calibration do not count. BENCH_ROUNDS (default 3) rounds, each running every scene
# once in turn: a change of load on a shared machine then reaches the default scene and the
# minimal one alike, and each round gives its own ratio (the median round is reported).
scene_run() {  # ROUND NAME SCENE REPEATS [ARGS...]
  local round=$1 name=$2 scene=$3 reps=$4
  shift 4
  /usr/bin/time -f "%U %S" -o "$T/scene.time" "$B"/tool/ranging simulate "$scene" --set geometry.repeats=$reps \
    --out "$T/scene" --quiet --timing "$@" >/dev/null
  echo "$round $name $reps $(cat "$T/scene.time") $($PY -c 'import json,sys; j = json.load(open(sys.argv[1])); t = j["stage_seconds"]; print(j["samples_simulated"], t["channel"], t["receiver"], t["metrics"])' "$T/scene/summary.json")" >>"$T/scenes.txt"
}
: >"$T/scenes.txt"
# (about 1 s of CPU each: /usr/bin/time counts in 10 ms steps, 10 % of the 0.1 s that 400 repeats
# of the minimal scene took)
scenes=("default scenes/default.yaml 100" "default-fixed scenes/default.yaml 100 --precision fixed"
  "default-fixed-no-metrics scenes/default.yaml 100 --precision fixed --set receiver.metrics=[]"
  "minimal scenes/minimal.yaml 4000")
for sc in "${scenes[@]}"; do
  read -r -a a <<<"$sc"
  scene_run 0 "${a[0]}" "${a[1]}" 1 "${a[@]:3}"
done
for ((round = 1; round <= ${BENCH_ROUNDS:-3}; round++)); do
  for sc in "${scenes[@]}"; do
    read -r -a a <<<"$sc"
    scene_run "$round" "${a[@]}"
  done
done
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
    # a difference of noisy timings: below zero it measures nothing, and says so
    det = f"{det_ns:10.2f}" if det_ns >= 0 else f"{'n/a':>10s}  (receiver {-det_ns:.2f} ns faster than its stages: timing noise)"
    print(f"  {prec.lower() + ' detector (receiver - others)':34s} {'':8s} {det}")
    row(f"{prec.lower()} receiver (all stages)", rx)
row("fixed receiver, per-sample API", m["BM_FixedReceiverPerSample"])
b8 = m["BM_FixedReceiverBatch8"]
label = next(b.get("label", "") for b in json.load(open(f"{t}/model.json"))["benchmarks"] if b["name"] == "BM_FixedReceiverBatch8")
row("fixed receiver, 8 streams at once", b8)
row("float receiver, 8 streams at once", m["BM_FloatReceiverBatch8"])
print(f"  8 streams at once ({label}: ReceiverFixedBatch, samples of all streams per CPU second) / one stream: "
      f"{b8 / m['BM_FixedReceiver']:.2f}x (float {m['BM_FloatReceiverBatch8'] / m['BM_FloatReceiver']:.2f}x); "
      f"target >= 125 MS/s per core: {'met' if b8 >= 125e6 else 'NOT met'} with 8 streams, "
      f"{'met' if m['BM_FixedReceiver'] >= 125e6 else 'NOT met'} with one")
print(f"  float / fixed receiver: {m['BM_FloatReceiver'] / m['BM_FixedReceiver']:.2f}")
lab = {b["name"]: b.get("label", "") for b in json.load(open(f"{t}/model.json"))["benchmarks"]}
row("fixed receiver, one long stream", m["BM_FixedReceiverLong"])
row("float receiver, one long stream", m["BM_FloatReceiverLong"])
print(f"  one 2 M-sample stream / the 23 k-sample input: fixed {m['BM_FixedReceiverLong'] / m['BM_FixedReceiver']:.2f}x, "
      f"float {m['BM_FloatReceiverLong'] / m['BM_FloatReceiver']:.2f}x (time splits, fixed: {lab['BM_FixedReceiverLong']}); "
      f"target >= 125 MS/s: {'met' if m['BM_FixedReceiverLong'] >= 125e6 else 'NOT met'} on a long stream; "
      f"float / fixed on it: {m['BM_FloatReceiverLong'] / m['BM_FixedReceiverLong']:.2f}")
print()
print("Channel stages (bench_model, the same input):")
row("white noise (Boost ziggurat)", m["BM_WhiteNoise"])
row("std::normal_distribution (before)", m["BM_StdNormalNoise"])
row("ADC, 12 bits", m["BM_Adc"])
row("clean burst (transducers, delay)", m["BM_ChannelClean"])
print(f"  white noise / std::normal_distribution: {m['BM_WhiteNoise'] / m['BM_StdNormalNoise']:.2f}x")
print()
k, kt = f["BM_BandpassFixed"], f["BM_FixedType"]
sc, scf = f["BM_ScFixed"], f["BM_ScFix"]
s4, s1m = float(sos["sosfilt_4096"]) * 1e6, float(sos["sosfilt_1048576"]) * 1e6
print(f"Bandpass kernel ({sos['sections']} sections, 4096-sample 200 kHz sine), MS/s:")
print(f"  ours, bit-exact fixed (execute_raw per sample)  {k/1e6:8.2f}")
print(f"  ours, bit-exact fixed (execute_block)           {f['BM_BandpassFixedBlock']/1e6:8.2f}")
print(f"  ours, execute_block on the receiver's input     {m['BM_FixedBandpass']/1e6:8.2f}  (22953 samples)")
flab = {b["name"]: b.get("label", "") for b in json.load(open(f"{t}/fixed.json"))["benchmarks"]}
print(f"  ours, execute_block on 1 M samples              {f['BM_BandpassFixedBlock1M']/1e6:8.2f}  ({flab['BM_BandpassFixedBlock1M']})")
print(f"  ranging::Fixed type                             {kt/1e6:8.2f}")
print(f"  sc_fixed<16,2,SC_RND,SC_SAT>                    {sc/1e6:8.2f}")
print(f"  sc_fix (runtime parameters)                     {scf/1e6:8.2f}")
print(f"  scipy.signal.sosfilt float64, 4096 samples      {s4/1e6:8.2f}")
print(f"  scipy.signal.sosfilt float64, 1 M samples       {s1m/1e6:8.2f}")
kb = f["BM_BandpassFixedBlock"]
print(f"  ratios: block kernel / sosfilt (4096) {kb/s4:.2f}, / sosfilt (1 M) {kb/s1m:.2f}, "
      f"1 M-sample block / sosfilt (1 M) {f['BM_BandpassFixedBlock1M']/s1m:.2f}, "
      f"/ sc_fixed {kb/sc:.0f}; per-sample kernel / sc_fixed {k/sc:.0f}")
print()
print("Streaming decode (ranging decode --json of a train as a float32 WAV and as a CSV, /usr/bin/time -v; MS/s per")
print("  CPU second; --jobs 2: wall time, the median and the fastest of BENCH_DECODE_REPEATS runs; target >= 50 MS/s):")
print(f"  {'file':>4s} {'samples':>8s} {'CPU s':>8s} {'MS/s':>8s} {'peak RSS MB':>12s} {'bursts':>7s} "
      f"{'--jobs 2 wall s':>16s} {'MS/s (wall)':>12s} {'fastest run':>12s}")
for line in open(f"{t}/decode.txt"):
    kind, n, cpu, rate, rss, dets, w2, r2, r2max = line.split()
    print(f"  {kind:>4s} {n:>8s} {cpu:>8s} {rate:>8s} {rss:>12s} {dets:>7s} {w2:>16s} {r2:>12s} {r2max:>12s}")
print()
w = {j: [float(v) for v in open(f"{t}/jobs{j}.time").read().split()] for j in (1, 2)}
print("Several cores (simulate scenes/default.yaml --set geometry.repeats=100; wall time, user+sys CPU):")
for j in (1, 2):
    print(f"  --jobs {j}: wall {w[j][0]:.2f} s, CPU {w[j][1] + w[j][2]:.2f} s")
print(f"  speedup (wall, jobs 1 / jobs 2): {w[1][0] / w[2][0]:.2f}; measurements.csv "
      f"{open(f'{t}/jobs.same').read().strip()} (target >= 1.8 on 2 idle cores)")
print()
print("Scenes, per received sample (simulate; CPU of a long run minus a 1-repeat run, over the samples between;")
print("  the median of the rounds, each round running every scene once in turn):")
sc = {}
for line in open(f"{t}/scenes.txt"):
    rnd, name, r, u, sy, n, ch, rx, mt = line.split()
    sc.setdefault(name, {})[int(rnd)] = (float(u) + float(sy), int(n), float(ch), float(rx), float(mt))
med = lambda v: sorted(v)[len(v) // 2]
ns_round = {}  # name -> {round: ns per sample}
for name, v in sc.items():
    c1, n1, ch1, rx1, mt1 = v[0]
    per = lambda a, b, nr: (b - a) / (nr - n1) * 1e9
    ns_round[name] = {k: per(c1, x[0], x[1]) for k, x in v.items() if k > 0}
    rows = [x for k, x in v.items() if k > 0]
    ns = med(list(ns_round[name].values()))
    spread = f"{min(ns_round[name].values()):.1f}-{max(ns_round[name].values()):.1f}"
    chs, rxs, mts = (med([per(b0, x[i], x[1]) for x in rows]) for i, b0 in ((2, ch1), (3, rx1), (4, mt1)))
    print(f"  {name:26s} {ns:8.1f} ns/sample ({spread:>9s}) {1e3 / ns:8.1f} MS/s {1e3 / ns / 5:8.1f} x real time;"
          f" per stage (simulate --timing) channel {chs:5.1f} ({1e3 / max(chs, 1e-9) / 5:5.1f}x real time),"
          f" receiver {rxs:5.1f}, metrics {mts:5.1f} ns/sample")
rounds = sorted(ns_round["minimal"])
ratio = [ns_round["default"][k] / ns_round["minimal"][k] for k in rounds]
fixed = [ns_round["default-fixed-no-metrics"][k] / ns_round["default-fixed"][k] for k in rounds]
print(f"  default / minimal per sample: {med(ratio):.2f} (rounds: {', '.join(f'{r:.2f}' for r in ratio)}; target >= 5); "
      f"fixed precision, metrics [] / all: {med(fixed):.2f}")
print()
print("Verilator RTL (tb/bench_receiver_top):")
for line in open(f"{t}/rtl.txt"):
    print("  " + line.rstrip())
PYEOF
