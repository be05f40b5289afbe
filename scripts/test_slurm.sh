#!/usr/bin/env bash
# A real one-node Slurm cluster (Debian's slurm-wlm + munge, scripts/setup.sh installs them), configured
# in a temporary folder, started and stopped by this script (no systemd; as root). It submits the job
# array and the dependent merge of docs/sweeps.md, scaled to this machine (4 shards of 8 subjects,
# one CPU per task, the shipped gait scenario shortened to 2 s), waits, and checks:
#   1. every array task completed, the merge job completed, and the merged aggregate (sweep.csv,
#      summary.json, sweep.json, plots/) is byte-identical to an unsharded `exotwin sweep` of the
#      same subjects;
#   2. a failing shard (its task exits 1) is reported by the merge job: it fails, naming the shard.
# Usage: scripts/test_slurm.sh [PATH_TO_EXOTWIN]   (default build/app/exotwin)
# Exit 0 pass (or skipped, with the reason, where the daemons cannot start here), 1 fail.
set -euo pipefail
cd "$(dirname "$0")/.."
SRC=$PWD
EXO=$(realpath "${1:-build/app/exotwin}")
SHARDS=4
PER_SHARD=8
SUBJECTS=$((SHARDS * PER_SHARD))

say() { echo "test_slurm: $*"; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.1f", b - a }'; }
fail() { say "FAIL: $*"; exit 1; }
skip() { say "SKIPPED: $* (the Slurm test did not run)"; exit 0; }

[ -x "$EXO" ] || fail "$EXO is not an executable (build first, or pass the path of exotwin)"
for tool in munged slurmctld slurmd sbatch squeue scontrol sinfo; do
  command -v $tool >/dev/null || PATH=$PATH:/usr/sbin command -v $tool >/dev/null ||
    fail "$tool not found: install slurm-wlm and munge (scripts/setup.sh)"
done
export PATH=$PATH:/usr/sbin
[ "$(id -u)" -eq 0 ] || skip "slurmd and munged need root to run jobs as the submitting user; run as root"

W=$(mktemp -d "${TMPDIR:-/tmp}"/exotwin_slurm_XXXXXX)
W=$(realpath "$W")
chmod 755 "$W"
PIDS=()
cleanup() {
  local p
  for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${PIDS[@]}"; do wait "$p" 2>/dev/null || true; done
  [ -f "$W/munged.pid" ] && kill "$(cat "$W/munged.pid")" 2>/dev/null || true
  sleep 0.2
  rm -rf "$W"
}
trap cleanup EXIT
t_start=$(date +%s)

# --- munge: a fresh key, its own socket ----------------------------------------------------------------
mkdir -m 700 "$W/munge"
dd if=/dev/urandom of="$W/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$W/munge/munge.key"
MUNGE_SOCKET=$W/munge/munge.socket
munged --force --key-file="$W/munge/munge.key" --socket="$MUNGE_SOCKET" --pid-file="$W/munged.pid" \
  --log-file="$W/munge/munged.log" --seed-file="$W/munge/munged.seed" >"$W/munged.out" 2>&1 ||
  skip "munged cannot start here: $(cat "$W/munged.out" "$W/munge/munged.log" 2>/dev/null | tail -3)"

# --- Slurm: controller and one node on free local ports ---------------------------------------------
free_port() {
  local p
  for _ in $(seq 50); do
    p=$((20000 + RANDOM % 20000))
    ! (exec 3<>/dev/tcp/127.0.0.1/$p) 2>/dev/null && { echo $p; return; }
  done
  fail "no free TCP port"
}
CTLD_PORT=$(free_port)
SLURMD_PORT=$(free_port)
[ "$CTLD_PORT" != "$SLURMD_PORT" ] || SLURMD_PORT=$((CTLD_PORT + 1))
HOST=$(hostname -s)
CPUS=$(nproc)
mkdir -p "$W/state" "$W/spool"
export SLURM_CONF=$W/slurm.conf
cat >"$SLURM_CONF" <<EOF
ClusterName=exotwin-test
SlurmctldHost=$HOST(127.0.0.1)
SlurmctldPort=$CTLD_PORT
SlurmdPort=$SLURMD_PORT
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$MUNGE_SOCKET
CredType=cred/munge
StateSaveLocation=$W/state
SlurmdSpoolDir=$W/spool
SlurmctldPidFile=$W/slurmctld.pid
SlurmdPidFile=$W/slurmd.pid
SlurmctldLogFile=$W/slurmctld.log
SlurmdLogFile=$W/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MinJobAge=600
SlurmdTimeout=30
NodeName=$HOST NodeAddr=127.0.0.1 CPUs=$CPUS State=UNKNOWN
PartitionName=exotwin Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
EOF
slurmctld -D -c -f "$SLURM_CONF" >"$W/slurmctld.out" 2>&1 &
PIDS+=($!)
slurmd -D -f "$SLURM_CONF" -N "$HOST" >"$W/slurmd.out" 2>&1 &
PIDS+=($!)
up=0
for _ in $(seq 60); do
  if sinfo -h -N -o '%T' 2>/dev/null | grep -q -E '^idle'; then up=1; break; fi
  for p in "${PIDS[@]}"; do kill -0 "$p" 2>/dev/null || break 2; done
  sleep 0.5
done
if [ $up -ne 1 ]; then
  skip "the Slurm daemons did not bring node $HOST up within 30 s: $(sinfo -h -N 2>&1 | head -2);
$(tail -n 5 "$W"/slurmctld.out "$W"/slurmctld.log "$W"/slurmd.out "$W"/slurmd.log 2>/dev/null)"
fi
say "cluster up in $(($(date +%s) - t_start)) s: $(sinfo -h -o '%P %D nodes %c CPUs/node %T' | head -1) ($(sinfo -V))"

# --- the job folder: the sbatch file of docs/sweeps.md, scaled ---------------------------------------
J=$W/job
mkdir -p "$J/scenarios" "$J/logs" "$J/bin"
sed -e 's/duration: 60/duration: 2/' -e 's/ramp: 2.0/ramp: 0.5/' "$SRC/scenarios/gait_2kmh.yaml" >"$J/scenarios/gait_2kmh.yaml"
grep -q 'duration: 2,' "$J/scenarios/gait_2kmh.yaml" || fail "could not shorten the gait scenario"
ln -s "$EXO" "$J/bin/exotwin"
cat >"$J/sweep.sbatch" <<EOF
#!/bin/bash
# sweep.sbatch: $SHARDS shards of $PER_SHARD subjects, 1 core each.
#SBATCH --job-name=exotwin-sweep
#SBATCH --array=0-$((SHARDS - 1))
#SBATCH --cpus-per-task=1
#SBATCH --time=00:10:00
#SBATCH --output=logs/sweep_%A_%a.out
exotwin sweep --scenario scenarios/gait_2kmh.yaml \\
  --subjects $SUBJECTS --seed 1 --jobs "\$SLURM_CPUS_PER_TASK" \\
  --shard "\${SLURM_ARRAY_TASK_ID}/\${SLURM_ARRAY_TASK_COUNT}" --out "parts/\${SLURM_ARRAY_TASK_ID}"
# exit 1 only means a check failed on some subject: the part is complete
rc=\$?; [ \$rc -le 1 ]
EOF

# job_field ID FIELD: a field of `scontrol show job` (first task of an array).
job_field() { scontrol show job "$1" 2>/dev/null | tr ' ' '\n' | sed -n "s/^$2=//p" | head -1; }
# wait_jobs ID...: until none of the jobs is pending or running (3 min at most).
wait_jobs() {
  local left
  for _ in $(seq 360); do
    left=$(squeue -h -j "$(IFS=,; echo "$*")" 2>/dev/null | wc -l)
    [ "$left" -eq 0 ] && return 0
    sleep 0.5
  done
  squeue
  fail "jobs $* still queued after 3 min"
}
# array_report JOB: "task state exit runtime" per array task, by task.
array_report() {
  scontrol show job "$1" | tr ' ' '\n' |
    awk -F= '/^ArrayTaskId=/{t=$2} /^JobState=/{s=$2} /^RunTime=/{r=$2} /^ExitCode=/{c=$2} /^NodeList=/{print t, s, c, r}' |
    sort -n
}

# submit DIR: the array and the dependent merge, as docs/sweeps.md submits them, from DIR.
submit() {
  (cd "$1" && jid=$(sbatch --parsable sweep.sbatch) &&
     mid=$(sbatch --parsable --job-name=exotwin-merge --output=logs/merge_%j.out \
             --dependency=afterany:"$jid" --wrap 'exotwin merge parts/* --out sweep') &&
     echo "$jid $mid")
}

export PATH=$J/bin:$PATH
t0=$(date +%s.%N)
read -r JID MID < <(submit "$J")
say "submitted array job $JID (tasks 0-$((SHARDS - 1))) and merge job $MID (afterany:$JID)"
wait_jobs "$JID" "$MID"
t1=$(date +%s.%N)
while read -r task state code runtime; do
  say "  array task ${JID}_$task: $state exit $code, run time $runtime"
  [ "$state" = COMPLETED ] || { cat "$J"/logs/sweep_*_"$task".out; fail "array task $task: $state"; }
done < <(array_report "$JID")
[ "$(job_field "$MID" JobState)" = COMPLETED ] || { cat "$J"/logs/merge_*.out; fail "merge job $MID: $(job_field "$MID" JobState) exit $(job_field "$MID" ExitCode)"; }
say "  merge job $MID: COMPLETED exit $(job_field "$MID" ExitCode), run time $(job_field "$MID" RunTime): $(cat "$J"/logs/merge_*.out)"
say "array + merge on Slurm: $(elapsed "$t0" "$t1") s wall"

t2=$(date +%s.%N)
rc=0
(cd "$J" && exotwin sweep --scenario scenarios/gait_2kmh.yaml --subjects $SUBJECTS --seed 1 --jobs "$CPUS" \
   --out whole >"$J/logs/whole.out" 2>&1) || rc=$?
[ $rc -le 1 ] || { cat "$J/logs/whole.out"; fail "unsharded sweep: exit $rc"; }
t3=$(date +%s.%N)
say "unsharded exotwin sweep --jobs $CPUS: $(elapsed "$t2" "$t3") s wall"
for f in sweep.csv summary.json sweep.json plots/gait_2kmh.svg; do
  cmp "$J/whole/$f" "$J/sweep/$f" || fail "$f differs between the unsharded sweep and the Slurm merge"
  say "  $f: identical ($(stat -c %s "$J/sweep/$f") bytes, sha256 $(sha256sum "$J/sweep/$f" | cut -c1-16))"
done
rows=$(($(wc -l <"$J/sweep/sweep.csv") - 1))
[ "$rows" -eq $SUBJECTS ] || fail "$rows rows in the merged sweep.csv, expected $SUBJECTS"
say "merged aggregate == unsharded sweep, byte for byte ($rows subjects)"

# --- a failing shard: the same array where task 2's exotwin fails before writing its part -------------
F=$W/job_fail
FAILED_TASK=2
mkdir -p "$F/logs" "$F/bin"
cp -r "$J/scenarios" "$J/sweep.sbatch" "$F/"
cat >"$F/bin/exotwin" <<EOF
#!/bin/bash
# Stands in for a shard that dies (node lost, out of memory) before writing its part.
if [ "\$1" = sweep ] && [ "\${SLURM_ARRAY_TASK_ID:-}" = $FAILED_TASK ]; then echo "shard $FAILED_TASK: killed" >&2; exit 137; fi
exec "$EXO" "\$@"
EOF
chmod +x "$F/bin/exotwin"
export PATH=$F/bin:$PATH
read -r JID2 MID2 < <(submit "$F")
wait_jobs "$JID2" "$MID2"
while read -r task state code runtime; do
  say "  array task ${JID2}_$task: $state exit $code, run time $runtime"
  if [ "$task" = $FAILED_TASK ]; then
    [ "$state" = FAILED ] && [ "${code%%:*}" = 1 ] || fail "task $task: $state $code, expected FAILED exit 1"
  else
    [ "$state" = COMPLETED ] || fail "task $task: $state, expected COMPLETED"
  fi
done < <(array_report "$JID2")
mstate=$(job_field "$MID2" JobState)
mcode=$(job_field "$MID2" ExitCode)
mlog=$(cat "$F"/logs/merge_*.out)
say "  merge job $MID2: $mstate exit $mcode: $mlog"
[ "$mstate" = FAILED ] || fail "merge job after a failed shard: $mstate, expected FAILED"
grep -q "shard(s) $FAILED_TASK/$SHARDS" <<<"$mlog" || fail "the merge does not name shard $FAILED_TASK/$SHARDS"
[ ! -e "$F/sweep/sweep.csv" ] || fail "the merge wrote an aggregate without shard $FAILED_TASK"
say "a failed shard: its task FAILED exit 1, the merge job FAILED naming shard $FAILED_TASK/$SHARDS, no aggregate"
say "ok ($(($(date +%s) - t_start)) s)"
