#!/usr/bin/env bash
# A sweep split into shards run by GNU parallel (as on a cluster, docs/sweeps.md) and merged gives
# byte for byte the aggregate of the unsharded sweep. Args: path of exotwin, source dir.
set -euo pipefail
EXO=$1
SRC=$2
command -v parallel >/dev/null || { echo "FAIL: GNU parallel is not installed (scripts/setup.sh installs it)"; exit 1; }
T=$(mktemp -d "${TMPDIR:-/tmp}"/exotwin_sweep_parallel_XXXXXX)
trap 'rm -rf "$T"' EXIT

# The shipped gait scenario, 2 s instead of 60.
sed -e 's/duration: 60/duration: 2/' -e 's/ramp: 2.0/ramp: 0.5/' "$SRC/scenarios/gait_2kmh.yaml" > "$T/gait.yaml"
grep -q 'duration: 2,' "$T/gait.yaml" || { echo "FAIL: could not shorten the scenario"; exit 1; }
SUBJECTS=7
SHARDS=3

rc=0
"$EXO" sweep --scenario "$T/gait.yaml" --subjects $SUBJECTS --seed 11 --jobs 2 --out "$T/whole" >"$T/whole.log" 2>&1 || rc=$?
[ $rc -le 1 ] || { echo "FAIL: unsharded sweep exit $rc"; cat "$T/whole.log"; exit 1; }

# One job per shard; exit 1 (a check failed on some subject) still leaves a complete part.
parallel --will-cite --halt never -j 2 \
  "$EXO" sweep --scenario "$T/gait.yaml" --subjects $SUBJECTS --seed 11 --jobs 1 --shard {}/$SHARDS \
  --out "$T/part{}" '>' "$T/log{}" '2>&1' ::: $(seq 0 $((SHARDS - 1))) || true
for k in $(seq 0 $((SHARDS - 1))); do
  [ -f "$T/part$k/sweep.csv" ] || { echo "FAIL: shard $k wrote no sweep.csv"; cat "$T/log$k"; exit 1; }
done

"$EXO" merge "$T"/part[0-9]* --out "$T/merged" >/dev/null
for f in sweep.csv summary.json sweep.json plots/gait_2kmh.svg; do
  cmp "$T/whole/$f" "$T/merged/$f" || { echo "FAIL: $f differs between unsharded and merged"; exit 1; }
done
rows=$(($(wc -l < "$T/merged/sweep.csv") - 1))
[ "$rows" -eq $SUBJECTS ] || { echo "FAIL: $rows rows, expected $SUBJECTS"; exit 1; }
echo "ok: $SHARDS shards via GNU parallel merged == unsharded ($rows rows)"
