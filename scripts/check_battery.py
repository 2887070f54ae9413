"""The modal-model check and the data-driven selection on simulated systems with exact modes:
the thesis's supine chain and Chapter 2 system, a five-segment supine chain with a light feet
segment (modes 3-5 heavily damped, the fifth near the ride's band edge), a lightly damped
6-DOF chain at 100 Hz, and random 2-6 DOF chains sampled at 100-400 Hz whatever their modes
(so modes can lie far below Nyquist). Prints per case the exact and found modes, the true
modes missed and the extra ones (a found mode within MATCH of no true mode), the check's
verdict and model error, and the check of the exact modes with the strongest one left out
(it must fail).

    python scripts/check_battery.py [--random 12] [--seed 11]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from robustness import random_chain  # scripts/ is on the path when a script runs

import armaxmodal as am
from armaxmodal.modes.diagram import stabilisation_diagram
from armaxmodal.modes.modal_check import check_modes
from armaxmodal.modes.pipeline import select_modes

#: a found mode within this relative frequency of a true one is that mode
MATCH = 0.05


def light_six() -> am.Structure:
    """A 6-DOF chain at about 0.5-2 % damping. (Base springs in proportion to the masses
    would leave the base able to drive one mode only: every other mode shape is orthogonal
    to the inertial load.)"""
    m = np.array([8.0, 6.0, 10.0, 5.0, 7.0, 4.0])
    k = 4e3 * m * np.array([1.0, 0.5, 2.0, 0.3, 1.5, 0.8])
    return am.Structure.from_chain(
        m, k, 4e-4 * k, [3e4, 2.5e4, 2e4, 1.5e4, 1e4], [3.0, 2.5, 2.0, 1.5, 1.0], [f"s{i}" for i in range(6)]
    )


def cases(n_random: int, seed: int):
    ride = am.random_vibration(60.0, 120.0, (0.5, 28.0), seed=1)
    yield "supine 4-DOF, 60 Hz", am.supine_human(), 60.0, ride, "bandlimited"
    yield "Chapter 2 4-DOF, 60 Hz zoh", am.chapter2_system(), 60.0, ride, "zoh"
    yield "supine 5-DOF with feet, 60 Hz", am.supine_with_feet(), 60.0, ride, "bandlimited"
    yield "light 6-DOF, 100 Hz", light_six(), 100.0, am.random_vibration(100.0, 240.0, (0.5, 45.0), seed=2), "zoh"
    rng = np.random.default_rng(seed)
    for i in range(n_random):
        s = random_chain(rng, (0.01, 0.03, 0.1, 0.3))
        fs = float(rng.choice([100.0, 200.0, 400.0]))
        if s.modes().freq_hz.max() > 0.4 * fs:
            fs = 400.0
        hold = str(rng.choice(["zoh", "bandlimited"]))
        u = am.random_vibration(fs, 120.0, (0.5, 0.45 * fs), seed=i)
        yield f"random {s.n_dof}-DOF #{i}, {fs:g} Hz", s, fs, u, hold


def matched(truth_f, found_f) -> tuple[list, list]:
    """One to one, nearest pairs first: the true modes no found mode within MATCH takes, and
    the found modes left over (two close true modes found as one leave one missed)."""
    pairs = sorted(
        (abs(g / f - 1), i, j) for i, f in enumerate(truth_f) for j, g in enumerate(found_f) if abs(g / f - 1) <= MATCH
    )
    used_t, used_f = set(), set()
    for _, i, j in pairs:
        if i not in used_t and j not in used_f:
            used_t.add(i)
            used_f.add(j)
    missed = [f for i, f in enumerate(truth_f) if i not in used_t]
    extra = [g for j, g in enumerate(found_f) if j not in used_f]
    return missed, extra


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--random", type=int, default=12)
    parser.add_argument("--seed", type=int, default=11)
    args = parser.parse_args()
    totals = {"cases": 0, "complete": 0, "extra": 0, "good": 0, "strongest_left_out_fails": 0}
    for name, s, fs, u, hold in cases(args.random, args.seed):
        truth = s.modes()
        rec = am.simulate_recording(s, u, fs, noise=0.05, seed=7, hold=hold)
        t = time.perf_counter()
        sel = select_modes(stabilisation_diagram(rec, per_sensor=False))
        found = sel.modes.freq_hz.to_numpy()
        missed, extra = matched(truth.freq_hz, found)
        strongest = int(np.argmin(truth.damping * truth.freq_hz))  # the sharpest peak
        keep = [i for i in range(truth.freq_hz.size) if i != strongest]
        left_out = check_modes(rec, truth.freq_hz[keep], truth.damping[keep])
        totals["cases"] += 1
        totals["complete"] += not missed
        totals["extra"] += bool(extra)
        totals["good"] += sel.quality == "good"
        totals["strongest_left_out_fails"] += not left_out.passed
        print(
            f"{name}: exact {np.round(truth.freq_hz, 2).tolist()} (damping {np.round(truth.damping, 3).tolist()}); "
            f"found {np.round(found, 2).tolist()}; missed {np.round(missed, 2).tolist()}; "
            f"extra {np.round(extra, 2).tolist()}; quality {sel.quality}, model error "
            f"{100 * np.nanmax(sel.check.model_error):.1f} %; without {truth.freq_hz[strongest]:.2f} Hz: "
            f"{'fails' if not left_out.passed else 'passes'} ({100 * np.nanmax(left_out.model_error):.0f} %); "
            f"notes {sorted({w.code for w in sel.notes})}; {time.perf_counter() - t:.1f} s",
            flush=True,
        )
    print(totals)


if __name__ == "__main__":
    main()
