"""The README's first command, run as a user runs it: the console script the install put on
the path, in a fresh folder holding the bundled recording, with the README's own arguments.
The install step itself (`python3 -m venv .venv && pip install -e .`) is what CI's first
line does; here the command after it is taken from the README text, so the documentation
and the product cannot drift apart."""

from __future__ import annotations

import json
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


def _readme_main_command() -> list[str]:
    """The part of the README's first fenced command after the install."""
    text = (ROOT / "README.md").read_text()
    first = re.search(r"```bash\n(.*?)\n```", text, re.S).group(1).strip()
    install, _, run = first.rpartition("&& ")
    assert "pip install" in install and "-e ." in install, first  # editable: see issue 11, item 5
    argv = shlex.split(run)
    assert argv[0] == ".venv/bin/armaxmodal", argv
    return argv[1:]


def test_readme_first_command_writes_the_modes_of_the_truth(tmp_path, fixtures_dir):
    script = Path(sys.executable).with_name("armaxmodal")
    if not script.exists():
        pytest.skip("the armaxmodal console script is not installed beside this Python")
    argv = _readme_main_command()
    (tmp_path / "fixtures").mkdir()
    for name in ("supine_random.csv", "supine_random.truth.json"):
        shutil.copy(fixtures_dir / name, tmp_path / "fixtures" / name)
    proc = subprocess.run([str(script), *argv], cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    outputs = [argv[i + 1] for i, a in enumerate(argv) if a in ("--plot", "--json", "--csv")]
    assert sorted(outputs) == ["modes.json", "poles.csv", "stab.png"]
    assert (tmp_path / "stab.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert len((tmp_path / "poles.csv").read_text().splitlines()) > 50
    modes = json.loads((tmp_path / "modes.json").read_text())["modes"]
    truth = json.loads((fixtures_dir / "supine_random.truth.json").read_text())["modes"]
    got = np.array([m["freq_hz"] for m in modes])
    want = np.array([m["freq_hz"] for m in truth])
    assert got.shape == want.shape and np.all(np.abs(got / want - 1) < 0.02), (got, want)
    # the README's sentence about what the command finds is what it finds
    readme = (ROOT / "README.md").read_text()
    stated = re.search(r"the command finds\s+([\d./ ]+) Hz", readme).group(1)
    assert [f"{v:.2f}" for v in got] == [v.strip() for v in stated.split("/")]


def test_readme_python_example_runs_as_written(tmp_path, fixtures_dir):
    """The landing page's Python example, in a folder holding the bundled recording: it runs
    against the current API and its modes pass the modal-model check."""
    text = (ROOT / "README.md").read_text()
    code = re.search(r"```python\n(.*?)\n```", text, re.S).group(1)
    (tmp_path / "fixtures").mkdir()
    shutil.copy(fixtures_dir / "supine_random.csv", tmp_path / "fixtures")
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    lines = run.stdout.splitlines()
    assert any(line.rstrip().endswith("good") for line in lines), run.stdout  # selection.quality
    assert "no effect" in run.stdout  # the clean ride's diagnosis
