# examples/python/first_steps.py, run as a user runs it (a script, Debian's python3), on 12 s of gait:
# it names the hidden effect, the extended twin replays closer than the rigid one, the plots exist.
import os
import re
import subprocess
import sys

from conftest import SOURCE


def test_first_steps(tmp):
    p = subprocess.run([sys.executable, str(SOURCE / "examples" / "python" / "first_steps.py"), "--out", str(tmp),
                        "--duration", "12"], capture_output=True, text=True, env=dict(os.environ, MPLCONFIGDIR=str(tmp)))
    assert p.returncode == 0, p.stderr
    out = p.stdout
    assert "checks passed" in out, out
    assert re.search(r"diagnose: coulomb_friction \(knee\) = ", out), out
    rigid, ext = map(float, re.search(r"replay knee: rigid ([0-9.]+) deg, extended ([0-9.]+) deg", out).groups())
    assert ext < rigid, out
    for png in ("tracking.png", "frame.png", "diagnosis.png", "replay.png", "ghosts.png"):
        with open(tmp / png, "rb") as f:
            assert f.read(8) == b"\x89PNG\r\n\x1a\n", png
