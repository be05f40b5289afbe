#!/usr/bin/env bash
# A bad scenario is refused before the plant starts (issue 43, DESIGN.md "Valid text, checked where it
# is read"): `run`, `render`, `serve`, `sweep` and `regress` each given a scenario with a byte that is
# not UTF-8 in a check's name, and one whose check names a metric no run reports, must exit 2 with a
# message naming the file, and leave no run's output behind (no measured.csv, no result.json; for
# `sweep` and `regress` a good scenario beside the bad one must not have run either). The scenarios
# last 600 s: a command that ran one would take minutes, and `serve` would wait for its controller
# (bounded by `timeout`, a hang fails). Args: path of exotwin, source dir.
set -uo pipefail
EXO=$1
SRC=$2
T=$(mktemp -d "${TMPDIR:-/tmp}"/exotwin_bad_scenario_XXXXXX)
trap 'rm -rf "$T"' EXIT
fail=0
long() { sed -e 's/duration: 60/duration: 600/' "$SRC/scenarios/gait_2kmh.yaml"; }
mkdir -p "$T/bytes" "$T/metric" "$T/good"
long | sed -e 's/name: hip tracking RMS (deg)/name: hip tracking \xC1 RMS/' > "$T/bytes/bad.yaml"
long | sed -e 's/metric: tracking_rms_hip_deg/metric: tracking_rms_hip_degrees/' > "$T/metric/bad.yaml"
sed -e 's/duration: 60/duration: 0.2/' -e 's/ramp: 2.0/ramp: 0.1/' -e 's/^name: gait_2kmh/name: good_one/' \
  "$SRC/scenarios/gait_2kmh.yaml" > "$T/good/good.yaml"
grep -q $'\xC1' "$T/bytes/bad.yaml" && grep -q tracking_rms_hip_degrees "$T/metric/bad.yaml" ||
  { echo "FAIL: the bad scenarios were not made"; exit 1; }

# expect2 NAME OUTDIR ARGS...: exit 2, bad.yaml named on stderr, nothing a run writes under OUTDIR.
expect2() {
  local name=$1 out=$2
  shift 2
  local rc=0
  timeout 60 "$EXO" "$@" >"$T/$name.out" 2>"$T/$name.err" || rc=$?
  local left
  left=$(find "$out" \( -name measured.csv -o -name result.json -o -name 'sweep.csv' -o -name '*.mp4' \) 2>/dev/null | head -3)
  if [ $rc -ne 2 ] || ! grep -q "bad.yaml" "$T/$name.err" || [ -n "$left" ]; then
    echo "FAIL: $name: exit $rc (expected 2), left: ${left:-nothing}; stderr:"
    head -5 "$T/$name.err"
    fail=1
  else
    echo "ok: $name: $(head -1 "$T/$name.err")"
  fi
}

for kind in bytes metric; do
  B="$T/$kind/bad.yaml"
  cp "$T/good/good.yaml" "$T/$kind/"
  expect2 "run_$kind"     "$T/o/run_$kind"     run "$B" --out "$T/o/run_$kind"
  expect2 "render_$kind"  "$T/o/render_$kind"  render "$B" -o "$T/o/render_$kind/v.mp4" --out "$T/o/render_$kind"
  expect2 "serve_$kind"   "$T/o/serve_$kind"   serve "$B" --bus "unix:$T/bus_$kind" --out "$T/o/serve_$kind"
  expect2 "sweep_$kind"   "$T/o/sweep_$kind"   sweep --scenario "$T/$kind/good.yaml" --scenario "$B" --subjects 2 \
                                               --jobs 1 --out "$T/o/sweep_$kind"
  expect2 "regress_$kind" "$T/o/regress_$kind" regress --suite "$T/$kind" --jobs 1 --out "$T/o/regress_$kind"
done
exit $fail
