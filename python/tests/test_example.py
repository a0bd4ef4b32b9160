"""examples/python/resolution_study.py at a tiny size: three coarse runs to T = 1.3 (two of
the experiment's points), the fronts collected and the figure written."""

import subprocess
import sys

from conftest import ADAPTER, REPO


def test_resolution_study_runs_and_plots(tmp_path):
    out = subprocess.run(
        [sys.executable, str(REPO / "examples" / "python" / "resolution_study.py"),
         "--columns", "5", "7", "10", "--end-T", "1.3", "--out", str(tmp_path),
         "--adapter", ADAPTER],
        capture_output=True, text=True, timeout=300,
    )
    assert out.returncode == 0, out.stderr
    rows = [l for l in out.stdout.splitlines() if l.startswith("n =")]
    assert len(rows) == 3, out.stdout
    for row in rows:
        rms = float(row.split("RMS error")[1])
        # Coarse, but the front is where the experiment puts it to within a fifth of a.
        assert 0 < rms < 0.2, row
    png = tmp_path / "resolution_study.png"
    assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    for n in (5, 7, 10):
        assert (tmp_path / f"n{n}" / "probes" / "front.csv").is_file()
