#!/usr/bin/env bash
# ctest label "cluster": starts a one-node Slurm cluster on localhost (munged, slurmctld, slurmd,
# slurm.conf in a temp folder), runs scripts/slurm-sweep.sh on a tiny sweep as a 4-task array
# plus its merge job, compares the merge with a serial run and stops the daemons it started,
# by PID. Needs root and Debian slurm-wlm + munge (scripts/install-deps.sh --cluster).
# Usage: tests/cluster/slurm_sweep.sh RANGING SOURCE_DIR
set -euo pipefail
ranging=$1 src=$2
for t in munged mungekey slurmctld slurmd sbatch squeue sinfo; do
  command -v "$t" >/dev/null || { echo "FAIL: $t not found (scripts/install-deps.sh --cluster)"; exit 1; }
done
[[ $(id -u) == 0 ]] || { echo "FAIL: the one-node cluster runs as root (SlurmUser=root)"; exit 1; }
tmp=$(mktemp -d /tmp/ranging-slurm.XXXXXX)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
  rm -rf "$tmp"
}
trap cleanup EXIT
port=$((20000 + $$ % 20000))

mungekey --create --keyfile="$tmp/munge.key"
chmod 600 "$tmp/munge.key"
munged --foreground --force --socket="$tmp/munge.sock" --key-file="$tmp/munge.key" \
  --pid-file="$tmp/munged.pid" --log-file="$tmp/munged.log" --seed-file="$tmp/munge.seed" >"$tmp/munged.out" 2>&1 &
pids+=($!)
mkdir -p "$tmp/state" "$tmp/spool"
cat > "$tmp/slurm.conf" <<CONF
ClusterName=ranging
SlurmctldHost=localhost
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$tmp/munge.sock
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
SlurmctldPort=$port
SlurmdPort=$((port + 1))
StateSaveLocation=$tmp/state
SlurmdSpoolDir=$tmp/spool
SlurmctldPidFile=$tmp/slurmctld.pid
SlurmdPidFile=$tmp/slurmd.pid
SlurmctldLogFile=$tmp/slurmctld.log
SlurmdLogFile=$tmp/slurmd.log
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$tmp/slurm.conf
for _ in $(seq 50); do [[ -S "$tmp/munge.sock" ]] && break; sleep 0.2; done
slurmctld -D -c -f "$SLURM_CONF" >"$tmp/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -N localhost -f "$SLURM_CONF" >"$tmp/slurmd.out" 2>&1 &
pids+=($!)
state=""
for _ in $(seq 120); do
  state=$(sinfo -h -o %T 2>/dev/null || true)
  [[ "$state" == idle* ]] && break
  sleep 0.5
done
[[ "$state" == idle* ]] || { echo "FAIL: the node did not come up (state '$state')"; tail -n 20 "$tmp"/*.out; exit 1; }

# A tiny sweep (4 grid points + the base), serial and on the cluster.
cat > "$tmp/scene.yaml" <<YAML
transducers: {}
geometry:
  distances_m: [0.3, 0.8]
excitation:
  family: Gold4
  codes: [1, 9]
noise:
  noise_v: 0.01
YAML
cat > "$tmp/spec.yaml" <<YAML
name: cluster
config: $src/configs/default.yaml
scene: scene.yaml
mode: grid
axes:
  - key: correlator_fixed.chip_bits
    values: [14, 22]
  - key: scene.noise.noise_v
    values: [0.005, 0.02]
YAML
"$ranging" sweep "$tmp/spec.yaml" --out "$tmp/serial" --no-synth --no-plot --quiet >/dev/null
jobs=$(RANGING=$ranging SWEEP_OPTS=--no-synth MERGE_OPTS=--no-plot "$src/scripts/slurm-sweep.sh" "$tmp/spec.yaml" "$tmp/cluster" 4)
merge=${jobs##* }
for _ in $(seq 600); do
  [[ -z "$(squeue -h 2>/dev/null)" ]] && break
  sleep 0.5
done
[[ -z "$(squeue -h)" ]] || { echo "FAIL: jobs still queued after 5 min"; squeue; exit 1; }
[[ -f "$tmp/cluster/merged/sweep.json" ]] || { echo "FAIL: no merged result (job $merge)"; cat "$tmp"/cluster/logs/*.log; exit 1; }
/usr/bin/python3 - "$tmp/serial/sweep.json" "$tmp/cluster/merged/sweep.json" <<'PY'
import json, sys
def load(p):
    d = json.load(open(p))
    for x in d["points"]:
        x.pop("speed", None)
    return d
a, b = load(sys.argv[1]), load(sys.argv[2])
assert len(a["points"]) == 5, len(a["points"])
assert a == b, "merged cluster result differs from the serial run"
PY
cmp "$tmp/serial/points.csv" "$tmp/cluster/merged/points.csv"
n=$(ls -d "$tmp"/cluster/shard* | wc -l)
[[ $n == 4 ]] || { echo "FAIL: $n shard folders, expected 4"; exit 1; }
echo "PASS: 4-task Slurm array + merge == serial"
