#!/usr/bin/env bash
# The main job end to end on the built-in default: install what is missing, build, run `ranging demo`.
# Extra arguments go to `ranging demo` (see `ranging demo --help`).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
"$root/scripts/install-deps.sh" --hardware
"$root/scripts/build.sh" "$root/build" >/dev/null
exec "$root/build/tool/ranging" demo "$@"
