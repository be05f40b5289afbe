"""exotwin from Python: the digital twin of a leg in a rehabilitation exoskeleton.

The same C++ layers as the command line (DESIGN.md "Python module"); results as dicts and NumPy
arrays whose columns are named as in the CSV files the command line writes.

    import exotwin
    r = exotwin.run("scenarios/gait_2kmh.yaml", seed=1)
    r.metrics["tracking_rms_knee_deg"], r.measured["q_knee"]

Errors: exotwin.InputError (a ValueError; the text the command line prints before exit 2) and
exotwin.SimulationError (the simulation diverged).
"""
import os as _os
import pathlib as _pathlib


def _locate_shipped_files():
    # core/data_dir.h finds the data folder next to the running program (P/bin/../share/exotwin); the
    # program here is the interpreter, so the package says where it is: P/share/exotwin, P being four
    # folders above this file (P/lib/python3/dist-packages/exotwin, installed and in the build tree).
    # Likewise the rendering plugin (render/render_plugin.h looks beside the program): P/lib/exotwin
    # installed, P/app in the build tree.
    prefix = _pathlib.Path(__file__).resolve().parent.parents[3]
    data = prefix / "share" / "exotwin"
    if not _os.environ.get("EXOTWIN_DATA_DIR") and data.is_dir():
        _os.environ["EXOTWIN_DATA_DIR"] = str(data)
    if not _os.environ.get("EXOTWIN_RENDER_PLUGIN"):
        for plugin in (prefix / "lib" / "exotwin", prefix / "app"):
            if (plugin / "libexotwin_render_plugin.so").is_file():
                _os.environ["EXOTWIN_RENDER_PLUGIN"] = str(plugin / "libexotwin_render_plugin.so")
                break


_locate_shipped_files()

from . import _exotwin  # noqa: E402
from ._exotwin import InputError, SimulationError, data_dir  # noqa: E402,F401
from ._api import (RunResult, Twin, data_path, diagnose, emg_fit, emg_predict, generate, identify, predict,  # noqa: E402,F401
                   read_csv, read_measured, read_model, read_sto, render_frame, replay, run)
from .env import Box, ExoEnv  # noqa: E402,F401

__all__ = ["Box", "ExoEnv", "InputError", "RunResult", "SimulationError", "Twin", "data_dir", "data_path", "diagnose",
           "emg_fit", "emg_predict", "generate", "identify", "predict", "read_csv", "read_measured", "read_model",
           "read_sto", "render_frame", "replay", "run"]
