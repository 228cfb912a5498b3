#!/usr/bin/env bash
# run_fuzz.sh TARGET SECONDS|runs=N CORPUS SEED_DIR... : fuzz TARGET for SECONDS seconds (or N
# executions) on CORPUS (created, kept between runs), seeded with the files of each SEED_DIR.
# A crash, leak, timeout (60 s wall clock: ASan builds on a loaded machine are slow) or UB
# report fails it; the input is left in CORPUS/../artifacts-NAME/ (copy it
# to tests/fuzz/regressions/<target>/). Prints libFuzzer's final stats (executions, coverage).
set -euo pipefail
target=$1 budget=$2 corpus=$3
shift 3
mkdir -p "$corpus"
artifacts=$(dirname "$corpus")/artifacts-$(basename "$corpus")/
mkdir -p "$artifacts"
if [[ $budget == runs=* ]]; then limit=(-runs="${budget#runs=}"); else limit=(-max_total_time="$budget"); fi
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
"$target" "${limit[@]}" -max_len=16384 -timeout=60 -rss_limit_mb=2048 -print_final_stats=1 \
  -artifact_prefix="$artifacts" "$corpus" "$@" 2>&1 | grep -v '^#[0-9]*.*\(NEW\|REDUCE\|pulse\)' | tail -40
exit "${PIPESTATUS[0]}"
