#!/usr/bin/env bash
# ROS 2 bags through the commands (issue 65, DESIGN.md "ROS 2 bags (MCAP) in and out"): a generated
# record (a hidden knee Coulomb friction) written as a JointState bag by the independent client
# (tests/mcap_client/write_bag.mjs: Foxglove's @mcap/core and ROS 2 serializer, zstd chunks, epoch
# header stamps) and as the CSV of the same data; `diagnose`, `predict` and `convert` given the bag
# and a column map must give exactly what they give from the CSV (diagnosis.json's effects, values and
# gains; the predicted torque; the converted record), `identify`, `replay` and `render-replay` must
# take the bag and its rosbag2 folder. Bad bags and maps exit 2 naming the file and the byte offset or the topic.
# Exit 77 (skipped) without node or tests/mcap_client/node_modules. Args: path of exotwin, source dir.
set -uo pipefail
EXO=$1
SRC=$2
CLIENT="$SRC/tests/mcap_client"
command -v node >/dev/null || { echo "SKIP: node is not installed (scripts/setup.sh)"; exit 77; }
[ -d "$CLIENT/node_modules/@mcap/core" ] || { echo "SKIP: $CLIENT/node_modules missing (npm ci there)"; exit 77; }
T=$(mktemp -d "${TMPDIR:-/tmp}"/exotwin_mcap_bag_XXXXXX)
trap 'rm -rf "$T"' EXIT
fail=0
S1="$SRC/examples/S1.yaml"

run() {  # run NAME ARGS...: exit 0 expected
  local name=$1
  shift
  if ! "$EXO" "$@" >"$T/$name.out" 2>&1; then
    echo "FAIL: $name: exotwin $*"
    tail -5 "$T/$name.out"
    fail=1
  fi
}

"$EXO" generate --params "$S1" --seed 11 --effect coulomb_friction --joint knee --duration 30 --rate 500 \
  --out "$T/gen.csv" >/dev/null 2>&1 || { echo "FAIL: generate"; exit 1; }
(cd "$CLIENT" && node write_bag.mjs from-csv "$T/gen.csv" "$T/rec.mcap" "$T/rec.csv") ||
  { echo "FAIL: the client did not write the bag"; exit 1; }
cat > "$T/map.yaml" <<'EOF'
columns:
  t:        {from: /exo/joint_states.header.stamp}
  q_hip:    {from: "/exo/joint_states.position[hip]"}
  q_knee:   {from: "/exo/joint_states.position[knee]"}
  tau_hip:  {from: "/exo/joint_states.effort[hip]", sign: -1}
  tau_knee: {from: "/exo/joint_states.effort[knee]", sign: -1}
EOF
if head -1 "$T/rec.csv" | grep -q qd_hip; then
  printf '  qd_hip:   {from: "/exo/joint_states.velocity[hip]"}\n  qd_knee:  {from: "/exo/joint_states.velocity[knee]"}\n' >> "$T/map.yaml"
fi
# The CSV holds the columns the bag carries (a JointState), no others.
python3 - "$T/rec.csv" "$T/map.yaml" <<'EOF' || fail=1
import sys
names = open(sys.argv[1]).readline().strip().split(",")
mapped = [l.split(":")[0].strip() for l in open(sys.argv[2]) if l.startswith("  ")]
extra = [n for n in names if n not in mapped]
if extra:
    lines = open(sys.argv[1]).read().splitlines()
    keep = [names.index(n) for n in names if n in mapped]
    with open(sys.argv[1], "w") as f:
        for l in lines:
            v = l.split(",")
            f.write(",".join(v[k] for k in keep) + "\n")
EOF

# diagnose: the same diagnosis from the bag and from the CSV.
run diagnose_csv diagnose --params "$S1" --measured "$T/rec.csv" --out "$T/d_csv"
run diagnose_bag diagnose --params "$S1" --measured "$T/rec.mcap" --map "$T/map.yaml" --out "$T/d_bag"
python3 - "$T/d_csv/diagnosis.json" "$T/d_bag/diagnosis.json" "$T" <<'EOF' || fail=1
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
# The records' names differ (rec.csv, rec.mcap); everything else must be equal, bit for bit.
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items()}
    if isinstance(x, list):
        return [strip(v) for v in x]
    if isinstance(x, str):
        return x.replace("rec.mcap", "REC").replace("rec.csv", "REC").replace(sys.argv[3] + "/map.yaml", "")
    return x
if strip(a) != strip(b):
    for k in a:
        if strip(a.get(k)) != strip(b.get(k)):
            print(f"FAIL: diagnosis.json differs at '{k}':\n  csv: {json.dumps(a.get(k))[:300]}\n  bag: {json.dumps(b.get(k))[:300]}")
    sys.exit(1)
effects = [(e["name"], e["joint"], e["value"]) for e in a["effects"]]
if not any(e[0] == "coulomb_friction" and e[1] == "knee" for e in effects):
    print(f"FAIL: the hidden knee Coulomb friction not found: {effects}")
    sys.exit(1)
print(f"ok: diagnose: the bag's diagnosis equals the CSV's: {effects}")
EOF

# predict and convert: the same numbers.
run predict_csv predict --params "$S1" --measured "$T/rec.csv" --out "$T/p_csv.csv"
run predict_bag predict --params "$S1" --measured "$T/rec.mcap" --map "$T/map.yaml" --out "$T/p_bag.csv"
run convert_bag convert --map "$T/map.yaml" "$T/rec.mcap" --out "$T/conv.csv"
python3 - "$T" <<'EOF' || fail=1
import sys
def table(p):
    rows = [l.strip().split(",") for l in open(p) if l.strip() and not l.startswith("#")]
    return {n: [float(r[k]) for r in rows[1:]] for k, n in enumerate(rows[0])}
T = sys.argv[1]
for a, b in [("p_csv.csv", "p_bag.csv"), ("rec.csv", "conv.csv")]:
    x, y = table(f"{T}/{a}"), table(f"{T}/{b}")
    if x != y:
        bad = [n for n in x if x.get(n) != y.get(n)]
        print(f"FAIL: {b} differs from {a} in {bad or sorted(set(x) ^ set(y))}")
        sys.exit(1)
    print(f"ok: {b} equals {a} ({len(x['t'])} rows, {len(x)} columns)")
EOF
grep -q "map .*rec.mcap" "$T/convert_bag.out" && grep -q "jitter" "$T/convert_bag.out" ||
  { echo "FAIL: convert did not report the map on the bag"; cat "$T/convert_bag.out"; fail=1; }

# A rosbag2 folder (metadata.yaml + the .mcap) and identify / replay on a bag.
mkdir -p "$T/bag2"
cp "$T/rec.mcap" "$T/bag2/rec_0.mcap"
printf 'rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  relative_file_paths: [rec_0.mcap]\n' \
  > "$T/bag2/metadata.yaml"
run convert_folder convert --map "$T/map.yaml" "$T/bag2" --out "$T/conv2.csv"
cmp -s <(grep -v '^#' "$T/conv.csv") <(grep -v '^#' "$T/conv2.csv") ||
  { echo "FAIL: the rosbag2 folder converts to another record than its .mcap"; fail=1; }
run replay_bag replay --params "$S1" --measured "$T/bag2" --map "$T/map.yaml" --horizon 0.5 --out "$T/r_bag"
[ -s "$T/r_bag/replay.csv" ] || { echo "FAIL: replay wrote no replay.csv from the bag"; fail=1; }
run render_bag render-replay --params "$S1" --measured "$T/bag2" --map "$T/map.yaml" --width 64 --height 48 \
  --fps 2 -o "$T/v.mp4"
[ -s "$T/v.mp4" ] || { echo "FAIL: render-replay wrote no video from the bag"; fail=1; }

# Bad input: exit 2, the file and the offset or topic named.
expect2() {  # expect2 NAME PATTERN ARGS...
  local name=$1 pattern=$2
  shift 2
  local rc=0
  "$EXO" "$@" >"$T/$name.err" 2>&1 || rc=$?
  if [ $rc -ne 2 ] || ! grep -q -- "$pattern" "$T/$name.err"; then
    echo "FAIL: $name: exit $rc (expected 2 and '$pattern'):"
    head -3 "$T/$name.err"
    fail=1
  else
    echo "ok: $name: $(head -1 "$T/$name.err" | cut -c1-200)"
  fi
}
expect2 no_map "rec.mcap: a ROS 2 bag needs a column map" predict --params "$S1" --measured "$T/rec.mcap" --out "$T/x.csv"
head -c 3000 "$T/rec.mcap" > "$T/cut.mcap"
expect2 truncated "cut.mcap: byte [0-9]*: .*truncated" diagnose --params "$S1" --measured "$T/cut.mcap" --map "$T/map.yaml" --out "$T/x"
printf 't,q_hip\n0,1\n' > "$T/text.mcap"
expect2 not_mcap "text.mcap: byte 0: not an MCAP file" convert --map "$T/map.yaml" "$T/text.mcap" --out "$T/x.csv"
python3 - "$T/rec.mcap" "$T/crc.mcap" <<'EOF'
import sys
b = bytearray(open(sys.argv[1], "rb").read())
i = b.find(b"exotwin tests/mcap_client")  # the Header record: outside every chunk
b[i] ^= 0x20
open(sys.argv[2], "wb").write(b)
EOF
expect2 bad_crc "crc.mcap: byte [0-9]*: .*CRC" predict --params "$S1" --measured "$T/crc.mcap" --map "$T/map.yaml" --out "$T/x.csv"
sed -e 's#/exo/joint_states.position\[knee\]#/exo/joint_state.position[knee]#' "$T/map.yaml" > "$T/bad_topic.yaml"
expect2 bad_topic "names no topic of .*rec.mcap (its topics: /exo/joint_states)" \
  predict --params "$S1" --measured "$T/rec.mcap" --map "$T/bad_topic.yaml" --out "$T/x.csv"
sed -e 's#position\[knee\]#position[ankle]#' "$T/map.yaml" > "$T/bad_name.yaml"
expect2 bad_name "topic /exo/joint_states, message 1: name 'ankle' is not in name \[hip, knee\]" \
  identify --measured "$T/rec.mcap" --map "$T/bad_name.yaml" --out "$T/x.yaml"
exit $fail
