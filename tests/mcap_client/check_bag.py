#!/usr/bin/env python3
"""Checks a bag exotwin wrote, as read_bag.mjs decoded it (Foxglove's libraries), against the run's CSV
logs (DESIGN.md "ROS 2 bags (MCAP) in and out"): every topic's message count equals the logs' rows,
every value equals the CSV's (the CSV prints each double so that it reads back bit for bit), every
CSV column is on a topic, the stamps are the run's clock (trial k shifted by k * trial_spacing_s), the
metadata names the scenario and the seed.

usage: check_bag.py BAG.json SCENARIO_NAME SEED CSV_DIR [TRIALS] [--velocity-unknown]
(--velocity-unknown: the measured JointState's velocity is NaN, JSON null: `serve` of an EXOwheel,
whose link does not carry the controller's estimate; otherwise a finite number per joint)
Exit 0 and one line per topic on success; 1 and the first mismatch otherwise.
"""
import csv
import json
import sys


def fail(what):
    print(f"check_bag: FAIL: {what}")
    sys.exit(1)


def read_csv(path):
    with open(path, newline="") as f:
        lines = [l for l in f if not l.startswith("#")]
    rows = list(csv.reader(lines))
    return rows[0], [[float(x) for x in r] for r in rows[1:]]


# The documented topics (run_bag.h): JointState fields from columns, Float64MultiArray labels.
MEASURED_JOINTS = [("hip", "q_hip", None, "tau_hip", -1), ("knee", "q_knee", None, "tau_knee", -1)]
TRUTH_JOINTS = [("hip", "q_hip", "qd_hip", "tau_R_hip", 1), ("knee", "q_knee", "qd_knee", "tau_R_knee", 1),
                ("knee", "th", "thd", "tau_motor", 1)]
JOINT_TOPIC = {"measured": "/exo/joint_states", "truth": "/exo/truth/joint_states"}
ARRAY_TOPICS = {"measured": ["/exo/command", "/exo/reference", "/exo/emg", "/exo/safety_state", "/exo/assist",
                             "/exo/measured/other"],
                "truth": ["/exo/truth/muscle_torque", "/exo/truth/human", "/exo/truth/other"]}


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    unknown_velocity = "--velocity-unknown" in sys.argv
    bag_json, name, seed, csv_dir = args[:4]
    trials = int(args[4]) if len(args) > 4 else 1
    bag = json.load(open(bag_json))
    meta = bag["metadata"].get("exotwin")
    if not meta or meta.get("scenario") != name or meta.get("seed") != seed:
        fail(f"metadata 'exotwin' {meta}, expected scenario {name} seed {seed}")
    if bag["profile"] != "ros2":
        fail(f"profile {bag['profile']}")
    spacing = float(meta["trial_spacing_s"])
    topics = bag["topics"]
    seen = {t: 0 for t in topics}  # messages of each topic checked so far (all trials)
    for kind in ("measured", "truth"):
        for k in range(trials):
            path = f"{csv_dir}/{kind}{'_trial%d' % (k + 1) if trials > 1 else ''}.csv"
            cols, rows = read_csv(path)
            ix = {c: i for i, c in enumerate(cols)}
            covered = {"t"}
            joints = [j for j in (MEASURED_JOINTS if kind == "measured" else TRUTH_JOINTS) if j[1] in ix]
            names = [j[0] for j in joints]
            if joints:
                topic = JOINT_TOPIC[kind]
                msgs = topics[topic]["messages"][seen[topic]:seen[topic] + len(rows)]
                if len(msgs) != len(rows):
                    fail(f"{topic}: {len(msgs)} messages for the {len(rows)} rows of {path}")
                for r, m in zip(rows, msgs):
                    ns = round((r[ix["t"]] + k * spacing) * 1e9)
                    js = m["message"]
                    stamp = js["header"]["stamp"]
                    if int(m["log_time"]) != ns or int(m["publish_time"]) != ns or stamp["sec"] * 10**9 + stamp["nanosec"] != ns:
                        fail(f"{topic}: stamp {m['log_time']} / {stamp}, expected {ns} ns (t = {r[0]}, trial {k + 1})")
                    if js["name"] != names:
                        fail(f"{topic}: names {js['name']}, expected {names}")
                    for i, (_, q, qd, tau, sign) in enumerate(joints):
                        if js["position"][i] != r[ix[q]]:
                            fail(f"{topic}: position[{i}] {js['position'][i]} != {q} {r[ix[q]]} at t = {r[0]}")
                        if js["effort"][i] != sign * r[ix[tau]]:
                            fail(f"{topic}: effort[{i}] {js['effort'][i]} != {sign} * {tau} {r[ix[tau]]} at t = {r[0]}")
                        if qd is not None and js["velocity"][i] != r[ix[qd]]:
                            fail(f"{topic}: velocity[{i}] {js['velocity'][i]} != {qd} {r[ix[qd]]} at t = {r[0]}")
                        if qd is None and len(js["velocity"]) != len(names):
                            fail(f"{topic}: velocity {js['velocity']}: expected one per joint")
                        if qd is None and unknown_velocity != (js["velocity"][i] is None):
                            fail(f"{topic}: velocity {js['velocity']}: expected "
                                 f"{'NaN (unknown)' if unknown_velocity else 'a finite estimate'} per joint")
                        covered |= {q, tau} | ({qd} if qd else set())
                seen[topic] += len(rows)
            for topic in ARRAY_TOPICS[kind]:
                if topic not in topics:
                    continue
                msgs = topics[topic]["messages"][seen[topic]:seen[topic] + len(rows)]
                if len(msgs) != len(rows):
                    fail(f"{topic}: {len(msgs)} messages for the {len(rows)} rows of {path}")
                for r, m in zip(rows, msgs):
                    ns = round((r[ix["t"]] + k * spacing) * 1e9)
                    if int(m["log_time"]) != ns:
                        fail(f"{topic}: log_time {m['log_time']}, expected {ns} ns")
                    dim = m["message"]["layout"]["dim"]
                    labels = dim[0]["label"].split(",")
                    data = m["message"]["data"]
                    if len(dim) != 1 or dim[0]["size"] != len(data) or len(labels) != len(data):
                        fail(f"{topic}: layout {dim} for {len(data)} values")
                    for lab, v in zip(labels, data):
                        if lab not in ix:
                            fail(f"{topic}: label {lab} is no column of {path}")
                        if v != r[ix[lab]]:
                            fail(f"{topic}: {lab} {v} != CSV {r[ix[lab]]} at t = {r[0]}")
                    covered |= set(labels)
                seen[topic] += len(rows)
            missing = [c for c in cols if c not in covered]
            if missing:
                fail(f"{path}: columns on no topic: {missing}")
    for t, n in seen.items():
        if n != topics[t]["count"] or n != len(topics[t]["messages"]):
            fail(f"{t}: {topics[t]['count']} messages in the bag, {n} rows in the logs")
        print(f"ok: {t} ({topics[t]['schema']}): {n} messages = rows, values = the CSV's")


main()
