# python/exotwin/bench.py (`exotwin bench --only python`) on 6 s of gait, once: it runs its three pairs
# (the UDP example against `exotwin serve` included) and reports three rows with positive ratios.
# Its figures are not judged here (bench rows, not timed tests).
import json
import math
import subprocess
import sys

from conftest import EXOTWIN_BIN


def test_the_bench_rows(tmp):
    p = subprocess.run([sys.executable, "-m", "exotwin.bench", "--exotwin", EXOTWIN_BIN, "--quick", "--repeat", "1",
                        "--json", str(tmp / "b.json")], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    j = json.loads((tmp / "b.json").read_text())
    assert j["status"] == "ok" and j["quick"] is True
    rows = j["rows"]
    assert [r["goal"] for r in rows] == ["<= 1.05x", "<= 0.25x", ""]
    for r in rows:
        assert r["unit"] == "x" and math.isfinite(r["ratio"]) and r["ratio"] > 0, r
    assert "6000 periods" in rows[1]["work"]
