#!/usr/bin/env python3
"""exotwin from Python, first steps: run the gait, plot the tracking, hide an effect in the plant,
diagnose it, replay the rigid and the extended twin on the record, plot the gain.

    python3 first_steps.py [--out DIR] [--duration S] [--effect NAME --joint J --value V]

Writes DIR/tracking.png, DIR/frame.png (the leg rendered off-screen), DIR/diagnosis.png,
DIR/replay.png, DIR/ghosts.png (both twins' replayed legs as ghosts) with matplotlib (Agg: no display
needed) and the commands' files under DIR; prints what it found. --duration shortens the gait
(default: the 60 s of scenarios/gait_2kmh.yaml). The test suite runs it (tests/python/example_test.py).
"""
import argparse
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import exotwin  # noqa: E402

# The shipped gait scenario's twin (scenarios/gait_2kmh.yaml), with room for the plant's hidden effects.
SCENARIO = """name: {name}
seed: 1
device: exowheel
subject: {{preset: S1, passive: riener1999}}
protocol: {{trajectory: gait, stride_period: 2.0, duration: {duration}, trials: 1, ramp: 2.0}}
controller: {{rate_hz: 1000, kp: [600, 400], kd: [30, 15], feedforward: true, torque_limit: 100}}
hardware: {{can_bitrate: 1000000, can_latency: 0.00005, can_jitter: 0.00001, torque_sensor_noise: 0.024}}
{plant}"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default="out/python_first_steps")
    ap.add_argument("--duration", type=float, default=60.0, help="s of gait")
    ap.add_argument("--effect", default="coulomb_friction")
    ap.add_argument("--joint", default="knee")
    ap.add_argument("--value", type=float, default=1.5, help="in the effect's unit (DESIGN.md \"Effects\")")
    ap.add_argument("--unit", default="N m")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)

    # 1. The gait: the twin with its shipped controller; the logs come back as numpy arrays.
    rigid_scenario = os.path.join(a.out, "gait.yaml")
    with open(rigid_scenario, "w") as f:
        f.write(SCENARIO.format(name="gait", duration=a.duration, plant=""))
    r = exotwin.run(rigid_scenario, seed=1, out=os.path.join(a.out, "gait"))
    m = r.measured
    print(f"gait: {len(m['t'])} samples, tracking RMS hip {r.metrics['tracking_rms_hip_deg']:.2f} deg, "
          f"knee {r.metrics['tracking_rms_knee_deg']:.2f} deg, checks {'passed' if r.passed else 'FAILED'}")
    fig, ax = plt.subplots(2, 1, sharex=True, figsize=(9, 5))
    for k, joint in enumerate(("hip", "knee")):
        ax[k].plot(m["t"], np.degrees(m[f"ref_{joint}"]), label="reference")
        ax[k].plot(m["t"], np.degrees(m[f"q_{joint}"]), "--", label="encoder")
        ax[k].set_ylabel(f"{joint} (deg)")
        ax[k].legend(loc="upper right")
    ax[1].set_xlabel("t (s)")
    fig.suptitle("gait_2kmh: reference and measured angle")
    fig.savefig(os.path.join(a.out, "tracking.png"), dpi=100)
    # the leg at mid-swing of the last stride, rendered off-screen into a numpy array
    last = min(2000, len(m["t"]))  # the last stride (2 s at 1 kHz)
    k = int(np.argmin(m["q_knee"][-last:])) + len(m["t"]) - last
    plt.imsave(os.path.join(a.out, "frame.png"), exotwin.render_frame(m["q_hip"][k], m["q_knee"][k]))

    # 2. A plant with an effect the rigid twin does not know, run with the same controller: its record.
    effect = f"{{name: {a.effect}, joint: {a.joint}, value: {a.value}, unit: \"{a.unit}\"}}"
    hidden_scenario = os.path.join(a.out, "gait_hidden.yaml")
    with open(hidden_scenario, "w") as f:
        f.write(SCENARIO.format(name="gait_hidden", duration=a.duration, plant=f"plant: {{effects: [{effect}]}}\n"))
    rec = exotwin.run(hidden_scenario, seed=2, out=os.path.join(a.out, "hidden"))
    record = os.path.join(a.out, "hidden", "measured.csv")
    print(f"hidden {a.effect} ({a.joint}) = {a.value} {a.unit}: record {record}")

    # 3. Diagnose the record against the rigid twin (the subject's model file).
    params = exotwin.data_path("examples/S1.yaml")
    d = exotwin.diagnose(params, [record], out=os.path.join(a.out, "diagnosis"))
    for e in d["effects"]:
        print(f"diagnose: {e['name']} ({e['joint']}) = {e['value']:.3g} {e['unit']} "
              f"[{e['ci95'][0]:.3g}, {e['ci95'][1]:.3g}]")
    if not d["effects"]:
        print("diagnose: no effect named")
    joints = ("hip", "knee")
    before = [d["joints"][j]["rmse_before"] for j in joints]
    after = [d["joints"][j]["rmse_after"] for j in joints]

    # 4. Replay both twins on the record: the angle each simulates from the measured torque.
    extended = os.path.join(a.out, "diagnosis", "extended.yaml")
    rigid_replay = exotwin.replay(params, [record])
    ext_replay = exotwin.replay(extended, [record])
    rmse_rigid = [rigid_replay["joints"][j]["rmse_rad"] for j in joints]
    rmse_ext = [ext_replay["joints"][j]["rmse_rad"] for j in joints]
    for k, j in enumerate(joints):
        print(f"replay {j}: rigid {np.degrees(rmse_rigid[k]):.3f} deg, extended {np.degrees(rmse_ext[k]):.3f} deg")

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    x = np.arange(2)
    ax[0].bar(x - 0.2, before, 0.4, label="rigid twin")
    ax[0].bar(x + 0.2, after, 0.4, label="extended twin")
    ax[0].set_xticks(x, joints)
    ax[0].set_ylabel("held-out torque RMSE (N m)")
    ax[0].set_title("diagnose: torque prediction")
    ax[0].legend()
    ax[1].bar(x - 0.2, np.degrees(rmse_rigid), 0.4, label="rigid twin")
    ax[1].bar(x + 0.2, np.degrees(rmse_ext), 0.4, label="extended twin")
    ax[1].set_xticks(x, joints)
    ax[1].set_ylabel("replayed angle RMSE (deg)")
    ax[1].set_title("replay: forward simulation")
    ax[1].legend()
    fig.tight_layout()
    fig.savefig(os.path.join(a.out, "diagnosis.png"), dpi=100)

    s_rigid, s_ext = rigid_replay["series"], ext_replay["series"]
    fig, ax = plt.subplots(figsize=(9, 4))
    n = min(len(s_rigid["t"]), 4000)
    ax.plot(s_rigid["t"][:n], np.degrees(s_rigid["q_knee"][:n]), "k", label="measured")
    ax.plot(s_rigid["t"][:n], np.degrees(s_rigid["q_knee_sim"][:n]), label="rigid twin (simulated)")
    ax.plot(s_ext["t"][:n], np.degrees(s_ext["q_knee_sim"][:n]), label="extended twin (simulated)")
    ax.set_xlabel("t (s)")
    ax.set_ylabel("knee (deg)")
    ax.set_title(f"replay, restarts every {rigid_replay['horizon_s']} s")
    ax.legend()
    fig.savefig(os.path.join(a.out, "replay.png"), dpi=100)

    # The measured leg at the rigid twin's worst replayed instant, with both twins' simulated legs as
    # ghosts (red: rigid, green: extended), as `exotwin render-replay --sim ... --sim ...` draws them.
    i = int(np.argmax(np.abs(s_rigid["q_knee_sim"] - s_rigid["q_knee"])))
    j = int(np.argmin(np.abs(s_ext["t"] - s_rigid["t"][i])))
    still = exotwin.render_frame(s_rigid["q_hip"][i], s_rigid["q_knee"][i],
                                 ghosts=[(s_rigid["q_hip_sim"][i], s_rigid["q_knee_sim"][i]),
                                         (s_ext["q_hip_sim"][j], s_ext["q_knee_sim"][j])],
                                 ghost_rgba=[(0.95, 0.1, 0.1, 0.45), (0.1, 0.8, 0.2, 0.45)])
    plt.imsave(os.path.join(a.out, "ghosts.png"), still)
    print(f"plots: {a.out}/tracking.png, {a.out}/frame.png, {a.out}/diagnosis.png, {a.out}/replay.png, "
          f"{a.out}/ghosts.png")


if __name__ == "__main__":
    main()
