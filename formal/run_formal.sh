#!/usr/bin/env bash
# Proves the formal properties of one RTL module (the `ifdef FORMAL` blocks beside the module in
# rtl/*.v, ZipCPU style) with yosys-smtbmc and z3: bounded model checking to DEPTH steps from
# reset, then k-induction of the same depth (unbounded proof) unless the module's job file says
# the induction does not close. Exit 0: every assertion holds; 1: a property fails (the
# counterexample trace goes to OUT/NAME-{bmc,ind}.vcd); 2: usage or tool error.
#
# Usage: formal/run_formal.sh JOB [--rtl DIR] [--out DIR] [--depth N] [--bmc-only]
#   JOB is formal/JOB.job: lines `top MODULE`, `files a.v b.v` (relative to the RTL folder),
#   `chparam NAME VALUE` (parameters for the proof), `induction yes|no`, `depth N`.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
usage() { sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; }
[[ $# -ge 1 ]] || { usage >&2; exit 2; }
case "$1" in -h|--help) usage; exit 0 ;; esac
job=$1; shift
rtl="$root/rtl"; out=""; depth=""; bmc_only=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --rtl) rtl=$(realpath "${2:?--rtl needs DIR}"); shift 2 ;;
    --out) out=$(realpath -m "${2:?--out needs DIR}"); shift 2 ;;
    --depth) depth=${2:?--depth needs N}; shift 2
             [[ "$depth" =~ ^[1-9][0-9]{0,3}$ ]] || { echo "run_formal: --depth must be 1..9999, got '$depth'" >&2; exit 2; } ;;
    --bmc-only) bmc_only=1; shift ;;
    -h|--help) usage; exit 0 ;;
    *) echo "run_formal: unknown option '$1'" >&2; exit 2 ;;
  esac
done
jf="$root/formal/$job.job"
[[ -f "$jf" ]] || { echo "run_formal: no job file $jf" >&2; exit 2; }
for t in yosys yosys-smtbmc z3; do
  command -v "$t" >/dev/null || { echo "run_formal: $t not found (scripts/install-deps.sh installs it)" >&2; exit 2; }
done
top=""; files=(); chp=""; induction=yes; jdepth=24; defines=""
while read -r key rest; do
  case "$key" in
    ''|'#'*) ;;
    top) top=$rest ;;
    files) read -r -a files <<<"$rest" ;;
    chparam) read -r n v <<<"$rest"; chp+="chparam -set $n $v $top; " ;;
    define) defines+=" -D$rest" ;;
    induction) induction=$rest ;;
    depth) jdepth=$rest ;;
    *) echo "run_formal: $jf: unknown key '$key'" >&2; exit 2 ;;
  esac
done <"$jf"
depth=${depth:-$jdepth}
out=${out:-"${TMPDIR:-/tmp}/ranging-formal-$job-$$"}
mkdir -p "$out"
uc=$(echo "$top" | tr a-z A-Z)
rc=""
for f in "${files[@]}"; do rc+="read_verilog -formal -DFORMAL -DF_$uc$defines $rtl/$f; "; done
# one SMT2 model of the flattened design; async2sync/dffunmap as SymbiYosys' prep does
yosys -q -l "$out/$job-yosys.log" -p "$rc $chp prep -top $top; flatten; opt_clean; async2sync; chformal -assume -early; dffunmap; \
    write_smt2 -wires $out/$job.smt2" >/dev/null || { echo "run_formal: yosys failed, see $out/$job-yosys.log" >&2; exit 2; }
status=0
t0=$(date +%s)
if ! yosys-smtbmc -s z3 --presat -t "$depth" --dump-vcd "$out/$job-bmc.vcd" "$out/$job.smt2" >"$out/$job-bmc.log" 2>&1; then
  grep -E "Assert failed|failed|Error" "$out/$job-bmc.log" | head -5 >&2
  echo "$job: BMC FAILED within $depth steps (trace $out/$job-bmc.vcd)"
  exit 1
fi
echo "$job: BMC depth $depth passed ($(( $(date +%s) - t0 )) s)"
if [[ $induction == yes && $bmc_only == 0 ]]; then
  t0=$(date +%s)
  if ! yosys-smtbmc -s z3 -i -t "$depth" --dump-vcd "$out/$job-ind.vcd" "$out/$job.smt2" >"$out/$job-ind.log" 2>&1; then
    grep -E "Assert failed|failed|Error" "$out/$job-ind.log" | head -5 >&2
    echo "$job: induction FAILED at depth $depth (trace $out/$job-ind.vcd)"
    exit 1
  fi
  echo "$job: induction depth $depth passed ($(( $(date +%s) - t0 )) s): proven for all depths"
fi
exit $status
