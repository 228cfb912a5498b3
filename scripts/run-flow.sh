#!/usr/bin/env bash
# The main job, end to end, on the built-in default (configs/default.yaml, scenes/default.yaml):
#   1. golden model: simulate the default scene and decode it (float and fixed point)
#   2. RTL equivalence: the generated receiver in Verilator against the golden model, stage by stage
#   3. HLS C-simulation: the HLS C++ against the golden model, bit for bit
#   4. bitstream: yosys / nextpnr-ice40 / icepack for the iCEBreaker (iCE40UP5K), resources and Fmax
# and prints a short report. Installs what is missing (Debian packages) and builds first.
# Usage: scripts/run-flow.sh [--no-bitstream]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build="$root/build"
bitstream=1
for a in "$@"; do
  case "$a" in
    --no-bitstream) bitstream=0 ;;
    -h|--help) sed -n 2,8p "$0"; exit 0 ;;
    *) echo "run-flow: unknown option '$a' (see --help)" >&2; exit 2 ;;
  esac
done

step() { printf '\n== %s ==\n' "$*" >&2; }

step "install and build"
"$root/scripts/install-deps.sh" --hardware
mkdir -p "$build"  # the build log goes into it before CMake creates it (fresh clone)
"$root/scripts/build.sh" "$build" >/dev/null 2>"$build/flow-build.log" || { cat "$build/flow-build.log" >&2; exit 1; }

work="$build/flow"
mkdir -p "$work"

step "1/4 golden model: ranging simulate scenes/default.yaml"
"$build/tool/ranging" simulate "$root/scenes/default.yaml" --precision fixed --out "$work/scene" --quiet >/dev/null
scene=$(/usr/bin/python3 - "$work/scene/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
f = s["families"][0]
print(f"{f['family']}: {f['measurements']} bursts, {s['decode_errors']} decode errors, "
      f"distance RMSE {f['distance_rmse_m'] * 1e3:.3f} mm, u_min {f['u_min']:.3f}, v_max {f['vmax_hz']:.0f} Hz")
PY
)

step "2/4 RTL equivalence: tb_receiver_top (Verilator)"
# The equivalence tests; the 10^8-sample soak (ReceiverTopSoak, label soak) is left to ctest -L soak.
if "$build/tb/tb_receiver_top" --gtest_filter='-*Soak.*' > "$work/rtl.log" 2>&1; then rtl_ok=PASS; else rtl_ok=FAIL; fi
rtl_samples=$(awk '{for (i = 1; i + 2 <= NF; i++) if ($(i+1) == "samples" && $(i+2) == "compared") s += $i} END {print s + 0}' "$work/rtl.log")
[[ $rtl_samples -gt 0 ]] || rtl_ok=FAIL  # a run that compared nothing proves nothing

step "3/4 HLS C-simulation: test_hls_csim"
if "$build/tests/test_hls_csim" > "$work/hls.log" 2>&1; then hls_ok=PASS; else hls_ok=FAIL; fi

bit="skipped (--no-bitstream)"
if [[ $bitstream == 1 ]]; then
  step "4/4 bitstream: scripts/build_bitstream.sh (several minutes)"
  "$root/scripts/build_bitstream.sh" --build-dir "$build" --results "$work" --no-others > "$work/bitstream.log" 2>&1 || true
  bit=$(/usr/bin/python3 - "$work/bitstream.json" <<'PY'
import json, sys
try:
    b = json.load(open(sys.argv[1]))
except Exception as e:
    print(f"FAILED (no summary: {e}); see build/flow/bitstream.log"); sys.exit()
r = b["ice40"]
line = (f"LUT4 {r['lut4']}/5280, DFF {r['dff']}, SB_MAC16 {r['sb_mac16']}/8, EBR {r['ebr']}/30, "
        f"SPRAM {r['spram']}/4")
if r.get("placed_and_routed") and r.get("bitstream"):
    print(f"{r['bitstream']}: {line}; Fmax {r.get('fmax_mhz', '?')} MHz, "
          f"{r['required_clock_mhz']} MHz required; targets met: {b['targets_met']}")
else:
    print(f"NOT BUILT: {line}; targets missed: " + "; ".join(b.get("target_failures", [])))
PY
)
fi

cat <<REPORT

ranging: co-design flow on configs/default.yaml
  scene (golden model)  $scene
  RTL equivalence       $rtl_ok: $rtl_samples samples compared stage by stage (Verilator, receiver_top vs ReceiverFixed)
  HLS C-simulation      $hls_ok (hls/receiver_hls.hpp vs ReceiverFixed)
  bitstream             $bit
REPORT
[[ $rtl_ok == PASS && $hls_ok == PASS ]]
