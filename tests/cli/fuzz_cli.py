#!/usr/bin/env python3
"""Mutation fuzz of the command line (issue 43): seeded mutations of the shipped inputs, each given to
the command that reads it, must end in exit 0, 1 (a scenario's check) or 2 (bad input, a message on
stderr): never "internal error", never a signal, never a hang.

  fuzz_cli.py EXOTWIN SRC [--count N] [--seed S] [--jobs J] [--readers a,b] [--keep DIR] [--timeout S]
              [--progress N]

EXOTWIN: the exotwin executable (exotwin-controller is looked for beside it and in ../deploy/);
SRC: the source tree (its shipped inputs are the seeds). --count mutations in all, shared round-robin
among the readers; the same --seed gives the same inputs. Prints per reader the inputs and the exits
by code, and every defect (kept with its input and stderr under --keep, default a temp folder that is
removed when nothing was found). Exit 0 when nothing was found, 1 otherwise, 2 on bad usage.
"""
import argparse
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

# Bytes and tokens that readers have trouble with: invalid or cut UTF-8, control characters, YAML
# structure, escapes, numbers at the edges, CSV structure.
BYTES = [0x00, 0x01, 0x07, 0x0B, 0x1B, 0x7F, 0x80, 0x85, 0xA0, 0xBF, 0xC0, 0xC1, 0xC2, 0xC3, 0xE2, 0xED, 0xEF,
         0xF0, 0xF4, 0xF5, 0xFF] + [ord(c) for c in "\n\r\t \"',:;#&*!?|>-[]{}\\%@`.eE+0159"]
TOKENS = [b"\xc1", b"\xc3", b"\xed\xa0\x80", b"\xf4\x90\x80\x80", b"\xef\xbb\xbf", b"\xc2\x85", b"\x1b[31m",
          b'"\\x85"', b'"\\e"', b'"\\0"', b'"\\xC1"', b'"\\uD800"', b'"\\U0010FFFF"', b"nan", b".nan", b"inf",
          b"-.inf", b"1e308", b"-1e308", b"1e-320", b"4.9e-324", b"0", b"-0", b"1e999", b"9" * 40, b"0x10",
          b"~", b"null", b"[]", b"{}", b"&a ", b"*a", b"<<: *a", b"!!binary ", b"!!str ", b"? ", b"- ", b"---\n",
          b"...\n", b"%YAML 1.2\n", b",", b",,", b'"', b'""', b"\r", b"\r\n", b"\t", b"#", b"\n#", b": ", b"|\n",
          b">\n", b"'", b"\\", b"\n\n", b" " * 70, b"a" * 300]
NUMBER = re.compile(rb"-?\d+(\.\d+)?([eE][-+]?\d+)?")


def mutate(data: bytes, rng: random.Random) -> bytes:
    b = bytearray(data)
    for _ in range(rng.choice([1, 1, 1, 2, 2, 3, 4, 8])):
        op = rng.randrange(10)
        pos = rng.randrange(len(b) + 1)
        if op == 0 and b:  # flip a bit
            p = rng.randrange(len(b))
            b[p] ^= 1 << rng.randrange(8)
        elif op == 1 and b:  # an awkward byte
            b[rng.randrange(len(b))] = rng.choice(BYTES)
        elif op in (2, 3):  # an awkward token
            b[pos:pos] = rng.choice(TOKENS)
        elif op == 4 and b:  # delete a range
            n = rng.choice([1, 1, 2, 5, 20, 200])
            del b[pos:pos + n]
        elif op in (5, 6, 7):  # a line duplicated, deleted or swapped
            lines = bytes(b).split(b"\n")
            i, j = rng.randrange(len(lines)), rng.randrange(len(lines))
            if op == 5:
                lines.insert(j, lines[i])
            elif op == 6 and len(lines) > 1:
                del lines[i]
            else:
                lines[i], lines[j] = lines[j], lines[i]
            b = bytearray(b"\n".join(lines))
        elif op == 8:  # a number replaced
            nums = list(NUMBER.finditer(bytes(b)))
            if nums:
                m = rng.choice(nums)
                b[m.start():m.end()] = rng.choice([b"0", b"-1", b"1e308", b"-1e308", b"nan", b"1e-320", b"99999999999",
                                                   b"0.5", b"-0", b"3", b"1e9", b"2.5e-5", b"inf"])
        elif op == 9 and b:  # truncated
            del b[rng.randrange(len(b)):]
    return bytes(b)


class Reader:
    """One reader: its seed files and the command that reads a mutated one (FILE in the arguments)."""

    def __init__(self, name, seeds, argv, exe="exotwin", suffix=None):
        self.name, self.seeds, self.argv, self.exe = name, seeds, argv, exe
        self.suffix = suffix


def head_lines(path, n):
    with open(path, "rb") as f:
        return b"".join(f.readline() for _ in range(n))


def setup(src, exo, work):
    """Writes the seed inputs into work/seeds and returns the readers."""
    seeds = os.path.join(work, "seeds")
    os.makedirs(seeds)

    def put(name, data):
        p = os.path.join(seeds, name)
        with open(p, "wb") as f:
            f.write(data if isinstance(data, bytes) else data.encode())
        return p

    def shipped(rel):
        with open(os.path.join(src, rel), "rb") as f:
            return f.read()

    csv = put("S1.csv", head_lines(os.path.join(src, "examples/S1_excitation.csv"), 402))
    foreign = put("rig.csv", head_lines(os.path.join(src, "examples/real_rig/trajectory_05.csv"), 300))
    gait = shipped("scenarios/gait_2kmh.yaml").replace(b"duration: 60", b"duration: 0.3").replace(b"ramp: 2.0", b"ramp: 0.1")
    gait = gait.replace(b"bus load below 70 %", "bus load below 70 % (\u00e9\u20ac)".encode())
    plant = gait.replace(b"checks:", b"plant:\n  effects:\n    - {name: coulomb_friction, joint: knee, value: 0.5, unit: N m}\n"
                         b"    - {name: sensor_offset, joint: hip, value: 0.1, unit: N m}\nchecks:")
    plant_from = gait.replace(b"checks:", ("plant: {effects_from: %s}\nchecks:" %
                                           os.path.join(src, "data/plants/exowheel_realistic.yaml")).encode())
    fault = shipped("scenarios/faults/sensor_stuck.yaml")
    fault = re.sub(rb"duration: *[0-9.]+", b"duration: 0.4", fault, count=1)
    fault = re.sub(rb"at: *[0-9.]+", b"at: 0.2", fault)
    # HAL-3: a short run (settle 4 s) of experiment 1, and a two-value viscosity sweep of it.
    hal = shipped("scenarios/hal3_exp1_no_assist.yaml").replace(b"protocol: {duration: 12}", b"protocol: {duration: 4.5}")
    hal_sweep = hal.replace(b"virtual_viscosity: 0.0,", b"sweep_viscosity: [0, 1.5],")
    scen = [put("gait.yaml", gait), put("gait_plant.yaml", plant), put("gait_plant_from.yaml", plant_from),
            put("fault.yaml", fault), put("hal.yaml", hal), put("hal_sweep.yaml", hal_sweep)]
    # An OpenSim motion file (the hip and knee of a slow swing) and the scenario that plays it.
    rows = ["%.3f\t%.4f\t%.4f" % (i * 0.01, 20 * ((i % 50) / 50.0), -30 * ((i % 40) / 40.0)) for i in range(101)]
    mot = put("swing.mot", "swing\nversion=1\nnRows=101\nnColumns=3\ninDegrees=yes\nendheader\n"
                           "time\thip_flexion_r\tknee_angle_r\n" + "\n".join(rows) + "\n")
    mot_scenario = re.sub(rb"protocol: \{[^}]*\}", ("protocol: {trajectory: file, path: %s, duration: 0.3, ramp: 0.1}" % mot).encode(), gait)
    put("motion.yaml", mot_scenario)
    # One-joint record: HAL's columns, from a short HAL run if one is there, else written here.
    one = "t,q_knee,tau_knee,cmd_knee\n" + "".join(
        "%.3f,%.5f,%.4f,%.4f\n" % (i * 0.001, 0.3 * (i % 500) / 500.0, 1.5 - 0.002 * (i % 700), 2.0) for i in range(400))
    one_csv = put("one_joint.csv", one)
    # The controller file `serve` writes for a scenario (a scenario is also accepted by exotwin-controller).
    ctrl_text = ("# exotwin controller file\ndevice: exowheel\nrate_hz: 1000\nkp: [600, 400]\nkd: [30, 15]\n"
                 "feedforward: true\ntorque_limit: 100\n")
    ctrl = put("controller.yaml", ctrl_text)
    d = os.path.join(work, "serve")
    try:  # the real one: serve writes it before it waits (its wait then times out)
        subprocess.run([exo, "serve", scen[0], "--bus", "unix:" + os.path.join(work, "s.sock"), "--timeout", "0.05",
                        "--out", d], capture_output=True, timeout=60)
        if os.path.exists(os.path.join(d, "controller.yaml")):
            shutil.copy(os.path.join(d, "controller.yaml"), ctrl)
    except subprocess.TimeoutExpired:
        pass
    # A measured.sto as `run --sto` writes it (the storage writer's output, read back by predict).
    d = os.path.join(work, "sto")
    subprocess.run([exo, "run", scen[0], "--sto", "--out", d], capture_output=True, timeout=120)
    sto = os.path.join(d, "measured.sto")
    stos = [put("measured.sto", head_lines(sto, 200))] if os.path.exists(sto) else []
    stos.append(mot)

    models = [os.path.join(src, p) for p in ("examples/S1.yaml", "data/plants/exowheel_realistic.yaml",
                                             "data/plants/relaxed_leg.yaml", "data/plants/human_side.yaml")]
    maps = [os.path.join(src, "examples/real_rig/dfki_double_pendulum_A0.map.yaml")]
    out = "{OUT}"
    readers = [
        Reader("scenario", scen + [os.path.join(seeds, "motion.yaml")], ["run", "{FILE}", "--out", out]),
        Reader("model", models, ["predict", "--params", "{FILE}", "--measured", csv, "--out", out + "/p.csv"]),
        Reader("model_one_joint", [os.path.join(src, "examples/hal3_knee.yaml")],
               ["predict", "--params", "{FILE}", "--measured", one_csv, "--out", out + "/p.csv"]),
        Reader("plant_file", [os.path.join(src, "data/plants/exowheel_realistic.yaml")],
               ["run", put("gait_plant_file.yaml", gait.replace(b"checks:", b"plant: {effects_from: plant.yaml}\nchecks:")),
                "--out", out], suffix="plant.yaml"),
        Reader("measured_csv", [csv], ["predict", "--params", models[0], "--measured", "{FILE}", "--out", out + "/p.csv"]),
        Reader("one_joint_csv", [one_csv], ["predict", "--params", os.path.join(src, "examples/hal3_knee.yaml"),
                                            "--measured", "{FILE}", "--out", out + "/p.csv"]),
        Reader("column_map", maps, ["convert", "--map", "{FILE}", foreign, "--out", out + "/c.csv"]),
        Reader("foreign_csv", [foreign], ["convert", "--map", maps[0], "{FILE}", "--out", out + "/c.csv"]),
        Reader("opensim_sto", stos, ["predict", "--params", models[0], "--measured", "{FILE}", "--out", out + "/p.csv"]),
        Reader("controller_file", [ctrl, scen[0]], ["--config", "{FILE}", "--bus", "unix:/nonexistent-exotwin-dir/c.sock"],
               exe="exotwin-controller"),
        Reader("argv", [], []),  # mutated command-line values (see argv_case)
    ]
    return readers


def argv_case(rng, readers, exo_dir, work):
    """A command line of a reader with one of its values mutated (the file itself unchanged)."""
    r = rng.choice([x for x in readers if x.seeds and x.exe == "exotwin" and x.name != "scenario"])
    argv = [a.replace("{FILE}", rng.choice(r.seeds)) for a in r.argv]
    i = rng.randrange(len(argv))
    # (a NUL cannot be passed in an argument: the kernel ends the string there)
    argv[i] = os.fsdecode(mutate(os.fsencode(argv[i]), rng).replace(b"\0", b"")) if rng.random() < 0.7 else rng.choice(
        ["", "-", "--", "-1", "nan", "1e999", "\udcc1", "a\udcff", "x\x1b", "--out", "--help", "/", "/dev/null"])
    return argv


def exe_path(exo, name):
    if name == "exotwin":
        return exo
    d = os.path.dirname(os.path.abspath(exo))
    for c in (os.path.join(d, name), os.path.join(d, "..", "deploy", name), os.path.join(d, "deploy", name)):
        if os.path.exists(c):
            return c
    return shutil.which(name)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("exotwin")
    ap.add_argument("src")
    ap.add_argument("--count", type=int, default=300)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--readers", default="")
    ap.add_argument("--keep", default="")
    ap.add_argument("--timeout", type=float, default=120)
    ap.add_argument("--progress", type=int, default=0, help="print the table every N mutations (0: at the end)")
    a = ap.parse_args()
    if a.count < 1 or a.jobs < 1:
        print("fuzz_cli: --count and --jobs must be >= 1", file=sys.stderr)
        return 2
    a.src = os.path.abspath(a.src)
    work = tempfile.mkdtemp(prefix="exotwin_fuzz_cli_")
    try:
        return run(a, work)
    finally:
        shutil.rmtree(work, ignore_errors=True)


def run(a, work):
    exo = os.path.abspath(a.exotwin)
    readers = setup(a.src, exo, work)
    if a.readers:
        want = set(a.readers.split(","))
        unknown = want - {r.name for r in readers}
        if unknown:
            print("fuzz_cli: unknown readers: %s (expected: %s)" % (", ".join(sorted(unknown)),
                  ", ".join(r.name for r in readers)), file=sys.stderr)
            return 2
        readers = [r for r in readers if r.name in want]
    for r in readers:
        if r.exe != "exotwin" and not exe_path(exo, r.exe):
            print("fuzz_cli: %s not found beside %s: reader %s skipped" % (r.exe, exo, r.name))
    readers = [r for r in readers if r.exe == "exotwin" or exe_path(exo, r.exe)]
    keep = a.keep or os.path.join(work, "found")
    os.makedirs(keep, exist_ok=True)
    stats = {r.name: {} for r in readers}
    found = []

    def one(k):
        r = readers[k % len(readers)]
        rng = random.Random("%d/%d" % (a.seed, k))
        case = os.path.join(work, "case%d" % k)
        os.makedirs(case)
        out = os.path.join(case, "out")
        if r.name == "argv":
            argv, exe, data = argv_case(rng, readers, os.path.dirname(exo), work), exo, None
        else:
            seed = rng.choice(r.seeds)
            with open(seed, "rb") as f:
                data = mutate(f.read(), rng)
            name = r.suffix or os.path.basename(seed)
            path = os.path.join(case, name)
            with open(path, "wb") as f:
                f.write(data)
            if r.suffix:  # the reader's file sits beside a fixed file that names it (plant effects_from)
                fixed = next(x for x in r.argv if x.endswith(".yaml") and x != "{FILE}")
                shutil.copy(fixed, os.path.join(case, os.path.basename(fixed)))
                argv = [os.path.join(case, os.path.basename(fixed)) if x == fixed else x for x in r.argv]
            else:
                argv = [x.replace("{FILE}", path) for x in r.argv]
            argv = [x.replace("{OUT}", out) for x in argv]
            exe = exe_path(exo, r.exe)
        argv = [x.replace("{OUT}", out) for x in argv]
        t0 = time.time()
        try:
            p = subprocess.run([exe] + argv, capture_output=True, timeout=a.timeout, cwd=case)
            rc, err = p.returncode, p.stderr
        except subprocess.TimeoutExpired as e:
            rc, err = "hang", e.stderr or b""
        verdict = None
        if rc == "hang":
            verdict = "hang (> %g s)" % a.timeout
        elif rc < 0:
            verdict = "signal %d" % -rc
        elif rc not in (0, 1, 2):
            verdict = "exit %d" % rc
        elif b"internal error" in err:
            verdict = "internal error"
        elif b"AddressSanitizer" in err or b"runtime error:" in err or b"LeakSanitizer" in err:
            verdict = "sanitizer report"
        elif rc == 2 and not err.strip():
            verdict = "exit 2 without a message"
        if verdict:
            d = os.path.join(keep, "%s_%d" % (r.name, k))
            os.makedirs(d, exist_ok=True)
            if data is not None:
                with open(os.path.join(d, "input"), "wb") as f:
                    f.write(data)
            with open(os.path.join(d, "stderr"), "wb") as f:
                f.write(err)
            with open(os.path.join(d, "argv"), "w", errors="surrogateescape") as f:
                f.write(" ".join([os.path.basename(exe)] + argv) + "\n")
        shutil.rmtree(case, ignore_errors=True)
        return r.name, rc, verdict, time.time() - t0, err

    def table(done, secs):
        print("fuzz_cli: %d mutations, seed %d, %.0f s (%d jobs)" % (done, a.seed, secs, a.jobs))
        print("  %-16s %7s  %s" % ("reader", "inputs", "exits"))
        for r in readers:
            s = stats[r.name]
            print("  %-16s %7d  %s" % (r.name, sum(s.values()),
                                         ", ".join("%s: %d" % (k, v) for k, v in sorted(s.items(), key=lambda kv: str(kv[0])))))
        sys.stdout.flush()

    t0 = time.time()
    done = 0
    with ThreadPoolExecutor(max_workers=a.jobs) as pool:
        for name, rc, verdict, secs, err in pool.map(one, range(a.count)):
            key = "hang" if rc == "hang" else rc
            if name == "controller_file" and rc == 2 and b": --bus unix:/nonexistent-exotwin-dir" in err:
                key = "2 (file read, bus refused)"  # the file passed every check before the bus
            stats[name][key] = stats[name].get(key, 0) + 1
            if verdict:
                found.append((name, verdict, err.decode(errors="replace").strip().splitlines()[-1:] if err else []))
                print("fuzz_cli: defect: %s: %s: %s" % (name, verdict, found[-1][2][0] if found[-1][2] else ""))
            done += 1
            if a.progress and done % a.progress == 0 and done < a.count:
                table(done, time.time() - t0)
    table(a.count, time.time() - t0)
    if found:
        print("fuzz_cli: %d defects (inputs, argv and stderr in %s):" % (len(found), keep))
        for name, verdict, last in found:
            print("  %s: %s: %s" % (name, verdict, last[0] if last else ""))
        if not a.keep:  # the temp folder goes: keep a copy next to the caller's TMPDIR
            dest = tempfile.mkdtemp(prefix="exotwin_fuzz_cli_found_")
            shutil.copytree(keep, dest, dirs_exist_ok=True)
            print("fuzz_cli: copied to %s" % dest)
        return 1
    print("fuzz_cli: no defect")
    return 0


if __name__ == "__main__":
    sys.exit(main())
