"""Where the benchmarks keep what they measured: one JSON file per benchmark in
``benchmarks/results/``, with the machine, the versions and the commit, which
``benchmarks/report.py`` turns into the performance page's tables. Nothing measured is typed
into the docs by hand."""

from __future__ import annotations

import datetime
import json
import os
import platform
import subprocess
from pathlib import Path

import numpy as np

RESULTS = Path(__file__).resolve().parent / "results"


def save(name: str, rows: list[dict]) -> Path:
    """Write ``rows`` (one per ratio or figure: ``what``, ``goal``, ``measured``, ``met``, and
    the raw numbers behind it) as ``results/NAME.json`` with when and where they were measured."""
    RESULTS.mkdir(exist_ok=True)
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                            cwd=RESULTS.parent).stdout.strip()  # fmt: skip
    record = {
        "benchmark": name,
        "date": datetime.date.today().isoformat(),
        "commit": commit,
        "machine": f"{os.cpu_count()} cores, {platform.machine()}, Python {platform.python_version()}, "
        f"numpy {np.__version__}",
        "rows": rows,
    }
    path = RESULTS / f"{name}.json"
    path.write_text(json.dumps(record, indent=1, allow_nan=False) + "\n")
    return path
