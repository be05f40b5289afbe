# The commands as functions and the readers (python/module_commands.cc, python/exotwin/_api.py):
# the same numbers as the program's files, the CLI's error text.
import json
import shutil
import subprocess

import numpy as np
import pytest

import exotwin
from conftest import SOURCE, cli, read_csv, same_bits


@pytest.fixture
def record(tmp):
    """A 12 s record of S1 with a hidden Coulomb friction at the knee (exotwin generate, seed 3)."""
    params = exotwin.data_path("examples/S1.yaml")
    g = exotwin.generate(params, seed=3, out=tmp / "rec.csv", effects=1, effect="coulomb_friction",
                         joint="knee", duration=12)
    return params, tmp / "rec.csv", g


def test_generate_is_the_programs_record(tmp, record):
    params, path, g = record
    cli("generate", "--params", params, "--seed", 3, "--out", tmp / "cli.csv", "--effects", 1, "--effect",
        "coulomb_friction", "--joint", "knee", "--duration", 12, "--truth", tmp / "truth.yaml")
    ref = read_csv(tmp / "cli.csv")
    assert list(g["measured"]) == list(ref) and g["path"] == str(path)
    for name in ref:
        assert same_bits(g["measured"][name], ref[name]), name
    truth = exotwin.read_model(tmp / "truth.yaml")
    assert g["truth"]["effects"] == truth["effects"]
    assert [e["name"] for e in truth["effects"]] == ["coulomb_friction"] and truth["effects"][0]["joint"] == "knee"


def test_predict_and_replay_are_the_programs(tmp, record):
    params, path, _ = record
    p = exotwin.predict(params, path)
    cli("predict", "--params", params, "--measured", path, "--out", tmp / "pred.csv")
    ref = read_csv(tmp / "pred.csv")
    assert list(p) == ["t", "tau_hip", "tau_knee"]
    assert all(same_bits(p[c], ref[c]) for c in ref)

    r = exotwin.replay(params, [path], horizon=0.5, between_samples="hold")
    cli("replay", "--params", params, "--measured", path, "--horizon", 0.5, "--between-samples", "hold",
        "--out", tmp / "replay")
    ref_json = json.loads((tmp / "replay" / "replay.json").read_text())
    series = r.pop("series")
    assert r == ref_json and r["input_between_samples"] == "hold"
    ref_csv = read_csv(tmp / "replay" / "replay.csv")
    assert all(same_bits(series[c], ref_csv[c]) for c in ref_csv)

    q = exotwin.replay(params, [path], between_samples="hold", windows="quiet")
    cli("replay", "--params", params, "--measured", path, "--between-samples", "hold", "--windows", "quiet",
        "--out", tmp / "quiet")
    q.pop("series")
    assert q == json.loads((tmp / "quiet" / "replay.json").read_text()) and q["windows_schedule"] == "quiet"


def test_diagnose_names_the_hidden_effect(tmp, record):
    params, path, g = record
    d = exotwin.diagnose(params, [path], out=tmp / "d")
    on_disk = json.loads((tmp / "d" / "diagnosis.json").read_text())
    assert {k: v for k, v in d.items() if k not in ("extended", "out")} == on_disk
    assert d["out"] == str(tmp / "d")
    names = [(e["name"], e["joint"]) for e in d["effects"]]
    assert ("coulomb_friction", "knee") in names
    hidden = g["truth"]["effects"][0]["value"]
    e = d["effects"][names.index(("coulomb_friction", "knee"))]
    assert e["ci95"][0] <= hidden <= e["ci95"][1] or abs(e["value"] - hidden) < 0.1 * hidden
    assert d["extended"]["effects"][0]["name"] == "coulomb_friction"
    assert d["joints"]["knee"]["rmse_after"] < d["joints"]["knee"]["rmse_before"]
    with pytest.raises(exotwin.InputError, match="fit: expected one of torque, motion, got 'inverse'"):
        exotwin.diagnose(params, [path], fit="inverse")


def test_diagnose_motion_fit_is_the_programs(tmp, record):
    params, path, g = record
    d = exotwin.diagnose(params, [path], fit="motion", out=tmp / "m")
    cli("diagnose", "--params", params, "--measured", path, "--fit", "motion", "--out", tmp / "cli")
    on_disk = json.loads((tmp / "cli" / "diagnosis.json").read_text())
    assert on_disk["fit"] == "motion"
    assert {k: v for k, v in d.items() if k not in ("extended", "out")} == on_disk


def test_readers(tmp, record):
    params, path, g = record
    m = exotwin.read_measured(path)
    c = exotwin.read_csv(path)
    assert list(m)[:5] == ["t", "q_hip", "q_knee", "tau_hip", "tau_knee"]
    assert all(same_bits(m[k], c[k]) for k in m)
    model = exotwin.read_model(params)
    assert model["exo"]["J1"] == 3.02 and model["human"]["X1"] == 4.54 and model["passive"] == "riener1999"
    assert model["effects"] == [] and "exo:" in model["yaml"]
    sto = tmp / "m.sto"
    cli("run", exotwin.data_path("scenarios/faults/sensor_stuck.yaml"), "--out", tmp / "run", "--sto")
    s = exotwin.read_sto(tmp / "run" / "measured.sto")
    ref = read_csv(tmp / "run" / "measured.csv")
    assert same_bits(s["time"], ref["t"]) and same_bits(s["q_knee"], ref["q_knee"])
    del sto


def test_read_measured_takes_a_ros2_bag(tmp, record):
    # The record as a JointState bag written by Foxglove's libraries (tests/mcap_client) and as the CSV
    # of the bag's own times: read_measured gives the same bits from both (DESIGN.md "ROS 2 bags").
    client = SOURCE / "tests" / "mcap_client"
    if shutil.which("node") is None or not (client / "node_modules" / "@mcap" / "core").is_dir():
        pytest.skip("node or tests/mcap_client/node_modules missing (scripts/setup.sh)")
    _, path, _ = record
    subprocess.run(["node", "write_bag.mjs", "from-csv", str(path), str(tmp / "rec.mcap"), str(tmp / "bag.csv")],
                   cwd=client, check=True)
    (tmp / "map.yaml").write_text(
        "columns:\n  t: {from: /exo/joint_states.header.stamp}\n"
        "  q_hip: {from: \"/exo/joint_states.position[hip]\"}\n  q_knee: {from: \"/exo/joint_states.position[knee]\"}\n"
        "  tau_hip: {from: \"/exo/joint_states.effort[hip]\", sign: -1}\n"
        "  tau_knee: {from: \"/exo/joint_states.effort[knee]\", sign: -1}\n")
    bag = exotwin.read_measured(tmp / "rec.mcap", map=tmp / "map.yaml")
    csv = exotwin.read_measured(tmp / "bag.csv")
    assert list(bag) == ["t", "q_hip", "q_knee", "tau_hip", "tau_knee"]
    assert all(same_bits(bag[k], csv[k]) for k in bag)
    with pytest.raises(exotwin.InputError, match="a ROS 2 bag needs a column map"):
        exotwin.read_measured(tmp / "rec.mcap")


def test_bad_input_is_the_programs_text(tmp):
    p = cli("predict", "--params", tmp / "none.yaml", "--measured", tmp / "none.csv", "--out", tmp / "o.csv",
            check=False)
    assert p.returncode == 2
    with pytest.raises(exotwin.InputError) as e:
        exotwin.predict(tmp / "none.yaml", tmp / "none.csv")
    assert p.stderr.strip() == "exotwin: error: " + str(e.value)
    with pytest.raises(exotwin.InputError, match="--horizon"):
        exotwin.replay(exotwin.data_path("examples/S1.yaml"), [tmp / "none.csv"], horizon=-1)
    with pytest.raises(exotwin.InputError, match="measured: expected at least one path"):
        exotwin.diagnose(exotwin.data_path("examples/S1.yaml"), [])
    with pytest.raises(exotwin.InputError, match="no_such"):
        exotwin.read_measured(tmp / "no_such.csv")


def test_divergence_is_simulation_error_with_the_programs_text(tmp, record):
    # A user's MJCF whose knee spring (1e9 N m/rad on ~0.1 kg m^2: a mode of ~1e5 rad/s against the
    # 1 ms step) makes the explicit step blow up: the program exits 1 naming the time and MuJoCo's
    # warning; the function raises SimulationError (a RuntimeError) with the same text.
    params, path, _ = record
    shipped = exotwin.data_path("mjcf/leg_exowheel.xml")
    text = open(shipped).read()
    stiff = text.replace('<joint name="knee" type="hinge"', '<joint name="knee" type="hinge" stiffness="1e9"')
    assert stiff != text
    mjcf = tmp / "stiff_knee.xml"
    mjcf.write_text(stiff)
    p = cli("replay", "--params", params, "--measured", path, "--mjcf", mjcf, "--out", tmp / "r", check=False)
    assert p.returncode == 1
    with pytest.raises(exotwin.SimulationError) as e:
        exotwin.replay(params, [path], mjcf=mjcf)
    assert isinstance(e.value, RuntimeError)
    assert "diverged" in str(e.value) and "bad qacc" in str(e.value)
    assert p.stderr.strip().endswith(str(e.value)), (p.stderr, str(e.value))


def test_identify_is_the_programs(tmp):
    # the exoskeleton alone in the protocol's two configurations (scenarios/identification, cut to 10 s)
    records = []
    for step in ("step1_exo_knee", "step2_exo_hip"):
        text = open(exotwin.data_path(f"scenarios/identification/{step}.yaml")).read()
        text = text.replace("duration: 40, trials: 5", "duration: 10, trials: 1")
        assert "duration: 10, trials: 1" in text
        scenario = tmp / f"{step}.yaml"
        scenario.write_text(text)
        exotwin.run(scenario, out=tmp / step)
        records.append(tmp / step / "measured.csv")
    m = exotwin.identify(records, out=tmp / "py.yaml", L1=0.41)
    cli("identify", "--measured", records[0], "--measured", records[1], "--L1", 0.41, "--out", tmp / "cli.yaml")
    ref = exotwin.read_model(tmp / "cli.yaml")
    assert m == ref and m["human"] is None
    assert m["exo"]["J1"] == pytest.approx(3.01, rel=0.05)  # the scenarios' exoskeleton (Table 3 mean)
    assert (tmp / "py.yaml").read_text() == (tmp / "cli.yaml").read_text()


def test_terms_are_read_written_and_hidden(tmp):
    """A model file's terms (DESIGN.md "Terms beyond the table"): expr and stage in read_model's effects
    and in its yaml; generate hides one, the same record as the program's generate --term."""
    params = exotwin.data_path("examples/S1.yaml")
    g = exotwin.generate(params, seed=5, out=tmp / "rec.csv", joint="knee", duration=4,
                         term=["abs(tau_R) * sgn(qd)", "tau_R * abs(tau_R)"], value=[0.06, -0.0016],
                         stage=["link", "sensor"])
    effects = g["truth"]["effects"]
    assert [e["name"] for e in effects] == ["term", "term"]
    assert effects[0]["expr"] == "abs(tau_R) * sgn(qd)" and "stage" not in effects[0]
    assert effects[1]["expr"] == "tau_R * abs(tau_R)" and effects[1]["stage"] == "sensor"
    assert effects[1]["value"] == -0.0016 and effects[0]["joint"] == "knee"
    cli("generate", "--params", params, "--seed", 5, "--out", tmp / "cli.csv", "--joint", "knee", "--duration", 4,
        "--term", "abs(tau_R) * sgn(qd)", "--value", 0.06, "--term", "tau_R * abs(tau_R)", "--value", -0.0016,
        "--stage", "link", "--stage", "sensor")
    ref = read_csv(tmp / "cli.csv")
    for name in ref:
        assert same_bits(g["measured"][name], ref[name]), name
    # The yaml written back reads as the same model.
    (tmp / "again.yaml").write_text(g["truth"]["yaml"])
    again = exotwin.read_model(tmp / "again.yaml")
    assert again["effects"] == effects
    # A bad expression: the program's exit 2 text, naming the position.
    with pytest.raises(Exception, match="position 17"):
        exotwin.generate(params, seed=5, joint="knee", duration=4, term="abs(tau_R) * sgn(qdx)", value=1.0)
