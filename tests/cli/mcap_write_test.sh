#!/usr/bin/env bash
# `run SCENARIO --mcap FILE` writes the run as a ROS 2 bag (DESIGN.md "ROS 2 bags (MCAP) in and out"),
# read back by an independent client, Foxglove's MCAP and ROS 2 libraries (tests/mcap_client/
# read_bag.mjs: indexed and streaming readers, every CRC, every message decoded from the file's own
# schema text), then checked against the run's CSV logs (check_bag.py: counts = rows, values = the
# CSV's, stamps = the run's clock, metadata = scenario and seed). Cases: an EXOwheel gait of two trials
# long enough for several chunks, a HAL-3 run, render's run and serve with exotwin-controller (when
# built), a run interrupted by SIGINT (the bag holds what was logged), and bad --mcap paths (exit 2).
# Skipped (exit 77) without node or tests/mcap_client's node_modules (scripts/setup.sh installs them).
# Args: path of exotwin, source dir.
set -uo pipefail
EXO=$1
SRC=$2
CLIENT="$SRC/tests/mcap_client"
command -v node >/dev/null || { echo "SKIP: node is not installed (Debian: nodejs, npm; then npm ci in tests/mcap_client)"; exit 77; }
[ -d "$CLIENT/node_modules/@mcap/core" ] ||
  { echo "SKIP: $CLIENT/node_modules missing (run npm ci there; scripts/setup.sh does)"; exit 77; }
T=$(mktemp -d "${TMPDIR:-/tmp}"/exotwin_mcap_bag_XXXXXX)
trap 'rm -rf "$T"' EXIT
fail=0

# roundtrip NAME SCENARIO_NAME SEED TRIALS COMMAND ARGS...: COMMAND (run, render) with --mcap, read the
# bag, check it against the CSVs.
roundtrip() {
  local name=$1 scenario=$2 seed=$3 trials=$4
  shift 4
  local rc=0
  "$EXO" "$@" --out "$T/$name" --mcap "$T/$name.mcap" >"$T/$name.log" 2>&1 || rc=$?
  if [ $rc -gt 1 ]; then
    echo "FAIL: $name: exit $rc"; tail -5 "$T/$name.log"; fail=1; return
  fi
  if ! node "$CLIENT/read_bag.mjs" "$T/$name.mcap" >"$T/$name.json" 2>"$T/$name.err"; then
    echo "FAIL: $name: the client could not read the bag: $(cat "$T/$name.err")"; fail=1; return
  fi
  if python3 "$CLIENT/check_bag.py" "$T/$name.json" "$scenario" "$seed" "$T/$name" "$trials" >"$T/$name.check"; then
    echo "ok: $name"; sed 's/^/  /' "$T/$name.check"
  else
    echo "FAIL: $name: $(cat "$T/$name.check")"; fail=1
  fi
}

# EXOwheel gait, 2 trials of 3 s at 1 kHz: 6000 rows of 7 topics, several 1 MB chunks, trial 2's stamps
# 4 s later.
sed -e 's/duration: 60/duration: 3/' -e 's/trials: 1/trials: 2/' -e 's/ramp: 2.0/ramp: 0.1/' \
  "$SRC/scenarios/gait_2kmh.yaml" > "$T/gait.yaml"
roundtrip gait gait_2kmh 5 2 run "$T/gait.yaml" --seed 5
chunks=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['statistics']['chunk_count'])" "$T/gait.json" 2>/dev/null)
if [ "${chunks:-0}" -lt 2 ]; then echo "FAIL: gait: ${chunks:-no} chunks, expected several"; fail=1; fi

# HAL-3 knee (one joint; assist estimates on a topic of their own), 5 s (settling 4 s).
sed -E 's/duration: *[0-9.]+/duration: 5/' "$SRC/scenarios/hal3_exp2_assist.yaml" > "$T/hal.yaml"
roundtrip hal hal3_exp2_assist 1 1 run "$T/hal.yaml"

# render's run (when the renderer is built), 0.3 s.
if [ -n "${EXOTWIN_RENDER_PLUGIN:-}" ] || [ -e "$(dirname "$EXO")/libexotwin_render_plugin.so" ]; then
  sed -e 's/duration: 60/duration: 0.3/' "$SRC/scenarios/gait_2kmh.yaml" > "$T/render.yaml"
  roundtrip render gait_2kmh 1 1 render "$T/render.yaml" -o "$T/render.mp4"
else
  echo "note: render case not run: the render plugin is not built"
fi

# serve + exotwin-controller (lockstep, shared memory): the same bag, the measured velocity NaN (the
# link does not carry the controller's estimate). The controller is looked for in ../deploy/.
CTRL="$(dirname "$EXO")/../deploy/exotwin-controller"
if [ -x "$CTRL" ]; then
  sed -e 's/duration: 60/duration: 2/' "$SRC/scenarios/gait_2kmh.yaml" > "$T/serve.yaml"
  bus="shm:exotwin_mcap_$$"
  "$EXO" serve "$T/serve.yaml" --bus "$bus" --out "$T/serve" --mcap "$T/serve.mcap" >"$T/serve.log" 2>&1 &
  spid=$!
  "$CTRL" --config "$T/serve.yaml" --bus "$bus" >"$T/ctrl.log" 2>&1
  wait $spid
  rc=$?
  if [ $rc -ne 0 ]; then
    echo "FAIL: serve: exit $rc"; tail -3 "$T/serve.log"; fail=1
  elif node "$CLIENT/read_bag.mjs" "$T/serve.mcap" >"$T/serve.json" 2>"$T/serve.err" &&
    python3 "$CLIENT/check_bag.py" "$T/serve.json" gait_2kmh 1 "$T/serve" 1 --velocity-unknown >"$T/serve.check"; then
    echo "ok: serve's bag: $(head -1 "$T/serve.check")"
  else
    echo "FAIL: serve's bag: $(cat "$T/serve.err" "$T/serve.check" 2>/dev/null)"; fail=1
  fi
else
  echo "note: serve case not run: $CTRL not built (cmake --build build --target exotwin-controller)"
fi

# Interrupted by SIGINT mid-run: exit 130, and the bag holds every row the CSVs hold.
sed -e 's/duration: 60/duration: 600/' "$SRC/scenarios/gait_2kmh.yaml" > "$T/long.yaml"
"$EXO" run "$T/long.yaml" --out "$T/int" --mcap "$T/int.mcap" >"$T/int.log" 2>&1 &
pid=$!
for _ in $(seq 1 100); do  # until the run logs rows
  [ -s "$T/int/measured.csv" ] && [ "$(wc -l <"$T/int/measured.csv")" -gt 200 ] && break
  sleep 0.1
done
kill -INT $pid
wait $pid
rc=$?
if [ $rc -ne 130 ]; then
  echo "FAIL: interrupted: exit $rc, expected 130"; fail=1
elif node "$CLIENT/read_bag.mjs" "$T/int.mcap" >"$T/int.json" 2>"$T/int.err" &&
  python3 "$CLIENT/check_bag.py" "$T/int.json" gait_2kmh 1 "$T/int" 1 >"$T/int.check"; then
  echo "ok: interrupted run's bag: $(head -1 "$T/int.check")"
else
  echo "FAIL: interrupted run's bag: $(cat "$T/int.err" "$T/int.check" 2>/dev/null)"; fail=1
fi

# Bad --mcap: exit 2 naming the path, before the run.
expect_2() {
  local name=$1 needle=$2
  shift 2
  local rc=0
  "$EXO" "$@" >"$T/$name.out" 2>&1 || rc=$?
  if [ $rc -eq 2 ] && grep -q -- "$needle" "$T/$name.out"; then
    echo "ok: $name (exit 2: $(tail -1 "$T/$name.out"))"
  else
    echo "FAIL: $name: exit $rc, expected 2 naming $needle:"; tail -3 "$T/$name.out"; fail=1
  fi
}
touch "$T/a_file"
mkdir -p "$T/a_folder"
expect_2 under_a_file "$T/a_file" run "$T/gait.yaml" --out "$T/e1" --mcap "$T/a_file/x.mcap"
expect_2 a_folder "$T/a_folder" run "$T/gait.yaml" --out "$T/e2" --mcap "$T/a_folder"
expect_2 emg_protocol "emg_calibration" run "$SRC/scenarios/exowheel_emg_isometric.yaml" --out "$T/e3" --mcap "$T/e3.mcap"
exit $fail
