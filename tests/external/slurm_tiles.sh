#!/usr/bin/env bash
# The Slurm example (examples/slurm) on a single-node cluster this test starts and stops itself:
# munged, slurmctld and slurmd from Debian's munge and slurm-wlm, with their own key, sockets,
# ports and state in a scratch folder (nothing system-wide is touched). Runs 5 tiles as an array
# job and the merge as a dependent job, and checks the merged file equals one process's.
#   slurm_tiles.sh DPOINT EXAMPLES_DIR
# Exit 77 (CTest: skipped) when Slurm or munge is not installed or not run as root (slurmd starts
# job steps as the submitting user, which needs root).
set -euo pipefail
dpoint=$1
examples=$2
for tool in munged slurmctld slurmd sbatch squeue sinfo; do
  command -v "$tool" >/dev/null || { echo "skipped: $tool not installed (scripts/setup installs slurm-wlm, munge)"; exit 77; }
done
[ "$(id -u)" = 0 ] || { echo "skipped: slurmd needs root to start job steps"; exit 77; }

work=$(mktemp -d)
cleanup() {
  for f in slurmd slurmctld munged; do [ -s "$work/$f.pid" ] && kill "$(cat "$work/$f.pid")" 2>/dev/null || true; done
  sleep 0.5
  rm -rf "$work"
}
trap cleanup EXIT
cd "$work"
mkdir state spool parts
dd if=/dev/urandom of=munge.key bs=1024 count=1 status=none
chmod 400 munge.key
# Ports of our own, away from a system Slurm's 6817/6818 and from another run of this test.
port=$((20000 + ($$ % 10000) * 2))
started=$(date +%s.%N)
munged --socket="$work/munge.socket" --key-file="$work/munge.key" --pid-file="$work/munged.pid" \
  --log-file="$work/munged.log" --seed-file="$work/munge.seed" --force
host=$(hostname)
cat >slurm.conf <<CONF
ClusterName=dpointtest
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$work/munge.socket
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
ReturnToService=2
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$work/slurm.conf
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 1 60); do
  sinfo -h -o %T 2>/dev/null | grep -q idle && break
  sleep 1
done
sinfo -h -o %T | grep -q idle || { echo "the cluster did not come up within a minute"; tail -20 slurmctld.log slurmd.log; exit 1; }
echo "cluster up after $(awk -v a="$started" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }') s"

export DPOINT=$dpoint PARTS=$work/parts OUTPUT=$work/merged.ply
# TILES, GPUS and KIND_ARGS may be given (bench/scripts/gpu_slurm.sh: one tile per GPU of a host).
export KIND_ARGS=${KIND_ARGS:-"mandelbulb --resolution 41 --variant fast"}
tiles=${TILES:-5}
# Each tile's escape counts on Vulkan device (task mod GPUS): with 1, device 0 (lavapipe here).
export DEVICE=task GPUS=${GPUS:-1}
merge_job=$("$examples/submit.sh" "$tiles" -D "$work")
for _ in $(seq 1 120); do
  [ -z "$(squeue -h 2>/dev/null)" ] && break
  sleep 1
done
[ -z "$(squeue -h)" ] || { echo "jobs still queued after two minutes"; squeue; exit 1; }
"$dpoint" generate $KIND_ARGS -q -o "$work/whole.ply"
if ! cmp "$work/whole.ply" "$work/merged.ply"; then
  echo "merge job $merge_job: the merged file differs from one process's"
  cat "$work"/dpoint-*.log
  exit 1
fi
echo "$tiles tiles through Slurm (merge job $merge_job, done $(awk -v a="$started" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }') s after the cluster started): merged file equals the single process's"
