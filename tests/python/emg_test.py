# exotwin.emg_fit / emg_predict (python/exotwin/_api.py over `exotwin emg-fit` / `emg-predict`): the
# program's model file and prediction, bit for bit, on OpenSim recordings written here (the synthetic
# recording of tests/app/emg_cli_test.cc: CEINMS-style envelopes, IK angles, ID moments that are a
# linear function of them).
import math

import pytest

import exotwin
from conftest import cli, read_csv, same_bits

ROWS = 2000  # 20 s at 100 Hz


def env(c, t):
    s = math.sin(2 * math.pi * (0.8 + 0.17 * c) * t + c) + 0.4 * math.sin(2 * math.pi * 0.11 * (c + 1) * t)
    return 0.02 + 0.25 * max(0.0, s) ** 2


def hip(t):
    return 20 * math.sin(2 * math.pi * 0.9 * t) + 5  # deg


def knee(t):
    return -35 - 25 * math.sin(2 * math.pi * 0.9 * t + 1)  # deg


def write_recording(d):
    with open(d / "emg.sto", "w") as f:
        f.write(f"Normalized EMG Linear Envelopes\nnRows={ROWS}\nnColumns=6\n\nendheader\n"
                "time\t  rect_fem_r\t vas_lat_r\t semimem_r\t med_gas_r\t soleus_r\t\n")
        for i in range(ROWS):
            t = 0.01 * i
            f.write(f"{t!r}" + "".join(f"\t  {env(c, t):.6f}" for c in range(5)) + "\t\n")
    with open(d / "ik.sto", "w") as f:
        f.write(f"Coordinates\nversion=1\nnRows={ROWS}\nnColumns=3\ninDegrees=yes\nendheader\n"
                "time\thip_flexion_r\tknee_angle_r\n")
        for i in range(ROWS):
            t = 0.01 * i
            f.write(f"{t!r}\t{hip(t)!r}\t{knee(t)!r}\n")
    with open(d / "id.sto", "w") as f:
        f.write(f"Inverse Dynamics Generalized Forces\nversion=1\nnRows={ROWS}\nnColumns=3\ninDegrees=no\n"
                "endheader\ntime\thip_flexion_r_moment\tknee_angle_r_moment\n")
        for i in range(ROWS):
            t = 0.01 * i
            h = 50 * env(0, t) - 60 * env(2, t) - 0.2 * hip(t) + 3 + 0.5 * math.sin(37.0 * i)
            k = 80 * env(1, t) + 20 * env(0, t) - 30 * env(2, t) - 40 * env(3, t) + 0.1 * knee(t) + 0.5 * math.cos(41.0 * i)
            f.write(f"{t!r}\t{h!r}\t{k!r}\n")
    return d / "emg.sto", d / "ik.sto", d / "id.sto"


def test_emg_fit_and_predict_are_the_programs(tmp):
    emg, ik, mom = write_recording(tmp)
    m = exotwin.emg_fit([emg], [ik], [mom], out=tmp / "py.yaml")
    cli("emg-fit", "--emg", emg, "--kinematics", ik, "--moments", mom, "--out", tmp / "cli.yaml")
    assert m["yaml"] == (tmp / "cli.yaml").read_text() and m["path"] == str(tmp / "py.yaml")
    p = exotwin.emg_predict(tmp / "py.yaml", emg, ik, moments=mom)
    cli("emg-predict", "--model", tmp / "cli.yaml", "--emg", emg, "--kinematics", ik, "--out", tmp / "cli.csv")
    ref = read_csv(tmp / "cli.csv")
    assert list(p) == ["t", "tau_hip", "tau_knee"] == list(ref)
    assert all(same_bits(p[c], ref[c]) for c in ref)
    s = exotwin.read_sto(ik)
    assert s["knee_angle_r"][0] == pytest.approx(knee(0.0))  # read as written: degrees stay degrees
    with pytest.raises(exotwin.InputError, match="no_such.sto"):
        exotwin.emg_predict(tmp / "py.yaml", tmp / "no_such.sto", ik)
