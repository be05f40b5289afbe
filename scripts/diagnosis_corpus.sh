#!/usr/bin/env bash
# The frozen corpus of diagnoses (issue 62: a refactor keeps every named effect and value): `diagnose`
# under both fits on generated records (each effect family hidden alone, pairs, clean), the development
# rig's records (examples/real_rig, and ../shared/data/real_rig where present) and closed-loop gait runs
# with and without plant effects. Not a test (minutes of CPU); a developer's check around a refactor.
#   scripts/diagnosis_corpus.sh EXOTWIN freeze DIR   # write DIR/<case>/diagnosis.json
#   scripts/diagnosis_corpus.sh EXOTWIN check DIR    # run again into a temporary folder, compare with DIR
# The comparison (scripts/diagnosis_corpus_diff.py): the same effects (name, joint, axis) in the same
# order, every number within 1e-6 relative (1e-12 absolute).
set -euo pipefail
[ $# -eq 3 ] || { echo "usage: $0 EXOTWIN freeze|check DIR" >&2; exit 2; }
exe="$(realpath "$1")" mode="$2" dir="$3"
src="$(cd "$(dirname "$0")/.." && pwd)"
case "$mode" in freeze) out="$dir" ;; check) out="$(mktemp -d "${TMPDIR:-/tmp}/corpus.XXXXXX")" ;;
  *) echo "mode must be freeze or check" >&2; exit 2 ;; esac
mkdir -p "$out/records"
S1="$src/examples/S1.yaml"
jobs=()  # "case|params|fit|map|record..."
# Generated records: each family hidden alone (one seed), two pairs, two clean.
for name in coulomb_friction viscous_friction inertia_error gravity_error joint_stiffness backlash \
            series_compliance torque_ripple sensor_offset sensor_gain sensor_delay muscle_activity; do
  r="$out/records/gen_$name.csv"
  "$exe" generate --params "$S1" --seed 7 --effect "$name" --duration 30 --rate 500 --out "$r" >/dev/null
  jobs+=("gen_$name|$S1|torque||$r")
done
for s in 11 12; do
  r="$out/records/gen_pair_$s.csv"
  "$exe" generate --params "$S1" --seed $s --effects 2 --duration 30 --rate 500 --out "$r" >/dev/null
  jobs+=("gen_pair_$s|$S1|torque||$r")
done
for s in 21 22; do
  r="$out/records/gen_clean_$s.csv"
  "$exe" generate --params "$S1" --seed $s --clean --duration 30 --rate 500 --out "$r" >/dev/null
  jobs+=("gen_clean_$s|$S1|torque||$r")
done
# Closed-loop gait runs (15 s of the shipped scenario), with and without plant effects.
gait() {  # name, effects (YAML flow list or empty)
  local d="$out/records/$1"; mkdir -p "$d"
  sed -e 's/duration: 60/duration: 15/' "$src/scenarios/gait_2kmh.yaml" > "$d/s.yaml"
  [ -n "$2" ] && echo "plant: {effects: $2}" >> "$d/s.yaml"
  "$exe" run "$d/s.yaml" --out "$d/run" >/dev/null 2>&1 || [ $? -eq 1 ]
  echo "$d/run/measured.csv"
}
r=$(gait gait_rigid ""); jobs+=("gait_rigid_torque|$S1|torque||$r" "gait_rigid_motion|$S1|motion||$r")
r=$(gait gait_backlash "[{name: backlash, joint: knee, value: 0.02}]")
jobs+=("gait_backlash_torque|$S1|torque||$r" "gait_backlash_motion|$S1|motion||$r")
r=$(gait gait_backlash_coulomb "[{name: backlash, joint: knee, value: 0.015}, {name: coulomb_friction, joint: knee, value: 1.5}]")
jobs+=("gait_backlash_coulomb_torque|$S1|torque||$r" "gait_backlash_coulomb_motion|$S1|motion||$r")
r=$(gait gait_strap "[{name: series_compliance, joint: knee, value: 600}]")
jobs+=("gait_strap_torque|$S1|torque||$r" "gait_strap_motion|$S1|motion||$r")
# The development rig: the shipped records, and the seven records where the shared data is present.
rig="$src/examples/real_rig"
jobs+=("rig_shipped_torque|$rig/model.yaml|torque|$rig/dfki_double_pendulum_A0.map.yaml|$rig/trajectory_05.csv|$rig/trajectory_11.csv"
       "rig_shipped_motion|$rig/model.yaml|motion|$rig/dfki_double_pendulum_A0.map.yaml|$rig/trajectory_05.csv|$rig/trajectory_11.csv")
A0="$src/../shared/data/real_rig/dfki_double_pendulum_A0"
if [ -d "$A0" ]; then
  all=$(ls "$A0"/trajectory_*.csv | tr '\n' '|'); all=${all%|}
  jobs+=("rig_A0_torque|$rig/model.yaml|torque|$rig/dfki_double_pendulum_A0.map.yaml|$all"
         "rig_A0_motion|$rig/model.yaml|motion|$rig/dfki_double_pendulum_A0.map.yaml|$all")
fi
for j in "${jobs[@]}"; do
  IFS='|' read -r -a f <<< "$j"
  name="${f[0]}" params="${f[1]}" fit="${f[2]}" map="${f[3]}"
  args=(); for r in "${f[@]:4}"; do args+=(--measured "$r"); done
  [ -n "$map" ] && args+=(--map "$map")
  "$exe" diagnose --params "$params" "${args[@]}" --fit "$fit" --out "$out/$name" > "$out/$name.log" 2>&1 ||
    [ $? -eq 1 ] || { echo "corpus: $name failed:" >&2; cat "$out/$name.log" >&2; exit 1; }
  echo "corpus: $name" >&2
done
if [ "$mode" = check ]; then
  python3 "$src/scripts/diagnosis_corpus_diff.py" "$dir" "$out"
fi
