"""How `armaxmodal stabilise` scales with the record: wall time per sample as the record grows
(linear beyond 20,000 samples x 5 sensors is the goal), saved in ``results/size.json``.

Builds a five-mass chain (modes 6.6-14.4 Hz, damping 7-10 %) ridden by random base
acceleration at 100 Hz (0.5-40 Hz, band-limited, 5 % sensor noise) for several record
lengths, runs the command as a user does (a new process each time, after one warm-up run
that fills numba's cache), and prints the wall time, the time per 1,000 samples and the
modes found against the chain's exact ones. With ``--stages`` it also times each stage of
one run in this process (preparation, delay choice, sweep, selection's finishing fits,
frequency-domain refit, segment refits).

    python benchmarks/bench_size.py [--samples 5000,10000,20000,40000] [--stages]
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from results import save  # benchmarks/results.py, beside this script

import armaxmodal as am
from armaxmodal.systems.datasets import five_mass_chain

FS = 100.0


def chain() -> am.Structure:
    return five_mass_chain()


def recording(n_samples: int) -> am.Recording:
    ride = am.random_vibration(FS, n_samples / FS, (0.5, 40.0), seed=1)
    return am.simulate_recording(chain(), ride, FS, noise=0.05, seed=2, hold="bandlimited")


def run_cli(path: Path, out: Path) -> float:
    start = time.perf_counter()
    proc = subprocess.run(
        [sys.executable, "-m", "armaxmodal", "stabilise", str(path), "--quiet", "--json", str(out)],
        capture_output=True,
        text=True,
    )
    elapsed = time.perf_counter() - start
    if proc.returncode not in (0, 2):
        raise RuntimeError(proc.stderr)
    return elapsed


def stages(rec: am.Recording) -> None:
    from armaxmodal.estimate.fit import load_kernels
    from armaxmodal.modes import diagram as st
    from armaxmodal.modes.pipeline import select_modes
    from armaxmodal.prepare.preparation import prepare

    load_kernels()
    marks = [("start", time.perf_counter())]
    prep = prepare(rec)
    marks.append(("preparation", time.perf_counter()))
    nk, _ = st._choose_nk(prep.recording, st.NK_SEARCH, (8, 10, 12), None, st.SWEEP_TOL)
    marks.append((f"delay choice (nk = {nk})", time.perf_counter()))
    diagram = st.stabilisation_diagram(prep.recording, prepared=True, nk=nk)
    marks.append(("sweep, shared + per sensor", time.perf_counter()))
    select_modes(diagram, refine=False, segments=0)
    marks.append(("selection with finishing fits", time.perf_counter()))
    select_modes(diagram, segments=0)
    marks.append(("... and frequency-domain refit", time.perf_counter()))
    select_modes(diagram)
    marks.append(("... and segment refits", time.perf_counter()))
    for (name, t1), (_, t0) in zip(marks[1:], marks[:-1], strict=True):
        print(f"  {name}: {t1 - t0:.2f} s")


def size_rows(times: dict[int, float]) -> list[dict]:
    """Each length's wall time per sample over the shortest's: at most 1 is linear or better."""
    first = min(times)
    return [{
        "what": f"wall time per sample of `stabilise` at {n:,} x 5 over {first:,} x 5 (five-mass chain, 100 Hz)",
        "goal": "<= 1 (linear)",
        "measured": f"{(t / n) / (times[first] / first):.2f} ({t:.1f} s against {times[first]:.1f} s)",
        "met": (t / n) / (times[first] / first) <= 1.0, "values": [t, times[first]],
    } for n, t in sorted(times.items()) if n != first]  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", default="5000,10000,20000,40000")
    parser.add_argument("--stages", action="store_true")
    args = parser.parse_args()
    sizes = [int(v) for v in args.samples.split(",")]
    truth = chain().modes().freq_hz
    print(f"exact modes: {np.round(truth, 2).tolist()} Hz")
    print("| samples x sensors | wall time (s) | s per 1,000 samples | modes found (Hz) |")
    print("|---|---|---|---|")
    times = {}
    with tempfile.TemporaryDirectory() as tmp:
        for i, n in enumerate(sizes):
            path = Path(tmp) / f"r{n}.csv"
            am.io.write_recording_csv(recording(n), path)
            out = Path(tmp) / f"m{n}.json"
            if i == 0:
                run_cli(path, out)  # warm-up: numba's cache, the OS file cache
            elapsed = run_cli(path, out)
            found = [round(m["freq_hz"], 2) for m in json.loads(out.read_text())["modes"]] if out.exists() else []
            print(f"| {n} x 5 | {elapsed:.1f} | {1000 * elapsed / n:.2f} | {found} |", flush=True)
            times[n] = elapsed
    save("size", size_rows(times))
    if args.stages:
        print(f"stages at {sizes[-1]} samples:")
        stages(recording(sizes[-1]))


if __name__ == "__main__":
    main()
