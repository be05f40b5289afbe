#!/usr/bin/env python3
"""The draw and the scoring of scripts/combination_sweep.sh (issue 64 part 3).

  combination_draw.py --draw N MASTER_SEED   one line per case: i|length|seed|label|plant effects (YAML)
  combination_draw.py --score DIAGNOSIS_JSON EFFECTS_YAML   named | errors % | false causes | pass|FAIL
  combination_draw.py --named DIAGNOSIS_JSON   the named effects, one line

The draw of case i comes from random.Random(MASTER_SEED * 1000 + i) alone (a case does not change
with N): the hinge a hip band, a knee band or a knee strap (even odds: the plant's hinges with a
human, whose strap is the knee's), the friction's joint hip|knee, band log-uniform in 0.005-0.03 rad,
strap log-uniform in 300-1500 N m/rad, Coulomb friction log-uniform in 0.5-3 N m, length uniform in
20-60 s (whole seconds), the run's seed uniform in 1-1000.
Targets: backlash within 20 %, series_compliance within 25 %, coulomb_friction within 15 %, and
nothing else named.
"""
import json
import math
import re
import sys

TOLERANCE = {"backlash": 0.20, "series_compliance": 0.25, "coulomb_friction": 0.15}


def log_uniform(rng, lo, hi):
    return math.exp(rng.uniform(math.log(lo), math.log(hi)))


def draw(i, master):
    import random
    rng = random.Random(master * 1000 + i)
    kind, hinge_joint = rng.choice([("backlash", "hip"), ("backlash", "knee"), ("series_compliance", "knee")])
    friction_joint = rng.choice(["hip", "knee"])
    hinge = log_uniform(rng, 0.005, 0.03) if kind == "backlash" else log_uniform(rng, 300, 1500)
    friction = log_uniform(rng, 0.5, 3.0)
    length = rng.randint(20, 60)
    seed = rng.randint(1, 1000)
    hinge = float("%.4g" % hinge)
    friction = float("%.3g" % friction)
    effects = "{name: %s, joint: %s, value: %g}, {name: coulomb_friction, joint: %s, value: %g}" % (
        kind, hinge_joint, hinge, friction_joint, friction)
    label = "%s %s %g + %s coulomb %g" % (hinge_joint, "band" if kind == "backlash" else "strap", hinge,
                                          friction_joint, friction)
    return length, seed, label, effects


def parse_effects(text):
    return [(m.group(1), m.group(2), float(m.group(3)))
            for m in re.finditer(r"name: (\w+), joint: (\w+), value: ([0-9.eE+-]+)", text)]


def named(path):
    d = json.load(open(path))
    return "; ".join("%s %s %.4g" % (e["name"], e["joint"], e["value"]) for e in d["effects"]) or "nothing"


def score(path, effects_text):
    d = json.load(open(path))
    truth = parse_effects(effects_text)
    found = {(e["name"], e["joint"]): e["value"] for e in d["effects"]}
    errors, ok = [], True
    for name, joint, value in truth:
        if (name, joint) in found:
            err = (found[(name, joint)] - value) / value
            errors.append("%s %+.0f" % (name.split("_")[0], 100 * err))
            ok = ok and abs(err) <= TOLERANCE[name]
        else:
            errors.append("%s missing" % name.split("_")[0])
            ok = False
    false = ["%s %s %.3g" % (n, j, v) for (n, j), v in found.items() if (n, j) not in {(t[0], t[1]) for t in truth}]
    ok = ok and not false
    return "%s | %s | %s | %s" % (named(path), ", ".join(errors), "; ".join(false) or "-", "pass" if ok else "FAIL")


def main(argv):
    if argv[1] == "--draw":
        n, master = int(argv[2]), int(argv[3])
        for i in range(1, n + 1):
            length, seed, label, effects = draw(i, master)
            print("%d|%d|%d|%s|%s" % (i, length, seed, label, effects))
    elif argv[1] == "--score":
        print(score(argv[2], argv[3]))
    elif argv[1] == "--named":
        print(named(argv[2]))
    else:
        sys.exit("usage: combination_draw.py --draw N SEED | --score JSON EFFECTS | --named JSON")


if __name__ == "__main__":
    main(sys.argv)
