"""Issue 29's second ratio: a long ride against a short one, with defaults, as a user runs it.

A supine-human ride at 120 Hz with four sensors (random base acceleration 0.5-40 Hz,
band-limited, 5 % sensor noise) is written to CSV at two lengths; ``armaxmodal stabilise`` runs
on each in a new process under ``/usr/bin/time -v``. Reported: wall time per sample (long over
short: the goal is at most 1), the peak resident memory per sample and sensor of the long
run (goal: at most 100 bytes), and what a sample adds: the slope of the peak between the
two lengths, which leaves out the fixed 0.25 GB of the interpreter and its libraries.

    python benchmarks/bench_long.py [--short 20000] [--long 432000]
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from results import save  # benchmarks/results.py, beside this script

import armaxmodal as am

FS = 120.0


def ride(n_samples: int, path: Path) -> None:
    base = am.random_vibration(FS, n_samples / FS, (0.5, 40.0), seed=1)
    rec = am.simulate_recording(am.supine_human(), base, FS, noise=0.05, seed=2, hold="bandlimited")
    am.write_recording_csv(rec, path)


def run(path: Path) -> tuple[float, float, str]:
    """Wall seconds, peak RSS in bytes, and the modes line of one ``stabilise`` run."""
    start = time.perf_counter()
    proc = subprocess.run(
        ["/usr/bin/time", "-v", sys.executable, "-m", "armaxmodal", "stabilise", str(path), "--json", "/dev/null"],
        capture_output=True, text=True,
    )  # fmt: skip
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise SystemExit(proc.stderr[-2000:])
    rss_kb = float(re.search(r"Maximum resident set size \(kbytes\): (\d+)", proc.stderr).group(1))
    table = [line for line in proc.stdout.splitlines() if re.match(r"\s*\d+\s+\d", line)]
    return wall, 1024 * rss_kb, "; ".join(" ".join(line.split()[1:3]) for line in table)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--short", type=int, default=20_000)
    parser.add_argument("--long", type=int, default=432_000)
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        results, peaks = {}, {}
        for n in (args.short, args.long):
            path = Path(tmp) / f"ride_{n}.csv"
            ride(n, path)
            wall, rss, modes = run(path)
            results[n], peaks[n] = wall / n, rss
            print(
                f"{n} samples x 4 sensors: {wall:.1f} s, {1e6 * wall / n:.1f} us/sample, peak RSS "
                f"{rss / 2**20:.0f} MB ({rss / (4 * n):.0f} bytes per sample and sensor); modes (Hz, damping): {modes}"
            )
        print(f"time per sample, long over short: {results[args.long] / results[args.short]:.2f} (goal <= 1)")
        # the peak holds a fixed part (the interpreter, numpy, scipy, numba's kernels: about
        # 0.25 GB before any data), so the slope between the two lengths is what a sample costs
        slope = (peaks[args.long] - peaks[args.short]) / (4 * (args.long - args.short))
        ten_hours = peaks[args.short] + slope * 4 * (36_000 * FS - args.short)
        print(
            f"memory a sample and sensor adds: {slope:.0f} bytes; fixed part {peaks[args.short] / 2**20:.0f} MB; "
            f"ten hours at {FS:g} Hz would peak near {ten_hours / 2**30:.1f} GB"
        )
        ratio, bytes_long = results[args.long] / results[args.short], peaks[args.long] / (4 * args.long)
        save("long", [
            {"what": f"wall time per sample of a {args.long:,} x 4 ride over a {args.short:,} one (defaults, a "
                     "new process each)", "goal": "<= 1 (linear in the record's length)",
             "measured": f"{ratio:.2f} ({results[args.long] * args.long:.1f} s against "
                         f"{results[args.short] * args.short:.1f} s)", "met": ratio <= 1.0, "values": [ratio]},
            {"what": "peak resident memory of that long run per sample and sensor", "goal": "none",
             "measured": f"{bytes_long:.0f} bytes ({peaks[args.long] / 2**20:.0f} MB; {slope:.0f} bytes a sample "
                         "and sensor adds)", "met": None, "values": [bytes_long, slope]},
        ])  # fmt: skip


if __name__ == "__main__":
    main()
