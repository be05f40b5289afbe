# exotwin.run (python/module_run.cc, python/exotwin/_api.py): the same bits as `exotwin run`, the logs
# as views of one buffer, the CLI's error text, Ctrl-C.
import json
import os
import signal
import threading

import numpy as np
import pytest

import exotwin
from conftest import cli, read_csv, same_bits, short_gait


def test_run_is_bit_identical_to_the_cli(tmp):
    scenario = short_gait(tmp, duration=3.0)
    cli("run", scenario, "--seed", 7, "--out", tmp / "cli")
    r = exotwin.run(scenario, seed=7, out=tmp / "py")
    assert r.seed == 7 and r.scenario == "gait_2kmh"
    for log, columns in (("measured.csv", r.measured), ("truth.csv", r.truth)):
        ref = read_csv(tmp / "cli" / log)
        assert list(columns) == list(ref), log
        assert len(ref["t"]) == 3000
        for name in ref:
            assert same_bits(columns[name], ref[name]), f"{log}: {name}"
        # the module's own files are the CLI's, byte for byte (after the comment naming the run)
        strip = lambda p: [l for l in open(p) if not l.startswith("#")]  # noqa: E731
        assert strip(tmp / "py" / log) == strip(tmp / "cli" / log)
    res = json.loads((tmp / "cli" / "result.json").read_text())
    for k, v in res["metrics"].items():
        if k != "wall_time_s":
            assert r.metrics[k] == v, k
    assert [(c["name"], c["passed"], c["value"]) for c in r.checks] == \
           [(c["name"], c["passed"], c["value"]) for c in res["checks"]]
    assert r.events == res["events"] and r.interrupted is None and r.passed


def test_seed_changes_the_bits_and_the_same_seed_repeats_them(tmp):
    scenario = short_gait(tmp, duration=1.0)
    a, b, c = exotwin.run(scenario, seed=1), exotwin.run(scenario, seed=1), exotwin.run(scenario, seed=2)
    assert same_bits(a.measured["tau_knee"], b.measured["tau_knee"])
    assert not same_bits(a.measured["tau_knee"], c.measured["tau_knee"])
    assert a.files == []  # out=None: a temporary folder, removed


def test_logs_are_views_of_one_buffer_per_log(tmp):
    r = exotwin.run(short_gait(tmp, duration=1.0), seed=3)
    cols = list(r.measured.values())
    base = cols[0].base
    assert base is not None and all(c.base is base for c in cols)
    assert base.shape == (1000, len(cols)) and base.dtype == np.float64
    assert all(np.shares_memory(c, base) for c in cols)
    assert r.truth["t"].base is not base  # one buffer per log


def test_trials_each_have_their_logs(tmp):
    r = exotwin.run(short_gait(tmp, duration=0.5, trials=2), seed=1, out=tmp / "o")
    assert set(r.logs) == {"measured_trial1.csv", "truth_trial1.csv", "measured_trial2.csv", "truth_trial2.csv"}
    assert r.measured is r.logs["measured_trial1.csv"]
    ref = read_csv(tmp / "o" / "measured_trial2.csv")
    assert same_bits(r.logs["measured_trial2.csv"]["q_knee"], ref["q_knee"])


def test_bad_input_is_the_cli_text(tmp):
    bad = tmp / "bad.yaml"
    bad.write_text("name: x\ndevice: exowheel\nprotocol: {duration: -1}\n")
    p = cli("run", bad, "--out", tmp / "cli", check=False)
    assert p.returncode == 2
    with pytest.raises(exotwin.InputError) as e:
        exotwin.run(bad, out=tmp / "py")
    assert isinstance(e.value, ValueError)
    assert p.stderr.strip() == "exotwin: error: " + str(e.value)
    with pytest.raises(exotwin.InputError, match="no_such.yaml"):
        exotwin.run(tmp / "no_such.yaml")
    for seed in (-1, 2**64, "1", 1.5, True):
        with pytest.raises(exotwin.InputError, match="seed"):
            exotwin.run(bad, seed=seed)
    with pytest.raises(exotwin.InputError, match="scenario"):
        exotwin.run(42)


def test_ctrl_c_stops_the_run_and_keeps_what_was_logged(tmp):
    # 600 s of gait run in ~6 s of wall time on an idle machine: the Ctrl-C at 0.5 s falls inside it
    # (60 s took ~0.6 s: it could end before the signal came).
    duration = 600.0
    scenario = short_gait(tmp, duration=duration)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as e:
            exotwin.run(scenario, seed=1, out=tmp / "o")
    finally:
        timer.cancel()
    r = e.value.result
    assert r.interrupted["name"] == "SIGINT" and 0 < r.interrupted["t_s"] < duration
    n = len(r.measured["t"])
    assert 0 < n < 1000 * duration and r.measured["t"][-1] == pytest.approx(r.interrupted["t_s"])
    assert len(read_csv(tmp / "o" / "measured.csv")["t"]) == n  # the file holds what was logged
    assert not any(c["passed"] for c in r.checks)
    # the interpreter's handler is back: the next Ctrl-C is an ordinary KeyboardInterrupt
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
    with pytest.raises(KeyboardInterrupt):
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(10**7):
            pass
    # and a stop request does not outlive its run
    assert exotwin.run(short_gait(tmp, duration=0.2), seed=1).interrupted is None


def test_mcap_is_the_cli_bag_byte_for_byte(tmp):
    # exotwin.run(..., mcap=) writes the bag `exotwin run --mcap` writes (DESIGN.md "ROS 2 bags (MCAP)
    # in and out"; read back by Foxglove's libraries in tests/cli/mcap_write_test.sh), kept with out=None.
    scenario = short_gait(tmp, duration=1.0)
    cli("run", scenario, "--seed", 4, "--out", tmp / "cli", "--mcap", tmp / "cli.mcap")
    r = exotwin.run(scenario, seed=4, mcap=tmp / "py.mcap")
    assert r.files == [str(tmp / "py.mcap")]
    assert (tmp / "py.mcap").read_bytes() == (tmp / "cli.mcap").read_bytes()
    with pytest.raises(exotwin.InputError, match="is a folder"):
        exotwin.run(scenario, seed=4, mcap=tmp)
