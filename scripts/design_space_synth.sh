#!/bin/bash
# Synthesis of chosen design-space points (docs/results/design-space.md): for each point (a list
# of configuration --set overrides on configs/default.yaml), `ranging generate` and yosys
# synth_ice40 -dsp / synth_ecp5 / synth_xilinx -family xc7 of the generated receiver_top with rtl/bandpass_sos.v,
# correlator_bank.v and peak_detector.v; one JSON object per point on stdout.
#   scripts/design_space_synth.sh OUT_DIR NAME "KEY=VALUE ..." [NAME "KEY=VALUE ..." ...]
# One yosys at a time (nice). Needs yosys (scripts/install-deps.sh).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
ranging=${RANGING:-$root/build/tool/ranging}
out=${1:?usage: design_space_synth.sh OUT_DIR NAME "KEY=VALUE ..." ...}
shift
mkdir -p "$out"
while [ $# -ge 2 ]; do
  name=$1 sets=$2
  shift 2
  dir="$out/$name"
  rm -rf "$dir"
  args=()
  for kv in $sets; do args+=(--set "$kv"); done
  "$ranging" generate --config "$root/configs/default.yaml" "${args[@]}" --out "$dir/gen" > "$dir.gen.log" 2>&1
  reads=""
  for m in fx_quantize bandpass_sos correlator_bank peak_detector; do reads+="read_verilog -defer $root/rtl/$m.v; "; done
  reads+="read_verilog -defer -I$dir/gen/rtl $dir/gen/rtl/receiver_top.v; hierarchy -top receiver_top; "
  nice yosys -q -l "$dir/ice40.log" -p "$reads synth_ice40 -dsp -top receiver_top; tee -q -o $dir/ice40.txt stat" > /dev/null
  nice yosys -q -l "$dir/ecp5.log" -p "$reads synth_ecp5 -top receiver_top; tee -q -o $dir/ecp5.txt stat" > /dev/null
  nice yosys -q -l "$dir/xilinx.log" -p "$reads synth_xilinx -family xc7 -top receiver_top; tee -q -o $dir/xilinx.txt stat" > /dev/null
  /usr/bin/python3 - "$name" "$sets" "$dir" <<'PY'
import json, re, sys
name, sets, d = sys.argv[1], sys.argv[2], sys.argv[3]
def cells(path):
    c = {}
    for line in open(path):
        m = re.match(r"\s+(\S+)\s+(\d+)\s*$", line)
        if m: c[m.group(1)] = c.get(m.group(1), 0) + int(m.group(2))
    return c
i, e, x = cells(d + "/ice40.txt"), cells(d + "/ecp5.txt"), cells(d + "/xilinx.txt")
ice = {"lut4": i.get("SB_LUT4", 0), "dff": sum(v for k, v in i.items() if k.startswith("SB_DFF")),
       "carry": i.get("SB_CARRY", 0), "mac16": i.get("SB_MAC16", 0),
       "ebr": sum(v for k, v in i.items() if k.startswith("SB_RAM40"))}
ecp5 = {"lut4": e.get("LUT4", 0), "ff": sum(v for k, v in e.items() if k.startswith("TRELLIS_FF")),
        "ccu2c": e.get("CCU2C", 0), "mult18": e.get("MULT18X18D", 0),
        "ebr": e.get("DP16KD", 0) + e.get("PDPW16KD", 0), "lutram": e.get("TRELLIS_DPR16X4", 0)}
xil = {"lut": sum(v for k, v in x.items() if re.match(r"LUT\d$", k)),
       "ff": sum(v for k, v in x.items() if k.startswith("FD")), "carry4": x.get("CARRY4", 0),
       "dsp48": x.get("DSP48E1", 0), "ramb18": x.get("RAMB18E1", 0), "ramb36": x.get("RAMB36E1", 0),
       "lutram": sum(v for k, v in x.items() if k.startswith("RAM") and not k.startswith("RAMB")),
       "srl": sum(v for k, v in x.items() if k.startswith("SRL"))}
print(json.dumps({"name": name, "set": sets.split(), "ice40": ice, "ecp5": ecp5, "xilinx": xil}))
PY
done
