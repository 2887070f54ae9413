"""The automatic pipeline on structures it has never seen: random chains (2-6 masses, damping
from about 1 % to 60 %), sampled at the lowest of 60/100/200/400 Hz that puts every mode below
0.35 fs, zoh or band-limited, 120 s random ride, 5 % sensor noise. Prints, per case, how many
modes were found and the frequency and damping errors against the exact modes.

    python scripts/robustness.py [--cases 10] [--seed 7]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import armaxmodal as am
from armaxmodal.modes.diagram import stabilisation_diagram
from armaxmodal.modes.pipeline import select_modes


def random_chain(rng, dampings=(0.01, 0.05, 0.15, 0.3)):
    """A chain of 2-6 masses whose first mode's damping is about one of ``dampings``."""
    n = int(rng.integers(2, 7))
    masses = rng.uniform(1, 20, n)
    k = rng.uniform(5e3, 1e5, n) * masses / 5
    k_s = rng.uniform(5e3, 8e4, n - 1) * masses[:-1] / 5
    target = float(rng.choice(list(dampings)))
    undamped = am.Structure.from_chain(masses, k, np.zeros(n), k_s, np.zeros(n - 1))
    w1 = 2 * np.pi * undamped.modes().freq_hz[0]
    c = 2 * target * w1 * masses * rng.uniform(0.5, 1.5, n)
    c_s = 2 * target * w1 * masses[:-1] * rng.uniform(0.2, 1.0, n - 1)
    return am.Structure.from_chain(masses, k, c, k_s, c_s)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=10)
    parser.add_argument("--seed", type=int, default=7)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    for case in range(args.cases):
        s = random_chain(rng)
        truth = s.modes()
        fs = float(min([f for f in (60.0, 100.0, 200.0, 400.0) if truth.freq_hz.max() < 0.35 * f] or [400.0]))
        hold = str(rng.choice(["zoh", "bandlimited"]))
        u = am.random_vibration(fs, 120.0, (0.5, 0.45 * fs), seed=case)
        rec = am.simulate_recording(
            s, u, fs, noise=0.05, input_noise=0.01 if hold == "bandlimited" else 0.0, seed=100 + case, hold=hold
        )
        t = time.perf_counter()
        modes = select_modes(stabilisation_diagram(rec, per_sensor=False)).modes
        f, x = modes.freq_hz.to_numpy(), modes.damping.to_numpy()
        nearest = [int(np.argmin(np.abs(f - ft))) for ft in truth.freq_hz]
        ef = 100 * (f[nearest] / truth.freq_hz - 1)
        ex = 100 * (x[nearest] / truth.damping - 1)
        print(
            f"case {case}: {truth.freq_hz.size} DOF, fs {fs:g} Hz, {hold}, damping {np.round(truth.damping, 3)}; "
            f"found {len(modes)}; f error % {np.round(ef, 2)}; damping error % {np.round(ex, 1)}; "
            f"{time.perf_counter() - t:.1f} s"
        )


if __name__ == "__main__":
    main()
