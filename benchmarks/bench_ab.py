"""Time `armaxmodal stabilise` from two checkouts, runs interleaved (A, B, A, B, ...).

This machine's speed drifts by 5-10 % between hours, more than most changes are worth, so a
change is timed against the code before it in the same minutes, not against a figure noted
earlier. Each checkout runs as its own warm process (one untimed run first fills its numba
cache); the record is any file the command reads.

    git worktree add /tmp/before <commit>
    python benchmarks/bench_ab.py RECORD /tmp/before . [--runs 8]
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def run(record: Path, checkout: Path, out: Path) -> float:
    """Wall time of one run with ``checkout`` first on the import path."""
    env = dict(os.environ, PYTHONPATH=str(checkout.resolve()))
    cmd = [sys.executable, "-m", "armaxmodal", "stabilise", str(record.resolve()), "--quiet", "--json", str(out)]
    out.unlink(missing_ok=True)
    start = time.perf_counter()
    proc = subprocess.run(cmd, env=env, capture_output=True, text=True, cwd=out.parent)
    elapsed = time.perf_counter() - start
    if not out.exists():  # a run that found no mode still writes its JSON; a refused input does not
        raise RuntimeError(f"{checkout}: no output ({proc.stderr.strip()})")
    return elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("record", type=Path)
    parser.add_argument("before", type=Path)
    parser.add_argument("after", type=Path)
    parser.add_argument("--runs", type=int, default=8)
    args = parser.parse_args()
    times: dict[Path, list[float]] = {args.before: [], args.after: []}
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "modes.json"
        for checkout in times:
            run(args.record, checkout, out)  # warm-up: numba's cache for this checkout
        for _ in range(args.runs):
            for checkout, series in times.items():
                series.append(run(args.record, checkout, out))
    for checkout, series in times.items():
        runs = ", ".join(f"{t:.2f}" for t in sorted(series))
        print(f"{checkout}: median {statistics.median(series):.2f} s ({runs})")
    ratio = statistics.median(times[args.after]) / statistics.median(times[args.before])
    print(f"after / before: {ratio:.3f}")


if __name__ == "__main__":
    main()
