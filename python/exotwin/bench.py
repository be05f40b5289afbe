"""The Python module's bench rows (`exotwin bench --only python` runs `python3 -m exotwin.bench`), each
against a baseline measured in the same run, best of `repeat`:

1. exotwin.run(gait_2kmh) in this interpreter vs `exotwin run gait_2kmh.yaml` (the program, spawned):
   the same work, both writing both CSV logs (target <= 1.05x wall);
2. a Python PD controller stepping Twin.step over the 60 s of gait vs the UDP example
   (examples/python_controller/pd_controller.py against `exotwin serve --bus udp:...`), the same gains
   (target <= 0.25x wall);
3. the binding's own cost per step: a no-op controller (Twin.step(None), the shipped controller acting)
   against exotwin.run of the same scenario (us per controller period).

Usage: python3 -m exotwin.bench --exotwin PATH/exotwin [--repeat N] [--quick] [--json FILE] [--cpu N];
prints JSON
{"status": "ok", "rows": [{work, ratio, unit, baseline, goal, detail}], ...} on stdout.
"""
import argparse
import json
import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time

import exotwin


def best_of_pair(n, a, b):
    """Best wall time of a and of b over n rounds, a and b alternating (a machine whose load drifts
    during the bench weighs on both alike)."""
    best = [float("inf"), float("inf")]
    for _ in range(n):
        for i, fn in enumerate((a, b)):
            t0 = time.perf_counter()
            fn()
            best[i] = min(best[i], time.perf_counter() - t0)
    return best


def free_udp_port():
    # two consecutive ports: the twin's and the controller's (HOST:PORT and HOST:PORT+1)
    for _ in range(50):
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as a:
            a.bind(("127.0.0.1", 0))
            port = a.getsockname()[1]
            try:
                with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as b:
                    b.bind(("127.0.0.1", port + 1))
                    return port
            except OSError:
                continue
    raise RuntimeError("no two consecutive free UDP ports")


def python_pd(twin, kp=(600.0, 400.0), kd=(30.0, 15.0), limit=100.0):
    """The UDP example's law on the twin's observations, in plain Python floats as the example is:
    PD on the reference, velocities as difference quotients, clamped to the torque limit. Returns the
    periods stepped."""
    obs = twin.reset()
    inv_dt = 1.0 / twin.period
    kp_h, kp_k = kp
    kd_h, kd_k = kd
    q_h, q_k, r_h, r_k = obs["q_hip"], obs["q_knee"], obs["ref_hip"], obs["ref_knee"]
    n = 0
    step = twin.step
    while not twin.done:
        q_h0, q_k0, r_h0, r_k0 = q_h, q_k, r_h, r_k
        q_h, q_k, r_h, r_k = obs["q_hip"], obs["q_knee"], obs["ref_hip"], obs["ref_knee"]
        u_h = kp_h * (r_h - q_h) + kd_h * ((r_h - r_h0) - (q_h - q_h0)) * inv_dt
        u_k = kp_k * (r_k - q_k) + kd_k * ((r_k - r_k0) - (q_k - q_k0)) * inv_dt
        obs = step((min(max(u_h, -limit), limit), min(max(u_k, -limit), limit)))
        n += 1
    return n


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--exotwin", required=True, help="the exotwin program (the CLI baseline, exotwin serve)")
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--quick", action="store_true", help="6 s of gait instead of 60")
    ap.add_argument("--json", help="write the JSON here too")
    ap.add_argument("--cpu", type=int, help="CPU the in-process comparisons (rows 1 and 3) run on, both halves "
                    "(and their threads and children): CPUs of a shared machine can differ in speed")
    a = ap.parse_args(argv)
    data = os.environ.get("EXOTWIN_DATA_DIR")
    scratch = tempfile.mkdtemp(prefix="exotwin_pybench_")
    try:
        scenario = os.path.join(data, "scenarios", "gait_2kmh.yaml")
        if a.quick:
            text = open(scenario).read().replace("duration: 60,", "duration: 6,")
            scenario = os.path.join(scratch, "gait_6s.yaml")
            with open(scenario, "w") as f:
                f.write(text)
        seconds = 6.0 if a.quick else 60.0
        rows = []

        unpinned = os.sched_getaffinity(0)
        pinned = {a.cpu} if a.cpu is not None and a.cpu in unpinned else unpinned

        # 1. exotwin.run vs the program
        os.sched_setaffinity(0, pinned)
        cli, py = best_of_pair(
            a.repeat, lambda: subprocess.run([a.exotwin, "run", scenario, "--out", os.path.join(scratch, "cli")],
                                             check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL),
            lambda: exotwin.run(scenario, out=os.path.join(scratch, "py")))
        rows.append({"work": f"exotwin.run gait_2kmh ({seconds:g} s, both CSV logs) from Python", "ratio": py / cli,
                     "unit": "x", "baseline": "exotwin run, the same scenario (program spawned)", "goal": "<= 1.05x",
                     "detail": f"{py:.3f} s vs {cli:.3f} s"})

        os.sched_setaffinity(0, unpinned)

        # 2. Python PD on Twin.step vs the UDP example (unpinned: the example's two processes as a user runs them)
        pd_script = os.path.join(data, "examples", "python_controller", "pd_controller.py")
        winter = os.path.join(data, "data", "WinterTableA1.txt")

        def udp():
            port = free_udp_port()
            serve = subprocess.Popen([a.exotwin, "serve", scenario, "--bus", f"udp:127.0.0.1:{port}", "--out",
                                      os.path.join(scratch, "serve")], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            ctrl = subprocess.run([sys.executable, pd_script, "--bus", f"udp:127.0.0.1:{port}", "--winter", winter],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            rc = serve.wait(timeout=600)
            if ctrl.returncode != 0 or rc not in (0, 1):
                raise RuntimeError(f"the UDP example failed: controller exit {ctrl.returncode}, serve exit {rc}")

        twin = exotwin.Twin(scenario)
        udp_s, twin_s = best_of_pair(a.repeat, udp, lambda: python_pd(twin))
        steps = python_pd(twin)
        rows.append({"work": f"Python PD controller on Twin.step, gait_2kmh ({seconds:g} s, {steps} periods)",
                     "ratio": twin_s / udp_s, "unit": "x",
                     "baseline": "the UDP example: pd_controller.py against exotwin serve --bus udp", "goal": "<= 0.25x",
                     "detail": f"{twin_s:.3f} s vs {udp_s:.3f} s; tracking RMS knee "
                               f"{twin.result.metrics['tracking_rms_knee_deg']:.2f} deg"})

        # 3. the binding's cost per step: no-op controller vs the in-process run
        logged = exotwin.Twin(scenario, out=os.path.join(scratch, "twin"))  # both CSV logs, as exotwin.run

        def noop():
            logged.reset()
            while not logged.done:
                logged.step()

        os.sched_setaffinity(0, pinned)
        noop_s, run_s = best_of_pair(a.repeat, noop, lambda: exotwin.run(scenario))
        os.sched_setaffinity(0, unpinned)
        per_step = (noop_s - run_s) / steps
        rows.append({"work": "binding cost per Twin.step (no-op Python controller, the shipped one acting)",
                     "ratio": noop_s / run_s, "unit": "x", "baseline": "exotwin.run of the same scenario (in-process; both write the CSV logs)",
                     "goal": "", "detail": f"{noop_s:.3f} s vs {run_s:.3f} s: {per_step * 1e6:+.2f} us per step "
                                           f"({steps} steps)"})
        text = json.dumps({"status": "ok", "quick": a.quick, "repeat": a.repeat, "rows": rows,
                           "python": sys.executable, "pinned_cpus": sorted(pinned), "cli_run_s": cli, "py_run_s": py, "udp_s": udp_s,
                           "twin_pd_s": twin_s, "twin_noop_s": noop_s, "inprocess_run_s": run_s}, indent=2)
        print(text)
        if a.json:
            with open(a.json, "w") as f:
                f.write(text + "\n")
    finally:
        shutil.rmtree(scratch, ignore_errors=True)


if __name__ == "__main__":
    main()
