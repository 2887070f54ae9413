"""The package and the command line on a machine with no display: nothing imports matplotlib until
a figure is asked for, and a figure is then drawn without one (a server, a CI runner, a cluster)."""

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def _run(code: str, cwd: Path) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY", "MPLBACKEND")}
    return subprocess.run([sys.executable, "-c", code], cwd=cwd, env=env, capture_output=True, text=True, timeout=300)


def test_no_figure_no_matplotlib_and_a_figure_without_a_display(tmp_path):
    data = ROOT / "fixtures" / "supine_random.csv"
    code = f"""
import sys
import armaxmodal, armaxmodal.cli.main
assert "matplotlib" not in sys.modules, "imported with the package"
from armaxmodal.cli.main import main
assert main(["--quiet", "stabilise", r"{data}", "--orders", "2:12", "--json", "m.json"]) == 0
assert "matplotlib" not in sys.modules, "imported by a run that draws nothing"
assert main(["--quiet", "stabilise", r"{data}", "--orders", "2:12", "--plot", "s.png"]) == 0
import matplotlib
print("backend", matplotlib.get_backend())
"""
    run = _run(code, tmp_path)
    assert run.returncode == 0, run.stderr[-2000:]
    assert (tmp_path / "s.png").read_bytes()[:4] == b"\x89PNG"
    assert "backend agg" in run.stdout.lower()
