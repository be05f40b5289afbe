#!/usr/bin/env bash
# Issue 41's table, by hand (minutes per case; not a test): the shipped gait (S1, closed loop) run
# DURATION s on a plant holding one hidden effect, then `diagnose --fit motion` and `--fit torque`
# with the rigid subject model (examples/S1.yaml); one line per case: what each fit names.
#   scripts/motion_fit_table.sh [EXOTWIN] [DURATION] [SEEDS]   (defaults: build/app/exotwin, 60, 1)
# SEEDS > 1 repeats every case with seeds 1..SEEDS (the scenario's noise and subject draws).
# env CASES: an extended regex on the case labels (e.g. CASES=none for the clean sweep over seeds).
# env OFFSET: seconds cut from the start of each record before both fits (default 0): the windows then
# restart at other phases of the gait (the gait's stride is 2 s, the windows 0.5 s).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
exe="${1:-$root/build/app/exotwin}"
duration="${2:-60}"
seeds="${3:-1}"
work="$(mktemp -d "${TMPDIR:-/tmp}/motion_fit_table.XXXXXX")"
trap 'rm -rf "$work"' EXIT

cases=(
  "none|"
  "knee backlash 0.005|{name: backlash, joint: knee, value: 0.005}"
  "knee backlash 0.01|{name: backlash, joint: knee, value: 0.01}"
  "knee backlash 0.02|{name: backlash, joint: knee, value: 0.02}"
  "knee backlash 0.03|{name: backlash, joint: knee, value: 0.03}"
  "hip backlash 0.005|{name: backlash, joint: hip, value: 0.005}"
  "hip backlash 0.01|{name: backlash, joint: hip, value: 0.01}"
  "hip backlash 0.02|{name: backlash, joint: hip, value: 0.02}"
  "hip backlash 0.03|{name: backlash, joint: hip, value: 0.03}"
  "knee strap 300|{name: series_compliance, joint: knee, value: 300}"
  "knee strap 600|{name: series_compliance, joint: knee, value: 600}"
  "knee strap 1100|{name: series_compliance, joint: knee, value: 1100}"
  "knee strap 1500|{name: series_compliance, joint: knee, value: 1500}"
  "knee sensor_delay 0.003|{name: sensor_delay, joint: knee, value: 0.003}"
  "knee backlash 0.02 + knee coulomb 2|{name: backlash, joint: knee, value: 0.02}, {name: coulomb_friction, joint: knee, value: 2.0}"
  "hip backlash 0.02 + knee coulomb 2|{name: backlash, joint: hip, value: 0.02}, {name: coulomb_friction, joint: knee, value: 2.0}"
)
named() {  # the effects of a diagnosis.json, one line
  python3 -c 'import json,sys
d=json.load(open(sys.argv[1]))
print("; ".join("%s %s %.4g" % (e["name"], e["joint"], e["value"]) for e in d["effects"]) or "nothing")' "$1"
}
printf '| hidden in the plant | seed | --fit motion | --fit torque | motion fit s |\n| --- | --- | --- | --- | --- |\n'
for c in "${cases[@]}"; do
  label="${c%%|*}"
  effects="${c#*|}"
  [[ "$label" =~ ${CASES:-.} ]] || continue
  for seed in $(seq 1 "$seeds"); do
    dir="$work/case"
    rm -rf "$dir"
    mkdir -p "$dir"
    sed "s/duration: 60/duration: $duration/" "$root/scenarios/gait_2kmh.yaml" > "$dir/s.yaml"
    [ -n "$effects" ] && echo "plant: {effects: [$effects]}" >> "$dir/s.yaml"
    "$exe" run "$dir/s.yaml" --seed "$seed" --out "$dir/run" > /dev/null 2>&1 || true
    if [ -n "${OFFSET:-}" ]; then  # comments and header kept; data rows with t < first + OFFSET dropped
      awk -F, -v off="$OFFSET" '/^#/ || !h { print; if (!/^#/) h = 1; next }
        { if (t0 == "") t0 = $1; if ($1 - t0 >= off - 1e-9) print }' "$dir/run/measured.csv" > "$dir/run/cut.csv"
      mv "$dir/run/cut.csv" "$dir/run/measured.csv"
    fi
    t0=$(date +%s.%N)
    "$exe" diagnose --params "$root/examples/S1.yaml" --measured "$dir/run/measured.csv" --fit motion \
      --out "$dir/motion" > /dev/null
    t1=$(date +%s.%N)
    "$exe" diagnose --params "$root/examples/S1.yaml" --measured "$dir/run/measured.csv" --out "$dir/torque" > /dev/null
    printf '| %s | %s | %s | %s | %.1f |\n' "$label" "$seed" "$(named "$dir/motion/diagnosis.json")" \
      "$(named "$dir/torque/diagnosis.json")" "$(echo "$t1 - $t0" | bc)"
  done
done
