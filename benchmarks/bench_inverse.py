"""Timing of the inverse methods on the Chapter 2 system (P1 10 % eigenvector noise), side by
side with the same SDP stated in cvxpy (the modelling-layer peer), on identical data.

    python benchmarks/bench_inverse.py [--repeat 20]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import armaxmodal as am
from armaxmodal.inverse import evphc, inner_solve, inner_solve_sdp, model_update, pia

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from tests.naive import sdp_inner_cvxpy  # noqa: E402

BOUNDS = [(1.0, 2.5), (3.0, 5.0), (1.0, 2.0)]


def best_time(fn, repeat: int) -> float:
    fn()  # warm: imports, first-call set-up
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        fn()
        times.append(time.perf_counter() - start)
    return float(np.median(times))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=20)
    args = parser.parse_args()
    s = am.chapter2_system()
    m = s.modes()
    rng = np.random.default_rng(0)
    z = (rng.standard_normal(m.shapes.shape) + 1j * rng.standard_normal(m.shapes.shape)) / np.sqrt(2)
    lam, psi = m.eigenvalues, m.shapes * (1 + 0.1 * z)
    f = np.linspace(0.5, 30.0, 256)
    t = s.transmissibility(f)
    full = np.ones((4, 4), bool)
    chain = np.abs(np.subtract.outer(np.arange(4), np.arange(4))) <= 1
    rows = [
        ("inner_solve (chain, bounded LS)", lambda: inner_solve(lam, psi, mass_ratio_bounds=BOUNDS), args.repeat),
        ("inner_solve_sdp, chain pattern", lambda: inner_solve_sdp(lam, psi, mass_ratio_bounds=BOUNDS), args.repeat),
        ("  same SDP in cvxpy + Clarabel", lambda: sdp_inner_cvxpy(lam, psi, chain, BOUNDS), args.repeat),
        (
            "inner_solve_sdp, full pattern",
            lambda: inner_solve_sdp(lam, psi, pattern=full, mass_ratio_bounds=BOUNDS),
            args.repeat,
        ),
        ("  same SDP in cvxpy + Clarabel", lambda: sdp_inner_cvxpy(lam, psi, full, BOUNDS), args.repeat),
        ("pia", lambda: pia(lam, psi, s.masses), args.repeat),
        ("model_update (256 lines)", lambda: model_update(lam, psi, frf=(f, t), mass_ratio_bounds=BOUNDS), 3),
        ("evphc, one start", lambda: evphc(lam, psi, (f, t), mass_ratio_bounds=BOUNDS, starts=1), 3),
    ]
    previous = None
    for name, fn, repeat in rows:
        seconds = best_time(fn, repeat)
        ratio = f"  peer / ours = {seconds / previous:.1f}" if name.startswith("  same") else ""
        print(f"{name:34s} {1e3 * seconds:9.2f} ms{ratio}")
        previous = seconds


if __name__ == "__main__":
    main()
