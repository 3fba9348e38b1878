#!/usr/bin/env bash
# rm3d sweep --slurm for real: installs Debian's slurm-wlm and munge if missing, starts a one-node
# Slurm cluster on this machine (munged, slurmctld, slurmd on localhost, in a scratch folder, on
# ports of its own), runs a 20-run sweep through sbatch (a job array of 10 tasks, 2 runs each),
# waits for it, and compares every run's outcome with the same sweep run locally.
# Needs root and apt-get (or Slurm and munge already installed); otherwise it exits 77, which
# ctest reports as skipped. Usage: slurm_sweep.sh RM3D SRC OUTDIR
set -u
RM3D=$(readlink -f "$1") SRC=$(readlink -f "$2") OUT=$3
skip() { echo "SKIP: $*"; exit 77; }
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null || ! command -v sbatch >/dev/null; then
  [ "$(id -u)" -eq 0 ] || skip "Slurm and munge are not installed and installing them needs root"
  command -v apt-get >/dev/null || skip "Slurm and munge are not installed and there is no apt-get"
  echo "installing slurm-wlm and munge"
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null 2>&1 ||
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge >/dev/null; } ||
    skip "apt-get could not install slurm-wlm and munge"
fi
[ "$(id -u)" -eq 0 ] || skip "starting slurmctld, slurmd and munged for a one-node cluster needs root"

rm -rf "$OUT" && mkdir -p "$OUT"
OUT=$(cd "$OUT" && pwd)
cluster=$OUT/cluster
mkdir -p "$cluster/state" "$cluster/spool" "$cluster/munge"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done
  for f in "$cluster/slurmctld.pid" "$cluster/slurmd.pid"; do [ -f "$f" ] && kill "$(cat "$f")" 2>/dev/null; done
  [ -f "$cluster/munge/munged.pid" ] && kill "$(cat "$cluster/munge/munged.pid")" 2>/dev/null
  return 0
}
trap cleanup EXIT

# munge: its own key, socket and pid file in the scratch folder (a system munged is left alone).
dd if=/dev/urandom of="$cluster/munge/munge.key" bs=1024 count=1 status=none
chmod 700 "$cluster/munge" && chmod 400 "$cluster/munge/munge.key"
socket=$cluster/munge/munge.socket
munged --force --key-file="$cluster/munge/munge.key" --socket="$socket" --pid-file="$cluster/munge/munged.pid" \
  --log-file="$cluster/munge/munged.log" --seed-file="$cluster/munge/munge.seed" || { cat "$cluster/munge/munged.log"; exit 1; }

host=$(hostname -s)
cpus=$(nproc)
cat >"$cluster/slurm.conf" <<CONF
ClusterName=rm3dtest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=16917
SlurmdPort=16918
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
StateSaveLocation=$cluster/state
SlurmdSpoolDir=$cluster/spool
SlurmctldPidFile=$cluster/slurmctld.pid
SlurmdPidFile=$cluster/slurmd.pid
SlurmctldLogFile=$cluster/slurmctld.log
SlurmdLogFile=$cluster/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
ReturnToService=2
SlurmdTimeout=30
InactiveLimit=0
KillWait=5
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=rm3d Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF=$cluster/slurm.conf
slurmctld -f "$SLURM_CONF" -i || { tail -20 "$cluster/slurmctld.log"; exit 1; }
slurmd -f "$SLURM_CONF" -N "$host" || { tail -20 "$cluster/slurmd.log"; exit 1; }
for _ in $(seq 60); do
  state=$(sinfo -h -N -o %T 2>/dev/null | head -1)
  [ "$state" = idle ] && break
  sleep 1
done
if [ "$state" != idle ]; then
  echo "FAIL: the one-node cluster did not come up (node state '$state')"
  tail -20 "$cluster/slurmctld.log" "$cluster/slurmd.log"
  exit 1
fi
echo "one-node cluster up: $host, $cpus CPUs, partition rm3d"

world=$SRC/tests/cli/sweep/world.lua
sweep=(sweep "$world" --param amp=0.2,0.5,0.8,1.1 --seeds 1-5)
cd "$OUT"
"$RM3D" "${sweep[@]}" --out "$OUT/slurm.jsonl" --slurm --wait --runs-per-task 2 || {
  echo "FAIL: rm3d sweep --slurm --wait"
  tail -20 "$cluster/slurmctld.log"
  cat "$OUT"/slurm.jsonl.slurm-logs/* 2>/dev/null | tail -20
  exit 1
}
grep -q '^#SBATCH --array=0-9$' "$OUT/slurm.jsonl.slurm.sh" || { echo "FAIL: expected an array of 10 tasks"; exit 1; }
"$RM3D" "${sweep[@]}" --out "$OUT/local.jsonl" --jobs 2 2>/dev/null || { echo "FAIL: the local sweep"; exit 1; }
cmake -DA="$OUT/slurm.jsonl" -DB="$OUT/local.jsonl" -DRUNS=20 -P "$SRC/tests/cli/compare_sweeps.cmake"
