#!/usr/bin/env bash
# Runs a `ranging sweep` on a Slurm cluster: one array task per shard (sbatch --array), then a
# merge job that depends on them (docs/design-space.md). The spec is checked before anything
# is submitted. Shards share one synthesis cache (OUT/cache).
#
# Usage: scripts/slurm-sweep.sh SPEC.yaml OUT_DIR SHARDS [sbatch options...]
#   RANGING=path/to/ranging   the tool (default: build/tool/ranging of this tree)
#   SWEEP_OPTS="--no-synth"   extra options for every shard
# Prints "array JOBID merge JOBID"; the result appears in OUT_DIR/merged/ (sweep.json,
# points.csv, summary.md, front.png), shard outputs in OUT_DIR/shardI, logs in OUT_DIR/logs.
set -euo pipefail
if [[ $# -lt 3 || "$1" == "--help" ]]; then
  sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'
  [[ "${1:-}" == "--help" ]] && exit 0 || exit 2
fi
spec=$1 out=$2 shards=$3
shift 3
root=$(cd "$(dirname "$0")/.." && pwd)
ranging=$(realpath "${RANGING:-$root/build/tool/ranging}")
[[ -x "$ranging" ]] || { echo "slurm-sweep.sh: $ranging not found (build it, or set RANGING)" >&2; exit 2; }
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || { echo "slurm-sweep.sh: SHARDS: '$shards' is not an integer >= 1" >&2; exit 2; }
command -v sbatch >/dev/null || { echo "slurm-sweep.sh: sbatch not found (Debian slurm-client)" >&2; exit 2; }
spec=$(realpath "$spec")
"$ranging" sweep "$spec" --out "$out/merged" --dry-run >/dev/null  # a bad spec exits 2 here
mkdir -p "$out/logs" "$out/cache"
out=$(realpath "$out")
opts=${SWEEP_OPTS:-}
array=$(sbatch --parsable --array=0-$((shards - 1)) --job-name=ranging-sweep --output="$out/logs/shard-%a.log" "$@" \
  --wrap "'$ranging' sweep '$spec' --out '$out/shard'\$SLURM_ARRAY_TASK_ID --shard \$SLURM_ARRAY_TASK_ID/$shards --cache '$out/cache' --quiet --no-plot $opts")
array=${array%%;*}
dirs=""
for ((i = 0; i < shards; i++)); do dirs+=" '$out/shard$i'"; done
merge=$(sbatch --parsable --dependency=afterok:$array --job-name=ranging-sweep-merge --output="$out/logs/merge.log" "$@" \
  --wrap "'$ranging' sweep merge --out '$out/merged' $dirs ${MERGE_OPTS:-}")
merge=${merge%%;*}
echo "array $array merge $merge"
