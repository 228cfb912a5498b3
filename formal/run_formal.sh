#!/usr/bin/env bash
# Proves the formal properties of one RTL module (the `ifdef FORMAL` blocks beside the module in
# rtl/*.v, ZipCPU style): bounded model checking to DEPTH steps from reset, then an unbounded
# proof unless the job file says it does not close. Engine smtbmc (default): yosys-smtbmc with
# z3, the proof k-induction of the same depth. Engine abc: the model as AIGER, yosys-abc's
# bmc3 (BMC) and pdr (property-directed reachability, the proof), as SymbiYosys' `abc bmc3` /
# `abc pdr`. Exit 0: every assertion holds; 1: a property fails (smtbmc: the counterexample
# trace goes to OUT/NAME-{bmc,ind}.vcd; abc: OUT/NAME-{bmc,pdr}.aiw and the failing assertion's
# name); 2: usage or tool error.
#
# Usage: formal/run_formal.sh JOB [--rtl DIR] [--out DIR] [--depth N] [--bmc-only]
#   JOB is formal/JOB.job: lines `top MODULE`, `files a.v b.v` (relative to the RTL folder;
#   formal/x.v: an environment model in formal/),
#   `chparam NAME VALUE` (parameters for the proof), `define NAME` (a Verilog define),
#   `engine smtbmc|abc`, `induction yes|no` (the unbounded proof), `depth N`, `assert_inputs
#   MODULE...` (a system proof: those submodules' assumptions on their inputs become assertions
#   of the composition, so each is proven of the module that drives it).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
usage() { sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; }
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
top=""; files=(); chp=""; induction=yes; jdepth=24; defines=""; engine=smtbmc; a2a=""; a2a_mods=()
while read -r key rest; do
  case "$key" in
    ''|'#'*) ;;
    top) top=$rest ;;
    files) read -r -a files <<<"$rest" ;;
    chparam) read -r n v <<<"$rest"; chp+="-set $n $v " ;;
    define) defines+=" -D$rest" ;;
    induction) induction=$rest ;;
    depth) jdepth=$rest ;;
    assert_inputs) read -r -a a2a_mods <<<"$rest"
                   for m in "${a2a_mods[@]}"; do a2a+="chformal -assume -assume2assert *$m*; "; done ;;
    engine) engine=$rest
            [[ $engine == smtbmc || $engine == abc ]] || { echo "run_formal: $jf: engine must be smtbmc or abc, got '$engine'" >&2; exit 2; } ;;
    *) echo "run_formal: $jf: unknown key '$key'" >&2; exit 2 ;;
  esac
done <"$jf"
# all parameters in one chparam (one elaboration with the proof's parameters)
[[ -n $chp ]] && chp="chparam $chp $top; "
if [[ $engine == smtbmc ]]; then tools=(yosys yosys-smtbmc z3); else tools=(yosys yosys-abc); fi
for t in "${tools[@]}"; do
  command -v "$t" >/dev/null || { echo "run_formal: $t not found (scripts/install-deps.sh installs it)" >&2; exit 2; }
done
depth=${depth:-$jdepth}
out=${out:-"${TMPDIR:-/tmp}/ranging-formal-$job-$$"}
mkdir -p "$out"
uc=$(echo "$top" | tr a-z A-Z)
rc=""
for f in "${files[@]}"; do
  # formal/NAME.v: a proof's environment model beside the jobs; anything else is an RTL file
  if [[ $f == formal/* ]]; then fp="$root/$f"; else fp="$rtl/$f"; fi
  rc+="read_verilog -formal -DFORMAL -DF_$uc$defines $fp; "
done
if [[ $engine == abc ]]; then
  # one AIGER model (assertions as bad states, assumptions as constraints; uninitialized
  # registers free at step 0), as SymbiYosys writes it for its abc engines
  yosys -q -l "$out/$job-yosys.log" -p "$rc $chp prep -top $top; $a2a flatten; memory_map; opt -fast; async2sync; \
      chformal -assume -early; setundef -undriven -anyseq; opt -fast; delete -output; techmap; \
      opt -fast; abc -g AND -fast; opt_clean; dffunmap; aigmap; tee -q -o $out/$job-asserts.txt select -list t:\$assert; \
      write_aiger -I -B -zinit -map $out/$job.aim $out/$job.aig" >/dev/null \
    || { echo "run_formal: yosys failed, see $out/$job-yosys.log" >&2; exit 2; }
  # bad-state outputs are numbered in the order of the model's assertion cells
  # (an assumption turned into an assertion by assert_inputs keeps its $assume name)
  name_of() { grep -E '[./]\$(assert|assume)\$' "$out/$job-asserts.txt" | sed -n "$(( $1 + 1 ))p"; }
  abc_run() {  # abc_run KIND COMMAND
    yosys-abc -c "read_aiger $out/$job.aig; fold; strash; $2; write_cex -a $out/$job-$1.aiw" >"$out/$job-$1.log" 2>&1 \
      || { echo "run_formal: yosys-abc failed, see $out/$job-$1.log" >&2; exit 2; }
    local f
    f=$(grep -o 'Output [0-9]* of miter "[^"]*" was asserted in frame [0-9]*' "$out/$job-$1.log" | head -1 || true)
    if [[ -n $f ]]; then
      local idx=${f#Output }; idx=${idx%% *}
      echo "$job: $1 FAILED: $f: $(name_of "$idx") (witness $out/$job-$1.aiw)"
      exit 1
    fi
  }
  t0=$(date +%s)
  abc_run bmc "bmc3 -F $depth"
  grep -q "No output asserted in $depth frames" "$out/$job-bmc.log" \
    || { echo "run_formal: bmc3 did not finish $depth frames, see $out/$job-bmc.log" >&2; exit 2; }
  echo "$job: BMC depth $depth passed ($(( $(date +%s) - t0 )) s, abc bmc3)"
  if [[ $induction == yes && $bmc_only == 0 ]]; then
    t0=$(date +%s)
    abc_run pdr "pdr"
    grep -q "Property proved" "$out/$job-pdr.log" \
      || { echo "run_formal: pdr gave no answer, see $out/$job-pdr.log" >&2; exit 2; }
    echo "$job: pdr proof passed ($(( $(date +%s) - t0 )) s): proven for all depths"
  fi
  exit 0
fi
# one SMT2 model of the flattened design; async2sync/dffunmap as SymbiYosys' prep does
yosys -q -l "$out/$job-yosys.log" -p "$rc $chp prep -top $top; $a2a flatten; opt_clean; async2sync; chformal -assume -early; dffunmap; \
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
