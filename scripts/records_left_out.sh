#!/usr/bin/env bash
# Each record left out in turn, as a user checks a twin on records it never saw (not a test): `diagnose`
# on the other records, then `replay` of the record left out with that extended.yaml (0.5 s restarts);
# one line per record (the RMS simulated-angle error per joint and the effects named), then the pooled
# error over every record's samples.
#   scripts/records_left_out.sh EXOTWIN FIT MODEL.yaml MAP.yaml RECORD.csv RECORD.csv [RECORD.csv ...]
# e.g. issue 41's real-rig check (FIT motion, then torque):
#   D=../shared/data/real_rig/dfki_double_pendulum_A0
#   scripts/records_left_out.sh build/app/exotwin motion examples/real_rig/model.yaml \
#     examples/real_rig/dfki_double_pendulum_A0.map.yaml $D/trajectory_*.csv
set -euo pipefail
[ $# -ge 6 ] || { echo "usage: $0 EXOTWIN FIT MODEL.yaml MAP.yaml RECORD.csv RECORD.csv [...]" >&2; exit 2; }
exe="$1" fit="$2" model="$3" map="$4"
shift 4
records=("$@")
work="$(mktemp -d "${TMPDIR:-/tmp}/records_left_out.XXXXXX")"
trap 'rm -rf "$work"' EXIT
for i in "${!records[@]}"; do
  args=()
  for k in "${!records[@]}"; do [ "$k" != "$i" ] && args+=(--measured "${records[$k]}"); done
  log="$work/$i.log"  # the maps' notes; shown when a step fails
  "$exe" diagnose --params "$model" --map "$map" "${args[@]}" --fit "$fit" --out "$work/$i/diag" > "$log" 2>&1 ||
    { cat "$log" >&2; exit 1; }
  "$exe" replay --params "$work/$i/diag/extended.yaml" --map "$map" --measured "${records[$i]}" \
    --out "$work/$i/replay" >> "$log" 2>&1 || { cat "$log" >&2; exit 1; }
done
python3 - "$work" "${records[@]}" <<'PY'
import json, math, sys
work, records = sys.argv[1], sys.argv[2:]
sse, n = {"hip": 0.0, "knee": 0.0}, 0
print("| record left out | hip deg | knee deg | named on the others |\n| --- | --- | --- | --- |")
for i, rec in enumerate(records):
    r = json.load(open(f"{work}/{i}/replay/replay.json"))["records"][0]
    d = json.load(open(f"{work}/{i}/diag/diagnosis.json"))
    named = "; ".join("%s %s %.4g" % (e["name"], e["joint"], e["value"]) for e in d["effects"]) or "nothing"
    rmse = {j: r["joints"][j]["rmse_rad"] for j in ("hip", "knee") if j in r["joints"]}
    print("| %s | %s | %s | %s |" % (rec.split("/")[-1], *("%.2f" % math.degrees(rmse[j]) if j in rmse else "-" for j in ("hip", "knee")), named))
    for j, v in rmse.items():
        sse[j] += v * v * r["samples"]
    n += r["samples"]
print("| pooled | %.2f | %.2f | |" % tuple(math.degrees(math.sqrt(sse[j] / n)) for j in ("hip", "knee")))
PY
