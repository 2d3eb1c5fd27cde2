#!/usr/bin/env bash
# Slurm, run for real: starts a single-node Slurm on this machine (Debian's slurmctld +
# slurmd + munge, every file and socket in a private temporary folder), submits the job-array bake
# of docs/bake.md for a generated city as shards, merges them with `pvs merge`, and checks that the
# bytes equal a single-process bake of the same cells. Prints the wall time of both.
#
#   bash scripts/slurm-test.sh            # needs root (munged and slurmd), build/cli/pvs built
#   SLURM_TEST_SHARDS=4 SLURM_TEST_BLOCKS=3,3 SLURM_TEST_GRID=6,1,6 bash scripts/slurm-test.sh
#
# Needs the Debian packages slurmctld, slurmd, slurm-client and munge
# (apt-get install --no-install-recommends slurmctld slurmd slurm-client munge). Exit 0 when the
# merged file is byte-identical, 1 on a mismatch or a failed job, 77 when Slurm is not installed.
# .ci/run runs it with a 300 s budget (see docs/bake.md, "Slurm job array", for its measured time).
set -euo pipefail
cd "$(dirname "$0")/.."
REPO=$(pwd)
PVS=${PVS:-$REPO/build/cli/pvs}
SHARDS=${SLURM_TEST_SHARDS:-4}
BLOCKS=${SLURM_TEST_BLOCKS:-3,3}
GRID=${SLURM_TEST_GRID:-6,1,6}
RES=${SLURM_TEST_RES:-64}
for tool in slurmctld slurmd sbatch sinfo munged; do
  command -v "$tool" > /dev/null || { echo "slurm-test: $tool not found (install slurmctld slurmd slurm-client munge)"; exit 77; }
done
[[ -x $PVS ]] || { echo "slurm-test: $PVS not built"; exit 1; }
[[ $(id -u) == 0 ]] || { echo "slurm-test: needs root (munged and slurmd run here)"; exit 77; }

WORK=$(mktemp -d /tmp/vislib-slurm.XXXXXX)
chmod 755 "$WORK"
HOST=$(hostname -s)
CPUS=$(nproc)
MEM_MB=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 / 2 ))
t_start=$(date +%s.%N)
cleanup() {
  for pid_file in "$WORK/slurmd.pid" "$WORK/slurmctld.pid" "$WORK/munged.pid"; do
    [[ -s $pid_file ]] && kill "$(cat "$pid_file")" 2> /dev/null || true
  done
  sleep 1
  [[ -n ${KEEP_WORK:-} ]] || rm -rf "$WORK"
}
trap cleanup EXIT

# --- munge: a fresh key and a private socket ---------------------------------------------------
mkdir -p "$WORK/munge"
dd if=/dev/urandom of="$WORK/munge/munge.key" bs=1024 count=1 status=none
chmod 700 "$WORK/munge"
chmod 400 "$WORK/munge/munge.key"
munged --force --key-file "$WORK/munge/munge.key" --socket "$WORK/munge/munge.socket" \
  --pid-file "$WORK/munged.pid" --log-file "$WORK/munged.log" --seed-file "$WORK/munge/munge.seed"

# --- slurm.conf: one node with every CPU, one partition, state and spool in $WORK ---------------
mkdir -p "$WORK/state" "$WORK/spool" "$WORK/logs"
cat > "$WORK/slurm.conf" << EOF
ClusterName=vislibtest
SlurmctldHost=$HOST
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$WORK/munge/munge.socket
CredType=cred/munge
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/slurmctld.pid
SlurmdPidFile=$WORK/slurmd.pid
SlurmctldLogFile=$WORK/slurmctld.log
SlurmdLogFile=$WORK/slurmd.log
SlurmctldPort=${SLURM_TEST_PORT:-16817}
SlurmdPort=$(( ${SLURM_TEST_PORT:-16817} + 1 ))
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MpiDefault=none
SwitchType=switch/none
NodeName=$HOST CPUs=$CPUS RealMemory=$MEM_MB State=UNKNOWN
PartitionName=test Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$WORK/slurm.conf
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 60); do
  sinfo -h -o %T 2> /dev/null | grep -qE '^(idle|mixed|allocated)' && break
  sleep 1
done
sinfo -h -o %T | grep -qE '^(idle|mixed|allocated)' || {
  # The daemons of this machine, not vislib: reported as a skip (exit 77), with their logs.
  echo "slurm-test: SKIP: the Slurm node did not come up on this machine"
  tail -20 "$WORK/slurmctld.log" "$WORK/slurmd.log"; exit 77; }
t_up=$(date +%s.%N)

# --- the bake: single process, then the job array of docs/bake.md and the merge -----------------
CITY=$WORK/city.glb
"$PVS" generate city --blocks "$BLOCKS" -o "$CITY" 2> /dev/null
BAKE_ARGS=(bake "$CITY" --box -60,0,-60,60,3,60 --grid "$GRID" --eye-height 1.5,1.8 --res "$RES" --seed 1)
t0=$(date +%s.%N)
"$PVS" "${BAKE_ARGS[@]}" -o "$WORK/single.pvs" 2> "$WORK/logs/single.log"
t1=$(date +%s.%N)

cat > "$WORK/bake.sbatch" << EOF
#!/bin/bash
#SBATCH --job-name=pvs-bake
#SBATCH --array=0-$(( SHARDS - 1 ))
#SBATCH --cpus-per-task=1
#SBATCH --output=$WORK/logs/bake_%A_%a.log
set -euo pipefail
mkdir -p $WORK/shards
"$PVS" ${BAKE_ARGS[*]} --threads "\$SLURM_CPUS_PER_TASK" \\
    --shard "\$SLURM_ARRAY_TASK_ID/\$SLURM_ARRAY_TASK_COUNT" --resume \\
    -o "$WORK/shards/world.\$SLURM_ARRAY_TASK_ID.pvs"
EOF
t2=$(date +%s.%N)
jobid=$(sbatch --parsable --chdir "$WORK" "$WORK/bake.sbatch")
merge_id=$(sbatch --parsable --chdir "$WORK" --dependency=afterok:"$jobid" --output "$WORK/logs/merge.log" \
  --wrap "\"$PVS\" merge $WORK/shards/world.*.pvs -o $WORK/merged.pvs")
# Wait for the merge job (it runs once every array task has succeeded, or never).
for _ in $(seq 1200); do
  state=$(squeue -h -j "$merge_id" -o %T 2> /dev/null || true)
  [[ -z $state ]] && break
  if [[ $state == PENDING ]] && squeue -h -j "$merge_id" -o %r | grep -q DependencyNeverSatisfied; then
    echo "slurm-test: a shard job failed"; cat "$WORK"/logs/bake_*.log; exit 1
  fi
  sleep 0.5
done
t3=$(date +%s.%N)
[[ -f $WORK/merged.pvs ]] || { echo "slurm-test: no merged file"; cat "$WORK"/logs/*.log; exit 1; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }
cells=$(awk -F, '{ print $1 * $2 * $3 }' <<< "$GRID")
echo "slurm-test: $cells cells, $SHARDS shards, N = $RES, $CPUS CPUs: Slurm up in $(elapsed "$t_start" "$t_up") s;" \
  "single-process bake $(elapsed "$t0" "$t1") s; job array + merge $(elapsed "$t2" "$t3") s (submit to merged file)"
if cmp -s "$WORK/single.pvs" "$WORK/merged.pvs"; then
  echo "slurm-test: merged shards are byte-identical to the single-process bake ($(stat -c %s "$WORK/merged.pvs") bytes)"
else
  echo "slurm-test: MISMATCH between merged shards and the single-process bake"
  exit 1
fi
