"""Chapter 2 study of the inverse modal problem under stated noise protocols (Tables 2.2-2.4).

Protocols, noise level s (1, 5, 10 %), on the Chapter 2 four-DOF system:
* P1 (the thesis's): exact eigenvalues, eigenvector components multiplied by (1 + s z) with
  z complex standard normal, exact transmissibility (the EPFRF carries the same information:
  T = 1 - EPFRF).
* P2: frequencies with relative noise s/10, damping ratios s/2, eigenvectors as P1, and the
  transmissibility on 256 frequencies 0.5-30 Hz with complex relative noise s.

Methods: PIA (true M given, as it requires), the inner solve (first mass known, Section 2.3.2
mass-ratio bounds), model updating (every block weighted by its protocol noise level).
Reported per method: median and 90th percentile over seeds of the worst relative frequency
and damping error over the four modes, and of |dK|/|K|, |dC|/|C| (Frobenius). Under P2 the
"(CR bound)" row gives the same figures for an efficient unbiased estimator (Gaussian draws
from the Cramér-Rao covariance of the chain parameters): no method can beat it on average.

    python scripts/inverse_study.py [--seeds 8]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import armaxmodal as am
from armaxmodal.exceptions import StructureError
from armaxmodal.inverse import evphc, inner_solve, model_update, pia

BOUNDS = [(1.0, 2.5), (3.0, 5.0), (1.0, 2.0)]  # Section 2.3.2
# An H1 estimate of a 120 s ride at 60 Hz with 512-sample segments has 256 lines below Nyquist.
FREQS = np.linspace(0.5, 30.0, 256)


def noisy_data(structure, level, protocol, rng):
    m = structure.modes()
    z = (rng.standard_normal(m.shapes.shape) + 1j * rng.standard_normal(m.shapes.shape)) / np.sqrt(2)
    shapes = m.shapes * (1 + level * z)
    t = structure.transmissibility(FREQS)
    if protocol == "P1":
        return m.eigenvalues, shapes, t, {"freq": 1e-4, "damping": 1e-4, "shape": level, "frf": 1e-4}
    f = m.freq_hz * (1 + 0.1 * level * rng.standard_normal(4))
    x = m.damping * (1 + 0.5 * level * rng.standard_normal(4))
    wn = 2 * np.pi * f
    lam = -x * wn + 1j * wn * np.sqrt(1 - x**2)
    zt = (rng.standard_normal(t.shape) + 1j * rng.standard_normal(t.shape)) / np.sqrt(2)
    sigma = {"freq": 0.1 * level, "damping": 0.5 * level, "shape": level, "frf": level}
    return lam, shapes, t * (1 + level * zt), sigma


def errors(sol, structure):
    truth = structure.modes()
    got = sol.modes
    idx = [int(np.argmin(np.abs(got.freq_hz - f))) for f in truth.freq_hz]
    ef = np.max(np.abs(got.freq_hz[idx] / truth.freq_hz - 1))
    ex = np.max(np.abs(got.damping[idx] / truth.damping - 1))
    ek = np.linalg.norm(sol.structure.K - structure.K) / np.linalg.norm(structure.K)
    ec = np.linalg.norm(sol.structure.C - structure.C) / np.linalg.norm(structure.C)
    return ef, ex, ek, ec


def p2_bound(structure, level, draws=400):
    """Cramér-Rao bound of the P2 protocol for the chain parameters (m1 fixed): Fisher
    information from the exact model's Jacobian of the noise-normalised residuals, then the
    median/p90 of the same error measures over Gaussian draws with that covariance -- what an
    efficient unbiased estimator would reach."""
    from armaxmodal.inverse.update import _log_ratio, _shape_residual

    c = structure.chain_components()
    n = c.masses.size
    x0 = np.r_[c.masses[1:], c.c, c.c_s, c.k, c.k_s]
    m0, t0 = structure.modes(), structure.transmissibility(FREQS)

    def build(v):
        return am.Structure.from_chain(
            np.r_[c.masses[0], v[: n - 1]],
            v[3 * n - 2 : 4 * n - 2],
            v[n - 1 : 2 * n - 1],
            v[4 * n - 2 :],
            v[2 * n - 1 : 3 * n - 2],
        )

    def residual(v):
        s = build(v)
        m = s.modes()
        parts = [(m.freq_hz / m0.freq_hz - 1) / (0.1 * level), (m.damping / m0.damping - 1) / (0.5 * level)]
        for r in range(n):
            parts += _shape_residual(m0.shapes[:, r], m.shapes[:, r], level, False)
        parts += _log_ratio(t0, s.transmissibility(FREQS), level, False)
        return np.concatenate(parts)

    h = 1e-6 * x0
    jac = np.array(
        [(residual(x0 + h[i] * e) - residual(x0 - h[i] * e)) / (2 * h[i]) for i, e in enumerate(np.eye(x0.size))]
    ).T
    cov = np.linalg.inv(jac.T @ jac)
    rng = np.random.default_rng(0)
    rows = []
    for v in rng.multivariate_normal(x0, cov, draws):
        s = build(np.abs(v))
        rows.append(errors(type("Draw", (), {"modes": s.modes(), "structure": s})(), structure))
    return np.array(rows)


def run(seeds: int) -> None:
    s = am.chapter2_system()
    methods = {
        "PIA": lambda lam, psi, t, sig: pia(lam, psi, s.masses),
        "inner solve": lambda lam, psi, t, sig: inner_solve(lam, psi, mass_ratio_bounds=BOUNDS, m1=6.0),
        "EVPHC": lambda lam, psi, t, sig: evphc(lam, psi, (FREQS, t), mass_ratio_bounds=BOUNDS, m1=6.0, starts=2),
        "model update": lambda lam, psi, t, sig: model_update(
            lam, psi, frf=(FREQS, t), sigma=sig, mass_ratio_bounds=BOUNDS, m1=6.0
        ),
    }
    print(
        f"{'protocol':8s} {'noise':>5s} {'method':13s} {'f worst % (med/p90)':>20s} {'xi worst %':>16s} "
        f"{'|dK|/|K|':>15s} {'|dC|/|C|':>15s} {'time s':>7s} failed"
    )
    for protocol in ("P1", "P2"):
        for level in (0.01, 0.05, 0.10):
            for name, method in methods.items():
                rows, t_total, failed = [], 0.0, 0
                for seed in range(seeds):
                    rng = np.random.default_rng(1000 * int(100 * level) + seed)
                    lam, psi, t, sig = noisy_data(s, level, protocol, rng)
                    start = time.perf_counter()
                    try:
                        rows.append(errors(method(lam, psi, t, sig), s))
                    except StructureError:
                        failed += 1
                    t_total += time.perf_counter() - start
                if name == "model update" and protocol == "P2":
                    bound = p2_bound(s, level)
                    b_med, b_p90 = np.median(bound, axis=0), np.percentile(bound, 90, axis=0)
                    print(
                        f"{protocol:8s} {100 * level:4.0f}% {'(CR bound)':13s} "
                        + " ".join(
                            f"{100 * b_med[i]:7.2f}/{100 * b_p90[i]:7.2f}".rjust(20 if i == 0 else 16)
                            if i < 2
                            else f"{b_med[i]:6.3f}/{b_p90[i]:6.3f}".rjust(15)
                            for i in range(4)
                        )
                    )
                if not rows:
                    print(f"{protocol:8s} {100 * level:4.0f}% {name:13s} all {failed} seeds failed")
                    continue
                e = np.array(rows)
                med, p90 = np.median(e, axis=0), np.percentile(e, 90, axis=0)
                cells = [
                    f"{100 * med[i]:7.2f}/{100 * p90[i]:7.2f}" if i < 2 else f"{med[i]:6.3f}/{p90[i]:6.3f}"
                    for i in range(4)
                ]
                print(
                    f"{protocol:8s} {100 * level:4.0f}% {name:13s} {cells[0]:>20s} {cells[1]:>16s} {cells[2]:>15s} "
                    f"{cells[3]:>15s} {t_total / seeds:7.3f} {failed}"
                )


def chapter4(seeds: int) -> None:
    """The issue's Chapter 4 setting: supine model, 10 % shape, 5 % transmissibility, 1 %
    frequency and 5 % damping noise; total mass known; Table 4.2 mass-ratio bounds."""
    from armaxmodal.inverse.modal_data import body_mass_bounds
    from armaxmodal.systems.datasets import TABLE_4_2_MASS_FRACTION

    s = am.supine_human()
    m = s.modes()
    bounds = body_mass_bounds(s.names, TABLE_4_2_MASS_FRACTION)
    sigma = {"freq": 0.01, "damping": 0.05, "shape": 0.10, "frf": 0.05}
    rows = []
    for seed in range(seeds):
        rng = np.random.default_rng(77 + seed)
        z = (rng.standard_normal(m.shapes.shape) + 1j * rng.standard_normal(m.shapes.shape)) / np.sqrt(2)
        f = m.freq_hz * (1 + 0.01 * rng.standard_normal(4))
        x = m.damping * (1 + 0.05 * rng.standard_normal(4))
        wn = 2 * np.pi * f
        lam = -x * wn + 1j * wn * np.sqrt(1 - x**2)
        t = s.transmissibility(FREQS)
        zt = (rng.standard_normal(t.shape) + 1j * rng.standard_normal(t.shape)) / np.sqrt(2)
        sol = model_update(
            lam,
            m.shapes * (1 + 0.1 * z),
            frf=(FREQS, t * (1 + 0.05 * zt)),
            sigma=sigma,
            mass_ratio_bounds=bounds,
            total_mass=s.masses.sum(),
        )
        rows.append(errors(sol, s))
    e = np.array(rows)
    print(
        f"\nChapter 4 setting, model update, {seeds} seeds: worst f error med/p90 "
        f"{100 * np.median(e[:, 0]):.2f}/{100 * np.percentile(e[:, 0], 90):.2f} %, worst damping error "
        f"{100 * np.median(e[:, 1]):.2f}/{100 * np.percentile(e[:, 1], 90):.2f} %, |dK|/|K| "
        f"{np.median(e[:, 2]):.3f}/{np.percentile(e[:, 2], 90):.3f}"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=8)
    args = parser.parse_args()
    run(args.seeds)
    chapter4(args.seeds)


if __name__ == "__main__":
    main()
