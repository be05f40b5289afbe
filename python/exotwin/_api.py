"""The commands as functions (exotwin.run, ...): argument checks and result objects around the
extension's calls (python/module*.cc)."""
import json
import os
import signal
import tempfile

from . import _exotwin
from ._exotwin import InputError


def _path(value, what):
    """A path argument (str or os.PathLike) as str; InputError otherwise."""
    try:
        return os.fspath(value)
    except TypeError:
        raise InputError(f"{what}: expected a path (str or os.PathLike), got {type(value).__name__}") from None


def _seed(value, what="seed"):
    """None, or a seed as the command line takes it (an integer 0 .. 2**64-1); InputError otherwise."""
    if value is None:
        return None
    if isinstance(value, bool) or not hasattr(value, "__index__"):
        raise InputError(f"{what}: expected an integer 0 .. 2**64-1, got {value!r}")
    v = value.__index__()
    if not 0 <= v < 2**64:
        raise InputError(f"{what}: expected an integer 0 .. 2**64-1, got {v}")
    return v


class RunResult:
    """What `exotwin run` reports and writes, in memory.

    scenario, seed; metrics: {name: float} (result.json's); checks: [{name, metric, op, passed, value,
    limit}]; events: fault events ("t=... type joint"); files: the files written (in `out`);
    interrupted: None, or {signal, name, t_s, trial} when a stop request ended the run;
    logs: {file name: {column: array}} for every measured/truth CSV the run wrote;
    measured, truth: the first trial's measured.csv / truth.csv as {column: float64 array} ({} when the
    scenario logs none). The arrays of a log are views of one (rows, columns) buffer.
    """

    def __init__(self, d):
        self.scenario = d["scenario"]
        self.seed = d["seed"]
        self.metrics = d["metrics"]
        self.checks = d["checks"]
        self.events = d["events"]
        self.files = d["files"]
        self.interrupted = d["interrupted"]
        self.logs = d["logs"]
        self.measured = self._first("measured")
        self.truth = self._first("truth")

    def _first(self, kind):
        for name in (f"{kind}.csv", f"{kind}_trial1.csv"):
            if name in self.logs:
                return self.logs[name]
        return {}

    @property
    def passed(self):
        """True when every check passed (`exotwin run` exits 0)."""
        return self.interrupted is None and all(c["passed"] for c in self.checks)

    def __repr__(self):
        n = len(next(iter(self.measured.values()))) if self.measured else 0
        state = "interrupted" if self.interrupted else ("passed" if self.passed else "failed")
        return f"<exotwin.RunResult {self.scenario} seed {self.seed}: {state}, {n} samples>"


def _raise_if_interrupted(result):
    """As `exotwin run` on SIGINT / SIGTERM: the logs so far are kept (in `result` and on disk);
    SIGINT raises KeyboardInterrupt carrying the result (its .result), SIGTERM goes on to the
    interpreter's own handler."""
    if result.interrupted is None:
        return
    sig = result.interrupted["signal"]
    if sig == signal.SIGTERM:
        os.kill(os.getpid(), signal.SIGTERM)
    e = KeyboardInterrupt(f"exotwin: interrupted by {result.interrupted['name']} at t = "
                          f"{result.interrupted['t_s']:.3f} s (trial {result.interrupted['trial']})")
    e.result = result
    raise e


def run(scenario, seed=None, out=None, mcap=None):
    """Runs a scenario as `exotwin run SCENARIO [--seed N] [--out DIR] [--mcap FILE]` does, bit for bit.

    scenario: the scenario file; seed: overrides the scenario's; out: the folder for result.json and
    the logs (None: a temporary folder, removed afterwards; the logs stay in the result); mcap: a file
    to write the run's logs to as a ROS 2 bag (None: none; kept when out is None).
    Returns a RunResult. Releases the interpreter's lock while it runs; Ctrl-C ends the run at a step's
    end and raises KeyboardInterrupt with the partial result as its `.result`.
    Raises InputError (bad scenario, a check naming an unknown metric) and SimulationError.
    """
    scenario = _path(scenario, "scenario")
    seed = _seed(seed)
    mcap = "" if mcap is None else _path(mcap, "mcap")
    if out is not None:
        result = RunResult(_exotwin._run(scenario, seed, _path(out, "out"), mcap))
    else:
        with tempfile.TemporaryDirectory(prefix="exotwin_run_") as tmp:
            result = RunResult(_exotwin._run(scenario, seed, tmp, mcap))
        result.files = [mcap] if mcap else []
    _raise_if_interrupted(result)
    return result


class Twin(_exotwin._Twin):
    """The EXOwheel twin stepped one controller period at a time, Python in the controller's place.

    twin = Twin(scenario, seed=None, out=None); obs = twin.reset(seed=None); obs = twin.step(command=None)

    Each step advances one controller period (1 / controller.rate_hz) through the virtual hardware: the
    CAN bus's timing and faults, the encoders, torque sensors and EMG amplifier, the drivers, the
    scenario's fault injection, and the controller's estimator and safety supervisor. `command`: a numpy
    array of the two joint torque commands (N m; cmd_hip, cmd_knee), which replaces the shipped
    controller's control law at that period's tick (the safety supervisor still vetoes and limits it);
    None: the shipped controller acts and Python only observes (the same bits as exotwin.run).
    obs: the row measured.csv logs at the period's end, {column: float} (observation_columns).
    twin.truth(): the plant's row of truth.csv at that instant. twin.done: every trial ran; then
    twin.result holds the run's metrics and checks (a RunResult without logs).
    reset(seed): starts the run again (seed None: the last seed given, else the scenario's).
    out: None, no files; a folder: result.json and the logs there, as exotwin.run writes them.
    Several twins run in parallel on threads (step releases the interpreter's lock).
    """

    def __init__(self, scenario, seed=None, out=None):
        scenario = _path(scenario, "scenario")
        seed = _seed(seed)
        if out is None:
            self._tmp = tempfile.TemporaryDirectory(prefix="exotwin_twin_")
            super().__init__(scenario, seed, self._tmp.name, False)
        else:
            super().__init__(scenario, seed, _path(out, "out"), True)

    def reset(self, seed=None):
        return super().reset(_seed(seed))

    @property
    def result(self):
        r = super().result
        return None if r is None else RunResult(r)


# --- the other commands: `exotwin <command> ...` run in this process (app/'s commands, the same
# options, checks, files and messages), their files read back through the project's readers.

def _paths(value, what):
    """One path or a list of paths, as a list of str."""
    if isinstance(value, (str, bytes, os.PathLike)):
        return [_path(value, what)]
    try:
        items = list(value)
    except TypeError:
        raise InputError(f"{what}: expected a path or a list of paths, got {type(value).__name__}") from None
    if not items:
        raise InputError(f"{what}: expected at least one path")
    return [_path(v, what) for v in items]


def _args(command, options):
    """`command` and its options: (flag, value) pairs; None is left out, True is the bare flag, a list
    repeats the flag."""
    args = [command]
    for flag, value in options:
        if value is None or value is False:
            continue
        if value is True:
            args.append(flag)
        elif isinstance(value, (list, tuple)):
            for v in value:
                args += [flag, str(v)]
        else:
            args += [flag, os.fspath(value) if isinstance(value, os.PathLike) else str(value)]
    return args


class _Out:
    """The folder a command writes into: `out`, or a temporary one removed on exit."""

    def __init__(self, out, prefix):
        self.out, self.prefix, self.tmp = out, prefix, None

    def __enter__(self):
        if self.out is not None:
            path = _path(self.out, "out")
            os.makedirs(path, exist_ok=True)
            return path
        self.tmp = tempfile.TemporaryDirectory(prefix=f"exotwin_{self.prefix}_")
        return self.tmp.name

    def __exit__(self, *exc):
        if self.tmp is not None:
            self.tmp.cleanup()


def _command(args):
    rc = _exotwin._command(args)
    if rc != 0:
        raise RuntimeError(f"exotwin {' '.join(args)}: exit code {rc}")


def _json(path):
    with open(path) as f:
        return json.load(f)


def data_path(rel):
    """A file of the shipped data folder (exotwin.data_dir()): data_path("scenarios/gait_2kmh.yaml")."""
    return os.path.join(_exotwin.data_dir(), rel)


def render_frame(q_hip, q_knee, params=None, ghosts=(), ghost_rgba=None, width=640, height=480):
    """The leg of a model file (default: subject S1 in the EXOwheel, examples/S1.yaml; the exoskeleton
    alone for a file without `human:`) at the hip and knee angles (rad), rendered off-screen as the
    videos show it (side view, no overlays), with translucent ghost legs at `ghosts` ((hip, knee) pairs,
    rad: e.g. a replay's simulated angles, as render-replay draws them; ghost_rgba: one (r, g, b, a) in
    0..1 per ghost, default translucent red): a (height, width, 3) uint8 RGB array (plt.imshow shows
    it). Loads the rendering plugin at the first call."""
    params = data_path("examples/S1.yaml") if params is None else _path(params, "params")
    try:
        pairs = [(float(h), float(k)) for h, k in ghosts]
    except (TypeError, ValueError):
        raise InputError(f"render_frame: ghosts: expected (q_hip, q_knee) pairs in rad, got {ghosts!r}") from None
    try:
        colours = [tuple(float(v) for v in c) for c in (ghost_rgba or [])]
    except (TypeError, ValueError):
        raise InputError(f"render_frame: ghost_rgba: expected (r, g, b, a) per ghost, got {ghost_rgba!r}") from None
    if any(len(c) != 4 for c in colours):
        raise InputError(f"render_frame: ghost_rgba: expected (r, g, b, a) per ghost, got {ghost_rgba!r}")
    return _exotwin._render_frame(float(q_hip), float(q_knee), params, pairs, colours, int(width), int(height))


def read_csv(path):
    """Any numeric CSV through the project's reader (formats/csv_table.h): {column: float64 array}."""
    return _exotwin._read_csv(_path(path, "path"))


def read_measured(path, map=None):
    """A measured-data record as predict / diagnose / replay read it (formats/column_map.h ReadMeasured,
    with a column map YAML for a foreign CSV or a ROS 2 bag: an .mcap file or a rosbag2 folder):
    {column: float64 array}, the schema's names."""
    return _exotwin._read_measured(_path(path, "path"), "" if map is None else _path(map, "map"))


def read_sto(path):
    """An OpenSim storage file (.sto / .mot; formats/opensim_storage.h): {column: float64 array}, `time`
    included, values as in the file (degrees stay degrees)."""
    return _exotwin._read_sto(_path(path, "path"))


def read_model(path):
    """A model file (MODEL.yaml; formats/model_file.h): {L1, g, exo, human, passive, effects[, one_joint],
    yaml (the model as the project writes it)}."""
    return _exotwin._read_model(_path(path, "path"))


def generate(params, seed, out=None, effects=None, effect=None, joint=None, duration=None, rate=None,
             clean=False, term=None, value=None, stage=None):
    """`exotwin generate`: a synthetic record of the twin with hidden effects. Returns {"measured":
    {column: array}, "truth": the model with the hidden effects (read_model), "path": the CSV (None
    without out)}. out: the CSV to write (None: a temporary file). term, value, stage: terms beyond the
    table hidden at `joint` (DESIGN.md "Terms beyond the table"): an expression or a list of them, with
    their values (N m) and stages (link or sensor) in the same order."""
    with _Out(None, "generate") as tmp:
        csv_path = _path(out, "out") if out is not None else os.path.join(tmp, "measured.csv")
        truth = os.path.join(tmp, "truth.yaml")
        _command(_args("generate", [("--params", _path(params, "params")), ("--seed", _seed(seed)),
                                    ("--out", csv_path), ("--effects", effects),
                                    ("--effect", [effect] if isinstance(effect, str) else effect),
                                    ("--joint", joint), ("--duration", duration), ("--rate", rate),
                                    ("--truth", truth), ("--clean", bool(clean)),
                                    ("--term", [term] if isinstance(term, str) else term),
                                    ("--value", [value] if isinstance(value, (int, float)) else value),
                                    ("--stage", [stage] if isinstance(stage, str) else stage)]))
        return {"measured": read_measured(csv_path), "truth": read_model(truth),
                "path": csv_path if out is not None else None}


def predict(params, measured, out=None, map=None, side=None, cutoff=None, mjcf=None):
    """`exotwin predict`: the torque-sensor reading the twin predicts for the measured kinematics.
    Returns {column: array} (t, tau_hip, tau_knee)."""
    with _Out(None, "predict") as tmp:
        path = _path(out, "out") if out is not None else os.path.join(tmp, "predicted.csv")
        _command(_args("predict", [("--params", _path(params, "params")), ("--measured", _path(measured, "measured")),
                                   ("--out", path), ("--map", map), ("--side", side), ("--cutoff", cutoff),
                                   ("--mjcf", mjcf)]))
        return read_csv(path)


# diagnose's fits in this build (DESIGN.md: torque|motion): `exotwin diagnose --fit` is passed for any
# but the default, so a build whose CLI has `--fit motion` needs only "motion" added here.
_FITS = ("torque", "motion")


def diagnose(params, measured, fit="torque", out=None, holdout=None, map=None, cutoff=None, max_effects=None,
             mjcf=None):
    """`exotwin diagnose`: what the twin gets wrong on the records, the effects that explain it, the
    extended model and its gain on held-out data. measured: one path or a list (one device, several
    records). Returns diagnosis.json as a dict, plus "extended" (extended.yaml, read_model) and "out"."""
    if fit not in _FITS:
        raise InputError(f"diagnose: fit: expected one of {', '.join(_FITS)}, got {fit!r}")
    with _Out(out, "diagnose") as d:
        _command(_args("diagnose", [("--params", _path(params, "params")),
                                    ("--measured", _paths(measured, "measured")), ("--out", d),
                                    ("--fit", None if fit == "torque" else fit), ("--holdout", holdout), ("--map", map), ("--cutoff", cutoff),
                                    ("--max-effects", max_effects), ("--mjcf", mjcf)]))
        result = _json(os.path.join(d, "diagnosis.json"))
        result["extended"] = read_model(os.path.join(d, "extended.yaml"))
        result["out"] = d if out is not None else None
        return result


def replay(params, measured, out=None, map=None, input=None, horizon=None, cutoff=None, mjcf=None,
           between_samples=None, windows=None):
    """`exotwin replay`: the twin (its effects in the plant) simulated forward on the records from the
    measured state every horizon s (windows="quiet": the motion fit's quiet windows). Returns
    replay.json as a dict plus "series": replay.csv as {column: array} (t, q_*, q_*_sim, window, record)."""
    with _Out(out, "replay") as d:
        _command(_args("replay", [("--params", _path(params, "params")),
                                  ("--measured", _paths(measured, "measured")), ("--out", d), ("--map", map),
                                  ("--input", input), ("--between-samples", between_samples),
                                  ("--windows", windows), ("--horizon", horizon), ("--cutoff", cutoff),
                                  ("--mjcf", mjcf)]))
        result = _json(os.path.join(d, "replay.json"))
        result["series"] = read_csv(os.path.join(d, "replay.csv"))
        return result


def identify(measured, out=None, known=None, map=None, L1=None, passive=None, cutoff=None, trim=None,
             friction=False):
    """`exotwin identify`: the four-step least squares (HJ15) on the two configurations' records.
    Returns the identified model (read_model; its yaml holds the identification block)."""
    with _Out(None, "identify") as tmp:
        path = _path(out, "out") if out is not None else os.path.join(tmp, "model.yaml")
        _command(_args("identify", [("--measured", _paths(measured, "measured")), ("--out", path),
                                    ("--known", known), ("--map", map), ("--L1", L1), ("--passive", passive),
                                    ("--cutoff", cutoff), ("--trim", trim), ("--friction", bool(friction))]))
        return read_model(path)


def emg_fit(emg, kinematics, moments, out=None, map=None, report=None, linear=False):
    """`exotwin emg-fit`: the EMG-to-moment calibration of hip and knee from OpenSim recordings (lists
    in step). Returns {"yaml": EMGMODEL.yaml's text, "path": out or None, "report": the report's
    diagnosis.json (dict) when report is given}."""
    with _Out(None, "emg_fit") as tmp:
        path = _path(out, "out") if out is not None else os.path.join(tmp, "emg_model.yaml")
        _command(_args("emg-fit", [("--emg", _paths(emg, "emg")), ("--kinematics", _paths(kinematics, "kinematics")),
                                   ("--moments", _paths(moments, "moments")), ("--out", path), ("--map", map),
                                   ("--report", report), ("--linear", bool(linear))]))
        with open(path) as f:
            result = {"yaml": f.read(), "path": path if out is not None else None}
        if report is not None and os.path.exists(os.path.join(report, "diagnosis.json")):
            result["report"] = _json(os.path.join(report, "diagnosis.json"))
        return result


def emg_predict(model, emg, kinematics, moments=None, map=None, out=None):
    """`exotwin emg-predict`: the hip and knee moments an EMG model estimates for a recording.
    Returns {column: array} (t, tau_hip, tau_knee)."""
    with _Out(None, "emg_predict") as tmp:
        path = _path(out, "out") if out is not None else os.path.join(tmp, "emg_predicted.csv")
        _command(_args("emg-predict", [("--model", _path(model, "model")), ("--emg", _path(emg, "emg")),
                                       ("--kinematics", _path(kinematics, "kinematics")), ("--moments", moments),
                                       ("--map", map), ("--out", path)]))
        return read_csv(path)
