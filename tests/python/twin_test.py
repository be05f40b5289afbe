# exotwin.Twin (python/module_twin.cc, runner/exowheel_runner.h ExowheelSession): stepped with the
# shipped controller it gives exotwin.run's bits; Python's commands reach the drivers through the
# safety supervisor; bad commands are clear errors; twins on threads are independent.
import json
import threading

import numpy as np
import pytest

import exotwin
from conftest import SOURCE, read_csv, same_bits, short_gait


def test_shipped_controller_gives_the_runs_bits(tmp):
    scenario = short_gait(tmp, duration=2.0)
    run = exotwin.run(scenario, seed=5, out=tmp / "run")
    twin = exotwin.Twin(scenario, seed=5, out=tmp / "twin")
    obs0 = twin.reset()
    assert list(obs0) == list(run.measured) == twin.observation_columns
    rows, truths = [], []
    while not twin.done:
        rows.append(twin.step())
        truths.append(twin.truth())
    assert len(rows) == 2000
    for name in run.measured:
        assert same_bits([r[name] for r in rows], run.measured[name]), name
    for name in run.truth:
        assert same_bits([r[name] for r in truths], run.truth[name]), name
    # the twin's files and result are the run's
    assert same_bits(read_csv(tmp / "twin" / "measured.csv")["tau_hip"], run.measured["tau_hip"])
    res = json.loads((tmp / "twin" / "result.json").read_text())
    assert res["metrics"]["tracking_rms_knee_deg"] == run.metrics["tracking_rms_knee_deg"]
    assert twin.result.metrics["frames"] == run.metrics["frames"]
    assert twin.result.passed == run.passed
    with pytest.raises(RuntimeError, match="the run is over"):
        twin.step()
    # reset() plays the same run again; reset(seed) another one
    again = twin.reset()
    assert list(again) == list(obs0) and same_bits(list(again.values()), list(obs0.values()))
    a = [twin.step()["tau_knee"] for _ in range(50)]
    assert same_bits(a, run.measured["tau_knee"][:50])
    twin.reset(seed=6)
    b = [twin.step()["tau_knee"] for _ in range(50)]
    assert not same_bits(a, b)


def test_python_commands_reach_the_drivers_through_the_supervisor(tmp):
    twin = exotwin.Twin(short_gait(tmp, duration=1.0), seed=1)
    assert twin.period == 1e-3 and twin.duration == 1.0
    for _ in range(5):
        twin.step()  # the joint modules' first status frames
    obs = twin.step(np.array([1.5, -2.0]))
    assert (obs["cmd_hip"], obs["cmd_knee"]) == (1.5, -2.0)
    assert twin.step(np.array([1, 2], dtype=np.int32))["cmd_knee"] == 2.0
    assert twin.step([0.25, 0.5])["cmd_hip"] == 0.25
    assert twin.step((0.75, 1))["cmd_knee"] == 1.0
    assert twin.step(np.array([1.0, -3.0], dtype=">f8"))["cmd_knee"] == -3.0  # another byte order
    assert twin.step(np.array([9.0, 0.5, 7.0, 0.25])[::2])["cmd_knee"] == 7.0  # strided
    # a Python PD law tracks the reference through the virtual hardware
    obs = twin.step()
    err = []
    while not twin.done:
        cmd = np.array([600 * (obs["ref_hip"] - obs["q_hip"]), 400 * (obs["ref_knee"] - obs["q_knee"])])
        obs = twin.step(cmd)
        err.append(obs["ref_knee"] - obs["q_knee"])
    assert np.sqrt(np.mean(np.square(err[200:]))) < np.radians(5)
    assert twin.result.metrics["safe_state_entered"] == 0


def test_torque_beyond_the_limit_is_the_supervisors_business(tmp):
    twin = exotwin.Twin(short_gait(tmp, duration=0.5), seed=1)
    for _ in range(5):
        twin.step()
    obs = twin.step(np.array([1e6, 0.0]))
    assert abs(obs["cmd_hip"]) <= twin.command_limit
    assert obs["state"] != 0 or abs(obs["cmd_hip"]) < 1e6


def test_bad_commands_are_clear_errors_and_change_nothing(tmp):
    twin = exotwin.Twin(short_gait(tmp, duration=0.5), seed=1)
    twin.step()
    t = twin.time
    for bad, kind, match in [(np.zeros(3), exotwin.InputError, r"shape \(2,\).*got shape \(3,\)"),
                             (np.zeros((2, 2)), exotwin.InputError, r"got shape \(2, 2\)"),
                             (np.zeros(2, dtype=complex), TypeError, "dtype complex128"),
                             (np.array(["a", "b"]), TypeError, "dtype <U1"),
                             (np.array([np.nan, 0.0]), exotwin.InputError, "cmd_hip is nan"),
                             (np.array([0.0, np.inf]), exotwin.InputError, "cmd_knee is inf"),
                             (object(), TypeError, "expected a"),
                             (5.0, exotwin.InputError, r"got shape \(\)"),
                             ([1.0, float("nan")], exotwin.InputError, "cmd_knee is nan"),
                             ((1.0, 2.0, 3.0), exotwin.InputError, r"got shape \(3,\)")]:
        with pytest.raises(kind, match=match):
            twin.step(bad)
        assert twin.time == t
    twin.step(np.zeros(2))
    assert twin.time > t


def test_twins_on_threads_are_independent(tmp):
    scenario = short_gait(tmp, duration=1.0)
    expected = {seed: exotwin.run(scenario, seed=seed).measured["tau_knee"] for seed in (1, 2, 3)}
    got = {}

    def drive(seed):
        twin = exotwin.Twin(scenario, seed=seed)
        rows = []
        while not twin.done:
            rows.append(twin.step()["tau_knee"])
        got[seed] = rows

    threads = [threading.Thread(target=drive, args=(s,)) for s in (1, 2, 3)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    for seed in expected:
        assert same_bits(got[seed], expected[seed]), seed


def test_devices_the_twin_does_not_step_are_named():
    with pytest.raises(exotwin.InputError, match="device hal3"):
        exotwin.Twin(SOURCE / "scenarios" / "hal3_exp1_no_assist.yaml")
    with pytest.raises(exotwin.InputError, match="no_such"):
        exotwin.Twin("no_such.yaml")
