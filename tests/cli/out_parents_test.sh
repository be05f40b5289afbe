#!/usr/bin/env bash
# Every --out / -o path is created with its missing parent folders (DESIGN.md "Command line", issue
# 41 item 6), for every command that writes one: each command below writes under a folder that does
# not exist yet, two levels deep, and must exit 0 (1 for a scenario whose checks fail) with its
# output there. Args: path of exotwin, source dir.
set -uo pipefail
EXO=$1
SRC=$2
T=$(mktemp -d "${TMPDIR:-/tmp}"/exotwin_out_parents_XXXXXX)
trap 'rm -rf "$T"' EXIT
fail=0
# expect NAME FILE_THAT_MUST_EXIST ARGS...: exit 0 or 1 and FILE there.
expect() {
  local name=$1 file=$2
  shift 2
  local rc=0
  "$EXO" "$@" >"$T/$name.log" 2>&1 || rc=$?
  if [ $rc -gt 1 ] || [ ! -e "$file" ]; then
    echo "FAIL: $name: exit $rc, $file $( [ -e "$file" ] && echo present || echo missing ):"
    tail -5 "$T/$name.log"
    fail=1
  else
    echo "ok: $name (exit $rc)"
  fi
}

# Inputs: a short gait scenario, a short synthetic record and a one-joint one (generate's own output).
sed -e 's/duration: 60/duration: 0.3/' -e 's/ramp: 2.0/ramp: 0.1/' "$SRC/scenarios/gait_2kmh.yaml" > "$T/gait.yaml"
"$EXO" generate --params "$SRC/examples/S1.yaml" --seed 1 --duration 3 --clean --out "$T/in/rec.csv" >/dev/null 2>&1 ||
  { echo "FAIL: generate could not write the input record"; exit 1; }
M="$SRC/examples/S1.yaml"
# Steps 1 and 2 of the identification protocol, 4 s of one trial each, for identify.
for s in step1_exo_knee step2_exo_hip; do
  sed -E -e 's/duration: *[0-9.]+/duration: 4/' -e 's/trials: 5/trials: 1/' "$SRC/scenarios/identification/$s.yaml" > "$T/$s.yaml"
  "$EXO" run "$T/$s.yaml" --out "$T/in/$s" >/dev/null 2>&1 || { echo "FAIL: could not record $s"; exit 1; }
done

expect generate  "$T/g/a/rec.csv"         generate --params "$M" --seed 2 --duration 3 --clean --out "$T/g/a/rec.csv"
expect run       "$T/r/a/result.json"     run "$T/gait.yaml" --out "$T/r/a"
expect run_can   "$T/rc/a/can.log"        run "$T/gait.yaml" --out "$T/rc/o" --can-log "$T/rc/a/can.log"
expect predict   "$T/p/a/pred.csv"        predict --params "$M" --measured "$T/in/rec.csv" --out "$T/p/a/pred.csv"
expect convert   "$T/c/a/data.csv"        convert --map "$SRC/examples/real_rig/dfki_double_pendulum_A0.map.yaml" \
                                          "$SRC/examples/real_rig/trajectory_05.csv" --out "$T/c/a/data.csv"
expect identify  "$T/i/a/model.yaml"      identify --measured "$T/in/step1_exo_knee/measured.csv" \
                                          --measured "$T/in/step2_exo_hip/measured.csv" --out "$T/i/a/model.yaml"
expect replay    "$T/rp/a/replay.json"    replay --params "$M" --measured "$T/in/rec.csv" --horizon 0.5 --out "$T/rp/a"
expect diagnose  "$T/d/a/diagnosis.json"  diagnose --params "$M" --measured "$T/in/rec.csv" --out "$T/d/a"
expect sweep     "$T/s/a/sweep.csv"       sweep --scenario "$T/gait.yaml" --subjects 1 --jobs 1 --out "$T/s/a"
expect merge     "$T/mg/a/sweep.csv"      merge "$T/s/a" --out "$T/mg/a"
if [ -n "${EXOTWIN_RENDER_PLUGIN:-}" ] || [ -e "$(dirname "$EXO")/libexotwin_render_plugin.so" ]; then
  expect render  "$T/v/a/run.mp4"         render "$T/gait.yaml" -o "$T/v/a/run.mp4" --out "$T/v/logs/x"
fi
exit $fail
