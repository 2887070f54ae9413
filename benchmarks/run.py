"""Every benchmark whose results the performance page shows, one after another, then the page.

    python benchmarks/run.py [--skip-long]

The in-process pairs run under pytest-benchmark (``test_peers.py``); the whole-command
benchmarks are scripts, because they time fresh processes, peak memory and dask clusters. About
15 minutes on 2 cores, most of it the one-hour ride (``--skip-long`` keeps its saved result).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--skip-long", action="store_true", help="keep bench_long.py's saved result")
    args = parser.parse_args()
    steps = [
        [sys.executable, "-m", "pytest", str(HERE / "test_peers.py"), "-q", "-n", "0", "-p", "no:cacheprovider",
         f"--benchmark-json={HERE / 'results' / 'peers.json'}"],
        [sys.executable, str(HERE / "bench_ratio.py")],
        [sys.executable, str(HERE / "bench_study.py")],
        [sys.executable, str(HERE / "bench_size.py")],
    ]  # fmt: skip
    if not args.skip_long:
        steps.insert(2, [sys.executable, str(HERE / "bench_long.py")])
    for step in steps:
        print("$", " ".join(Path(a).name if a.startswith("/") else a for a in step), flush=True)
        subprocess.run(step, check=True, cwd=HERE.parent)
    subprocess.run([sys.executable, str(HERE / "report.py")], check=True, cwd=HERE.parent)


if __name__ == "__main__":
    main()
