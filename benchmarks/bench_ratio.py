"""Issue 29's first ratio: the CPU work of a whole ``stabilise`` against its own shared-pole
sweep, both measured in one process on the same record, one after the other.

A  what ``armaxmodal stabilise`` runs after reading the file: the preparation, the delay
   choice, the sweep (shared poles and every sensor alone) and the selection (finishing fits,
   frequency-domain refit, segment refits), on the worker pool as the command does;
B  its shared-pole sweep alone: the orders A swept, at the delay A chose, each fitted from
   scratch with the sweep's own cap and tolerance, one after another in this process.

A1 the same as A on one thread (``n_jobs=1``): the work ratio without the two workers' contention for
   the machine (on this 2-core machine each of two processes running at once takes about 15 % more
   CPU than one alone), shown beside the guard, not guarding.

CPU time is user + system time of this process (all its threads, the pool's workers among
them) and of any children it has reaped; process start, imports, reading and numba's first load are outside both. The
record is ``benchmarks/bench_size.py``'s five-mass chain at 100 Hz (20,000 x 5 by default).
Guard: A / B at most 3.5 (the sweep, the per-sensor sweeps and the delay choice are about 2 of it).

    python benchmarks/bench_ratio.py [--samples 20000] [--repeat 2]
"""

from __future__ import annotations

import argparse
import resource
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_size import recording  # noqa: E402  (the same chain record as the size benchmark)
from results import save  # noqa: E402

import armaxmodal as am  # noqa: E402
from armaxmodal._threads import one_blas_thread  # noqa: E402
from armaxmodal.estimate.fit import fit_resumable, load_kernels  # noqa: E402
from armaxmodal.modes.diagram import SWEEP_TOL  # noqa: E402

GUARD = 3.5


def cpu_seconds() -> float:
    """User + system CPU of this process and of its children that have ended."""
    me, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + children.ru_utime + children.ru_stime


def whole_command(rec: am.Recording, n_jobs: int | None = None):
    """A: the command's work after reading (preparation included); the diagram it made."""
    diagram = am.stabilisation_diagram(rec, n_jobs=n_jobs)
    am.select_modes(diagram, n_jobs=n_jobs)
    return diagram


def shared_sweep(diagram) -> None:
    """B: the shared-pole fits of the diagram's orders, from scratch, one after another, with
    one BLAS thread as the sweep's (spinning BLAS threads make small fits 3-4 times slower)."""
    with one_blas_thread():
        for orders in diagram.orders:
            fit_resumable(
                diagram.recording, orders, shared_poles=True, max_iter=30, tol=SWEEP_TOL, stop="decrease", warn=False
            )


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--samples", type=int, default=20_000)
    parser.add_argument("--repeat", type=int, default=2)
    args = parser.parse_args()
    rec = recording(args.samples)
    load_kernels()
    fit_resumable(rec, (4, 5, 4, 0), shared_poles=True, max_iter=2, warn=False)  # numba's first call
    print(f"{rec.n_samples} samples x {len(rec.sensors)} sensors at {rec.fs:g} Hz")
    ratios, cpu, serial = [], [], []
    for run in range(args.repeat):
        t0, w0 = cpu_seconds(), time.perf_counter()
        diagram = whole_command(rec)
        t1, w1 = cpu_seconds(), time.perf_counter()
        shared_sweep(diagram)
        t2, w2 = cpu_seconds(), time.perf_counter()
        whole_command(rec, n_jobs=1)
        t3 = cpu_seconds()
        a, b, a1 = t1 - t0, t2 - t1, t3 - t2
        print(
            f"run {run + 1}: stabilise {a:.2f} CPU-s ({w1 - w0:.2f} s wall), its shared sweep {b:.2f} CPU-s "
            f"({w2 - w1:.2f} s wall, {len(diagram.orders)} orders, nk {diagram.orders[0][3]}): ratio {a / b:.2f}; "
            f"on one thread {a1:.2f} CPU-s, ratio {a1 / b:.2f}"
        )
        ratios.append(a / b)
        cpu.append((a, b))
        serial.append(a1 / b)
    what = (f"CPU of a whole `stabilise` over the CPU of its own shared-pole sweep, {rec.n_samples:,} x "
            f"{len(rec.sensors)} chain record")  # fmt: skip
    measured = f"{min(ratios):.2f}-{max(ratios):.2f}, median {np.median(ratios):.2f} ({len(ratios)} runs; " + ", ".join(
        f"{a:.2f} against {b:.2f} CPU-s" for a, b in cpu) + ")"  # fmt: skip
    one = (f"{min(serial):.2f}-{max(serial):.2f}, median {np.median(serial):.2f} (the same runs; stabilise with "
           "n_jobs=1)")  # fmt: skip
    save("ratio", [{"what": what, "goal": f"<= {GUARD} (the selection costs at most 2.5 sweeps more)",
                    "measured": measured, "met": max(ratios) <= GUARD, "values": ratios},
                   {"what": "the same on one thread: the work ratio without two workers' contention for the machine",
                    "goal": "shown beside the guard", "measured": one, "met": None,
                    "values": serial}])  # fmt: skip


if __name__ == "__main__":
    main()
