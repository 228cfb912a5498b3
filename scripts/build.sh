#!/usr/bin/env bash
# Configures and builds the project into a build directory.
# Usage: scripts/build.sh [BUILD_DIR] [extra cmake args...]
# With CI=true warnings are errors (-Wall -Wextra -Werror).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-"$root/build"}
shift || true
args=(-DCMAKE_BUILD_TYPE=Release)
if [[ "${CI:-}" == "true" ]]; then
  args+=(-DRANGING_WERROR=ON)
fi
cmake -S "$root" -B "$build" "${args[@]}" "$@" >/dev/null
cmake --build "$build" -j"$(nproc)"
