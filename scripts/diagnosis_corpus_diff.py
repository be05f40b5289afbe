#!/usr/bin/env python3
"""Compares two corpora of diagnoses (scripts/diagnosis_corpus.sh): every case's diagnosis.json and
extended.yaml. JSON: the same keys, the same strings, every number within 1e-6 relative (1e-12
absolute); keys that measure the machine (timings, threads) and the records' paths are skipped. Prints each difference with
its path; exit 1 when any."""
import json, math, os, sys

SKIP = {"seconds", "wall_s", "cpu_s", "threads", "timing", "elapsed_s",
        "source"}  # the record's path: the corpus's own folder, which differs between runs


def close(a, b):
    return a == b or abs(a - b) <= 1e-12 + 1e-6 * max(abs(a), abs(b))


def diff(a, b, path, out):
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k in SKIP:
                continue
            if k not in a or k not in b:
                out.append(f"{path}.{k}: only in {'frozen' if k in a else 'new'}")
            else:
                diff(a[k], b[k], f"{path}.{k}", out)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{path}: {len(a)} entries, now {len(b)}")
        for i, (x, y) in enumerate(zip(a, b)):
            diff(x, y, f"{path}[{i}]", out)
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)) and not isinstance(a, bool):
        if not close(float(a), float(b)) and not (math.isnan(a) and math.isnan(b)):
            out.append(f"{path}: {a!r} -> {b!r}")
    elif a != b:
        out.append(f"{path}: {a!r} -> {b!r}")


def main():
    frozen, new = sys.argv[1], sys.argv[2]
    cases = sorted(c for c in os.listdir(frozen) if os.path.isfile(os.path.join(frozen, c, "diagnosis.json")))
    out = []
    for c in cases:
        fn = os.path.join(new, c, "diagnosis.json")
        if not os.path.isfile(fn):
            out.append(f"{c}: no diagnosis now")
            continue
        d = []
        diff(json.load(open(os.path.join(frozen, c, "diagnosis.json"))), json.load(open(fn)), c, d)
        out += d
    for line in out[:200]:
        print(line)
    print(f"corpus: {len(cases)} cases, {len(out)} differences")
    sys.exit(1 if out else 0)


if __name__ == "__main__":
    main()
