#!/usr/bin/env bash
# The whole test suite: install what is missing, build, run ctest.
# With CI=true: warnings are errors, and the suite runs a second time in an ASan+UBSan build.
# Tests labelled "soak" (minutes long) are skipped unless RANGING_SOAK=1.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh" --hardware
jobs=$(nproc)
# Labels: unit, hardware, postsynth run always; bitstream (place and route against the UP5K
# targets, ~8 min on one core) in CI (CI=true) or with RANGING_BITSTREAM=1; soak only with
# RANGING_SOAK=1; cluster (a one-node Slurm cluster, root, ~25 s) only with RANGING_CLUSTER=1
# (it installs slurm-wlm and munge).
skip=()
[[ "${RANGING_SOAK:-0}" == "1" ]] || skip+=(soak)
if [[ "${RANGING_CLUSTER:-0}" == "1" ]]; then "$root/scripts/install-deps.sh" --cluster; else skip+=(cluster); fi
[[ "${RANGING_BITSTREAM:-0}" == "1" || "${CI:-}" == "true" ]] || skip+=(bitstream)
exclude=()
if ((${#skip[@]})); then
  exclude=(-LE "^($(IFS='|'; echo "${skip[*]}"))\$")
fi
# The sanitized pass skips the same labels and never places and routes.
asan_skip=(bitstream)
for l in "${skip[@]}"; do [[ $l == bitstream ]] || asan_skip+=("$l"); done

echo "== build (Release) =="
"$root/scripts/build.sh" "$root/build"
echo "== tests (Release) =="
ctest --test-dir "$root/build" --output-on-failure -j"$jobs" "${exclude[@]}"

if [[ "${CI:-}" == "true" || "${RANGING_SANITIZE:-0}" == "1" ]]; then
  echo "== build (ASan+UBSan) =="
  # The model, the CLI and every unit test run sanitized; the Verilated testbenches, already
  # run in the Release pass, are left out here (recompiling the Verilated models with the
  # sanitizers would double CI time for no model code that the unit tests do not cover).
  "$root/scripts/build.sh" "$root/build-asan" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DRANGING_SANITIZE=ON -DRANGING_BUILD_BENCH=OFF -DRANGING_BUILD_HARDWARE=OFF
  echo "== tests (ASan+UBSan) =="
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir "$root/build-asan" --output-on-failure -j"$jobs" \
      -LE "^($(IFS='|'; echo "${asan_skip[*]}"))\$"
fi
