# Fixtures of the Python module's tests (tests/python/*_test.py, run by ctest as python.<file>: see
# tests/CMakeLists.txt, which sets PYTHONPATH to the build tree's package, EXOTWIN_BIN and
# EXOTWIN_SOURCE_DIR). Temporary folders are removed after each test (the suite leaves nothing
# behind in TMPDIR; pytest's own tmp_path would keep them).
import csv
import os
import pathlib
import subprocess
import tempfile

import numpy as np
import pytest

SOURCE = pathlib.Path(os.environ.get("EXOTWIN_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
EXOTWIN_BIN = os.environ.get("EXOTWIN_BIN", str(SOURCE / "build" / "app" / "exotwin"))


@pytest.fixture
def tmp():
    with tempfile.TemporaryDirectory(prefix="exotwin_pytest_") as d:
        yield pathlib.Path(d)


def short_gait(folder, duration=3.0, trials=1, extra=""):
    """gait_2kmh.yaml cut to `duration` s per trial (the same subject, controller, hardware, checks)."""
    text = (SOURCE / "scenarios" / "gait_2kmh.yaml").read_text()
    text = text.replace("duration: 60, trials: 1", f"duration: {duration}, trials: {trials}")
    assert f"duration: {duration}" in text
    path = pathlib.Path(folder) / f"gait_{duration}s_{trials}.yaml"
    path.write_text(text + extra)
    return path


def cli(*args, check=True):
    """Runs the exotwin program; returns the CompletedProcess (text)."""
    p = subprocess.run([EXOTWIN_BIN, *map(str, args)], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"exotwin {' '.join(map(str, args))}: exit {p.returncode}\n{p.stderr}")
    return p


def read_csv(path):
    """A CSV the program wrote as {column: float64 array} (Python's float() reads the shortest text back
    to the same double)."""
    with open(path) as f:
        rows = [r for r in csv.reader(line for line in f if not line.startswith("#"))]
    names, body = rows[0], rows[1:]
    return {n: np.array([float(r[i]) for r in body]) for i, n in enumerate(names)}


def same_bits(a, b):
    a, b = np.ascontiguousarray(a, dtype=np.float64), np.ascontiguousarray(b, dtype=np.float64)
    return a.shape == b.shape and np.array_equal(a.view(np.uint64), b.view(np.uint64))
