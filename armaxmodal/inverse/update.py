"""Model updating: weighted nonlinear least squares of the chain's physical values on every
kind of modal data at once (the method recommended to users).

Residual blocks, each divided by its stated noise level so that none dominates by units:
frequencies and damping ratios (relative), complex or magnitude mode shapes (unit norm,
phase-aligned), complex or magnitude transmissibility (relative). Frequencies, damping,
shapes and transmissibility do not change when M, C and K are scaled together, so the
first mass is held at 1 during the fit and the scale is applied at the end (a mass in kg,
or the total mass). Started from :func:`inner_solve` unless a start is given.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.optimize

from ..exceptions import StructureError
from ..structure import Structure
from ._modal_data import check_modes
from .inner import inner_solve
from .result import InverseSolution

DEFAULT_SIGMA = {"freq": 0.01, "damping": 0.05, "shape": 0.05, "frf": 0.05}


def _unit(v: np.ndarray) -> np.ndarray:
    v = v / np.linalg.norm(v)
    big = v[np.argmax(np.abs(v))]
    return v * (abs(big) / big)


def model_update(
    eigenvalues=None,
    shapes=None,
    *,
    frf=None,
    sigma: dict | None = None,
    shape_magnitude_only: bool = False,
    frf_magnitude_only: bool = False,
    mass_ratio_bounds=None,
    m1: float | None = 1.0,
    total_mass: float | None = None,
    start: InverseSolution | None = None,
    names=None,
    max_nfev: int = 2000,
) -> InverseSolution:
    """Fit chain masses, springs and dampers to modal data and/or transmissibility.

    Parameters
    ----------
    eigenvalues : (n_modes,) complex, optional
        Measured continuous poles (rad/s); give frequencies and damping through these.
    shapes : (n_dof, n_modes) complex, optional
        Measured mode shapes (any scale).
    frf : (freq_hz (n_f,), T (n_f, n_dof) complex), optional
        Measured absolute-acceleration transmissibility over the base.
    sigma : dict, optional
        Noise levels: ``freq`` and ``damping`` (relative), ``shape`` (of a unit-norm shape),
        ``frf`` (relative). Defaults: 1 %, 5 %, 0.05, 5 %.
    shape_magnitude_only, frf_magnitude_only : bool
        Use magnitudes only for that block (phases not trusted).
    mass_ratio_bounds, m1, total_mass, names
        As :func:`inner_solve`.
    start : InverseSolution, optional
        Starting model (default: :func:`inner_solve` on the modes).
    """
    t_start = time.perf_counter()
    sig = {**DEFAULT_SIGMA, **(sigma or {})}
    if eigenvalues is None and frf is None:
        raise StructureError("model_update needs modal data (eigenvalues, shapes) or a transmissibility (frf).")
    lam = psi = None
    if eigenvalues is not None:
        if shapes is None:
            raise StructureError("shapes are needed with eigenvalues (for the start and the shape block).")
        lam, psi = check_modes(eigenvalues, shapes)
    if start is None:
        if lam is None:
            raise StructureError("without modal data give a start model (start=...).")
        start = inner_solve(lam, psi, mass_ratio_bounds=mass_ratio_bounds, m1=1.0, names=names)
    comps = start.components
    if comps is None:
        raise StructureError("the start model is not a chain; start from inner_solve or a chain.")
    n = comps.masses.size
    x0 = np.r_[comps.masses[1:], comps.c, comps.c_s, comps.k, comps.k_s] / comps.masses[0]
    kinds = np.r_[np.zeros(n - 1), np.ones(n), np.ones(n - 1), 2 * np.ones(n), 2 * np.ones(n - 1)]
    # each parameter in units of its start value (or of its kind's mean where the start is 0)
    floor = np.array([x0[kinds == k].mean() for k in kinds])
    scale = np.where(x0 > 1e-9 * floor, x0, floor)
    lo = np.full(x0.size, 0.0)  # physical units (first mass = 1) ...
    hi = np.full(x0.size, np.inf)
    if mass_ratio_bounds is not None:
        b = np.asarray(mass_ratio_bounds, dtype=float)
        lo[: n - 1], hi[: n - 1] = b[:, 0], b[:, 1]
    lo[kinds == 2] = 1e-9 * scale[kinds == 2]  # a spring must keep K positive definite
    lo, hi = lo / scale, hi / scale  # ... and in the optimiser's units (start values)

    def build(z):
        v = z * scale
        return Structure.from_chain(
            np.r_[1.0, v[: n - 1]],
            v[3 * n - 2 : 4 * n - 2],
            v[n - 1 : 2 * n - 1],
            v[4 * n - 2 :],
            v[2 * n - 1 : 3 * n - 2],
            names,
        )

    def residual(z):
        s = build(z)
        parts = []
        if lam is not None:
            model = s.modes()
            f_meas, x_meas = np.abs(lam) / (2 * np.pi), -lam.real / np.abs(lam)
            idx = [int(np.argmin(np.abs(model.freq_hz - f))) for f in f_meas]
            parts.append((model.freq_hz[idx] - f_meas) / (sig["freq"] * f_meas))
            parts.append((model.damping[idx] - x_meas) / (sig["damping"] * x_meas))
            for r, i in enumerate(idx):
                meas, mod = _unit(psi[:, r]), _unit(model.shapes[:, i])
                if shape_magnitude_only:
                    parts.append((np.abs(mod) - np.abs(meas)) / sig["shape"])
                else:
                    d = (mod - meas) / sig["shape"]
                    parts += [d.real, d.imag]
        if frf is not None:
            f, t_meas = frf
            t_mod = s.transmissibility(f)
            if frf_magnitude_only:
                parts.append(((np.abs(t_mod) - np.abs(t_meas)) / (sig["frf"] * np.abs(t_meas))).ravel())
            else:
                d = (t_mod - t_meas) / (sig["frf"] * np.abs(t_meas))
                parts += [d.real.ravel(), d.imag.ravel()]
        return np.concatenate(parts)

    z0 = np.clip(x0 / scale, lo, hi)
    res = scipy.optimize.least_squares(
        residual, z0, bounds=(lo, hi), method="trf", x_scale=1.0, xtol=1e-14, ftol=1e-14, gtol=1e-14, max_nfev=max_nfev
    )
    s = build(res.x)
    mass_scale = total_mass / s.masses.sum() if total_mass is not None else (m1 if m1 is not None else 1.0)
    comps = s.chain_components()
    s = Structure.from_chain(
        comps.masses * mass_scale,
        comps.k * mass_scale,
        comps.c * mass_scale,
        comps.k_s * mass_scale,
        comps.c_s * mass_scale,
        names,
    )
    flags = [] if res.success else [f"model updating stopped: {res.message}"]
    labels = (
        [f"m{i + 2}/m1" for i in range(n - 1)]
        + [f"c{i + 1}" for i in range(n)]
        + [f"c_s{i + 1}" for i in range(n - 1)]
        + [f"k{i + 1}" for i in range(n)]
        + [f"k_s{i + 1}" for i in range(n - 1)]
    )
    at_bound = [lab for lab, a in zip(labels, res.active_mask, strict=True) if a != 0]
    if at_bound:
        flags.append(f"at a bound: {', '.join(at_bound)} (a component at zero or a mass ratio at its limit)")
    return InverseSolution(
        s,
        s.chain_components(),
        s.modes(),
        {"weighted_rms": float(np.sqrt(np.mean(res.fun**2)))},
        "model_update",
        int(res.nfev),
        time.perf_counter() - t_start,
        bool(res.success),
        flags,
    )


def weight_sweep(eigenvalues, shapes, frf, weights=None, **kwargs):
    """Model updating over a range of relative weights of the FRF block against the modal
    blocks: the Pareto curve when the data disagree (Chapter 4's averaged modes against
    averaged transmissibilities, which no single chain fits at once).

    Parameters
    ----------
    eigenvalues, shapes, frf : as :func:`model_update`.
    weights : sequence of float
        Multipliers of the FRF block's weight (its noise level is divided by each).
    **kwargs : passed to :func:`model_update`.

    Returns
    -------
    pandas.DataFrame
        One row per weight: weight, modal_rms (frequency, damping and shape residuals in
        noise units), frf_rms, and the model's frequencies and damping ratios.
    """
    import pandas as pd

    weights = np.logspace(-2, 2, 9) if weights is None else np.asarray(weights, dtype=float)
    sig = {**DEFAULT_SIGMA, **kwargs.pop("sigma", {})}
    lam, psi = check_modes(eigenvalues, shapes)
    f, t_meas = frf
    rows = []
    for w in weights:
        sol = model_update(lam, psi, frf=frf, sigma={**sig, "frf": sig["frf"] / w}, **kwargs)
        modal = model_update_residuals(sol.structure, lam, psi, None, sig)
        t_mod = sol.structure.transmissibility(f)
        frf_rms = float(np.sqrt(np.mean(np.abs((t_mod - t_meas) / (sig["frf"] * np.abs(t_meas))) ** 2)))
        rows.append(
            {
                "weight": w,
                "modal_rms": float(np.sqrt(np.mean(modal**2))),
                "frf_rms": frf_rms,
                **{f"f{i + 1}_hz": v for i, v in enumerate(sol.modes.freq_hz)},
                **{f"damping{i + 1}": v for i, v in enumerate(sol.modes.damping)},
            }
        )
    return pd.DataFrame(rows)


def model_update_residuals(structure, lam, psi, frf, sig) -> np.ndarray:
    """The modal residual blocks of :func:`model_update` for a given structure (noise units)."""
    model = structure.modes()
    f_meas, x_meas = np.abs(lam) / (2 * np.pi), -lam.real / np.abs(lam)
    idx = [int(np.argmin(np.abs(model.freq_hz - f))) for f in f_meas]
    parts = [
        (model.freq_hz[idx] - f_meas) / (sig["freq"] * f_meas),
        (model.damping[idx] - x_meas) / (sig["damping"] * x_meas),
    ]
    for r, i in enumerate(idx):
        d = (_unit(model.shapes[:, i]) - _unit(psi[:, r])) / sig["shape"]
        parts += [d.real, d.imag]
    return np.concatenate(parts)
