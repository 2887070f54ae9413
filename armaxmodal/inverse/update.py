"""Model updating: weighted nonlinear least squares of the chain's physical values on every
kind of modal data at once (the method recommended to users).

Residual blocks, each divided by its stated noise level so that none dominates by units:
frequencies and damping ratios (relative), complex or magnitude mode shapes and
transmissibility. Shapes and transmissibility carry relative (multiplicative) noise, so their
residuals are log ratios (log magnitude and phase of measured over model; for a shape after
removing its free complex factor): their spread is the same at every line and component, so
small components and FRF troughs get the weight their precision earns. On the Chapter 2 P2
protocol this halves the matrix errors against differences scaled by the measured magnitude
and brings them to the Cramér-Rao bound (scripts/inverse_study.py). Frequencies, damping,
shapes and transmissibility do not change when M, C and K are scaled together, so the
first mass is held at 1 during the fit and the scale is applied at the end (a mass in kg,
or the total mass). Started from :func:`~armaxmodal.inverse.inner_solve` unless a start is given.
"""

from __future__ import annotations

import time
from functools import partial

import numpy as np
import scipy.optimize

from armaxmodal.exceptions import StructureError
from armaxmodal.inverse.inner import inner_solve
from armaxmodal.inverse.modal_data import check_modes
from armaxmodal.inverse.result import InverseSolution
from armaxmodal.systems.structure import ChainComponents, Structure

DEFAULT_SIGMA = {"freq": 0.01, "damping": 0.05, "shape": 0.05, "frf": 0.05}


def _log_ratio(meas: np.ndarray, model: np.ndarray, sigma: float, magnitude_only: bool) -> list[np.ndarray]:
    """Residuals of relative (multiplicative) noise: log|meas/model| and the phase of
    meas/model, in noise units. Unlike (model - meas)/|meas| their spread does not depend on
    the parameters or on the noisy data, so least squares on them is not pulled towards
    larger or smaller magnitudes."""
    ratio = (meas / model).ravel()
    ratio = np.where(ratio == 0, 1e-300, ratio)  # a model zero gives a huge, finite residual
    # complex relative error of rms sigma: sigma/sqrt(2) per part (log magnitude, phase)
    part_sd = np.broadcast_to(sigma, np.shape(meas)).ravel() / np.sqrt(2)
    parts = [np.log(np.abs(ratio)) / part_sd]
    if not magnitude_only:
        parts.append(np.angle(ratio) / part_sd)
    return parts


def _shape_residual(meas: np.ndarray, model: np.ndarray, sigma: float, magnitude_only: bool) -> list[np.ndarray]:
    """Component-relative shape residual: log ratio of each component to the model's, after
    removing the best common complex factor (a shape has no scale or phase of its own)."""
    ratio = meas / model
    ratio = ratio / np.exp(np.mean(np.log(np.abs(ratio))))
    if not magnitude_only:
        ref = np.sum(ratio)  # phase of the mean ratio: the common rotation, free of wrapping
        ratio = ratio * (abs(ref) / ref)
    return _log_ratio(ratio, np.ones_like(ratio), sigma, magnitude_only)


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
        Noise levels, all relative standard deviations: ``freq``, ``damping`` (scalars or one
        per mode), ``shape`` (of each shape component, complex rms) and ``frf`` (of each
        transmissibility value, complex rms; a scalar or an array shaped like T, e.g. from the
        coherence, see ``armaxmodal.spectra.h1_relative_error``). Defaults: 1 %, 5 %, 5 %, 5 %.
    shape_magnitude_only, frf_magnitude_only : bool
        Use magnitudes only for that block (phases not trusted).
    mass_ratio_bounds, m1, total_mass, names
        As :func:`~armaxmodal.inverse.inner_solve`.
    start : InverseSolution, optional
        Starting model (default: :func:`~armaxmodal.inverse.inner_solve` on the modes).
    max_nfev : int
        Cap on residual evaluations of the least-squares fit.

    Returns
    -------
    InverseSolution
        The updated chain with its standard errors and misfits.

    See Also
    --------
    armaxmodal.inverse.evphc : The inverse modal problem by eigenvector phase correction.
    armaxmodal.inverse.pia : The Pilkey-Inman baseline, from all complex modes and a known mass.

    Examples
    --------
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> body = am.supine_human()
    >>> modes = body.modes()
    >>> f = np.linspace(1.0, 25.0, 200)
    >>> start = am.inner_solve(modes.eigenvalues, modes.shapes, total_mass=body.masses.sum())
    >>> solution = am.model_update(modes.eigenvalues, modes.shapes, frf=(f, body.transmissibility(f)), start=start,
    ...                            total_mass=body.masses.sum())
    >>> np.round(solution.structure.masses, 2)
    array([ 6.23, 21.37, 30.01, 19.95])
    """
    t_start = time.perf_counter()
    sig = {**DEFAULT_SIGMA, **(sigma or {})}
    lam, psi = _checked_data(eigenvalues, shapes, frf)
    if start is None:
        if lam is None:
            raise StructureError("without modal data give a start model (start=...).")
        start = inner_solve(lam, psi, mass_ratio_bounds=mass_ratio_bounds, m1=1.0, names=names)
    comps = start.components
    if comps is None:
        raise StructureError("the start model is not a chain; start from inner_solve or a chain.")
    n = comps.masses.size
    x0, scale, lo, hi = _parameters(comps, mass_ratio_bounds)
    build = partial(_chain, scale=scale, n=n, names=names)

    def residual(z):
        return _residual(build(z), lam, psi, frf, sig, shape_magnitude_only, frf_magnitude_only)

    z0 = np.clip(x0 / scale, lo, hi)
    res = scipy.optimize.least_squares(
        residual, z0, bounds=(lo, hi), method="trf", x_scale=1.0, xtol=1e-14, ftol=1e-14, gtol=1e-14, max_nfev=max_nfev
    )
    s = build(res.x)
    mass_scale = total_mass / s.masses.sum() if total_mass is not None else (m1 if m1 is not None else 1.0)
    s = _scaled(s, mass_scale, names)
    std = _component_std(res, scale, n, total_mass, mass_scale, s.chain_components())
    return InverseSolution(
        s,
        s.chain_components(),
        s.modes(),
        {"weighted_rms": float(np.sqrt(np.mean(res.fun**2)))},
        "model_update",
        int(res.nfev),
        time.perf_counter() - t_start,
        bool(res.success),
        _flags(res, n),
        std,
    )


def _checked_data(eigenvalues, shapes, frf) -> tuple:
    """``(lam, psi)``, None without modal data; refused when no block can be fitted."""
    if eigenvalues is None and frf is None:
        raise StructureError("model_update needs modal data (eigenvalues, shapes) or a transmissibility (frf).")
    lam = psi = None
    if eigenvalues is not None:
        if shapes is None:
            raise StructureError("shapes are needed with eigenvalues (for the start and the shape block).")
        lam, psi = check_modes(eigenvalues, shapes)
    for label, values in (("shapes", psi), ("frf", None if frf is None else frf[1])):
        if values is not None and np.any(np.asarray(values) == 0):
            raise StructureError(
                f"{label}: a value is exactly zero; their noise is modelled as relative, so a zero (a "
                "missing or dead channel) cannot be fitted. Drop that sensor or fill the gap first."
            )
    return lam, psi


def _parameters(comps: ChainComponents, mass_ratio_bounds) -> tuple:
    """The start ``x0`` (first mass = 1: mass ratios, dampers, springs), each parameter's
    ``scale`` and the bounds ``lo``, ``hi`` in the optimiser's units (start values)."""
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
    return x0, scale, lo / scale, hi / scale  # ... and in the optimiser's units (start values)


def _chain(z, scale, n, names) -> Structure:
    """The chain of the optimiser's parameters ``z`` (first mass 1)."""
    v = z * scale
    return Structure.from_chain(
        np.r_[1.0, v[: n - 1]],
        v[3 * n - 2 : 4 * n - 2],
        v[n - 1 : 2 * n - 1],
        v[4 * n - 2 :],
        v[2 * n - 1 : 3 * n - 2],
        names,
    )


def _residual(s: Structure, lam, psi, frf, sig, shape_magnitude_only, frf_magnitude_only) -> np.ndarray:
    """Every block's misfit in units of its noise: frequencies, damping, shapes, transmissibility."""
    parts = []
    if lam is not None:
        model = s.modes()
        f_meas, x_meas = np.abs(lam) / (2 * np.pi), -lam.real / np.abs(lam)
        idx = [int(np.argmin(np.abs(model.freq_hz - f))) for f in f_meas]
        parts.append((model.freq_hz[idx] - f_meas) / (sig["freq"] * f_meas))
        parts.append((model.damping[idx] - x_meas) / (sig["damping"] * x_meas))
        for r, i in enumerate(idx):
            parts += _shape_residual(psi[:, r], model.shapes[:, i], sig["shape"], shape_magnitude_only)
    if frf is not None:
        f, t_meas = frf
        t_mod = s.transmissibility(f)
        parts += _log_ratio(t_meas, t_mod, sig["frf"], frf_magnitude_only)
    return np.concatenate(parts)


def _scaled(s: Structure, mass_scale: float, names) -> Structure:
    """The fitted chain (first mass 1) at the mass scale."""
    comps = s.chain_components()
    # components read back from C and K carry round-off (seen: a damper of -9e-14 N s/m where
    # the optimiser's bound is 0); the bounds are exact, so clip to them
    return Structure.from_chain(
        comps.masses * mass_scale,
        np.maximum(comps.k, 0.0) * mass_scale,
        np.maximum(comps.c, 0.0) * mass_scale,
        np.maximum(comps.k_s, 0.0) * mass_scale,
        np.maximum(comps.c_s, 0.0) * mass_scale,
        names,
    )


def _flags(res, n: int) -> list[str]:
    """What the user must know about the fit: stopped early, blocks in disagreement, values at a bound."""
    flags = [] if res.success else [f"model updating stopped: {res.message}"]
    dof = max(res.fun.size - int(np.sum(res.active_mask == 0)), 1)
    if np.sum(res.fun**2) / dof > 2.0:
        flags.append(
            f"the data blocks disagree beyond their stated noise (weighted rms {np.sqrt(np.sum(res.fun**2) / dof):.2f}"
            " > 1): noise levels understated or the chain misses an effect; standard errors widened to match"
        )
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
    return flags


def _component_std(res, scale, n, total_mass, mass_scale, comps: ChainComponents) -> ChainComponents:
    """Standard errors of the physical chain values: Gauss-Newton covariance of the free
    parameters (residuals in noise units; scaled up by the reduced chi-square when above 1), mapped through the
    mass scale (m1 fixed, or the total mass fixed, which makes m1 uncertain too)."""
    free = res.active_mask == 0
    j = res.jac[:, free] / scale[free]  # d residual / d (value with m1 = 1); z = value / scale
    # Birge ratio: when the blocks disagree beyond their stated noise, widen rather than trust it
    birge = max(1.0, float(np.sum(res.fun**2)) / max(res.fun.size - int(free.sum()), 1))
    cov_x = np.zeros((scale.size, scale.size))
    cov_x[np.ix_(free, free)] = birge * np.linalg.pinv(j.T @ j)
    x = res.x * scale
    # physical values p = mass_scale(x) * [1, x]; the scale depends on the masses when the total is fixed
    d_scale = np.zeros(scale.size)
    if total_mass is not None:
        d_scale[: n - 1] = -mass_scale / (1.0 + x[: n - 1].sum())
    jac = np.vstack([d_scale, mass_scale * np.eye(scale.size) + np.outer(x, d_scale)])
    sd = np.sqrt(np.clip(np.diag(jac @ cov_x @ jac.T), 0.0, None))
    return ChainComponents(
        masses=sd[:n],
        c=sd[n : 2 * n],
        c_s=sd[2 * n : 3 * n - 1],
        k=sd[3 * n - 1 : 4 * n - 1],
        k_s=sd[4 * n - 1 :],
        names=comps.names,
    )


def weight_sweep(eigenvalues, shapes, frf, weights=None, **kwargs):
    """Model updating over a range of relative weights of the FRF block against the modal
    blocks: the Pareto curve when the data disagree (Chapter 4's averaged modes against
    averaged transmissibilities, which no single chain fits at once).

    Parameters
    ----------
    eigenvalues, shapes, frf
        As :func:`~armaxmodal.inverse.model_update`.
    weights : sequence of float
        Multipliers of the FRF block's weight (its noise level is divided by each).
    **kwargs
        Passed to :func:`~armaxmodal.inverse.model_update`.

    Returns
    -------
    pandas.DataFrame
        One row per weight: weight, modal_rms (frequency, damping and shape residuals in
        noise units), frf_rms, and the model's frequencies and damping ratios.

    See Also
    --------
    armaxmodal.inverse.model_update : The joint update the weight sets.

    Examples
    --------
    The supine body's exact modes against the FRF of the same body with the legs' spring 30 %
    softer: weighted lightly, the FRF block gives way to the modes; weighted heavily, the modes
    give way to it (the first mode moves from 5.83 to 5.80 Hz):

    >>> import numpy as np
    >>> import armaxmodal as am
    >>> from armaxmodal.inverse import weight_sweep
    >>> body = am.supine_human()
    >>> c = body.chain_components()
    >>> softer = am.Structure.from_chain(c.masses, c.k * [1, 1, 1, 0.7], c.c, c.k_s, c.c_s, c.names)
    >>> f = np.linspace(1.0, 25.0, 200)
    >>> sweep = weight_sweep(body.modes().eigenvalues, body.modes().shapes, (f, softer.transmissibility(f)),
    ...                      weights=[0.01, 100.0], total_mass=body.masses.sum())
    >>> sweep[["weight", "modal_rms", "frf_rms", "f1_hz"]].round(2)
       weight  modal_rms  frf_rms  f1_hz
    0    0.01       0.00     0.16   5.83
    1  100.00       0.11     0.00   5.80
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
        frf_rms = float(np.sqrt(np.mean(np.concatenate(_log_ratio(t_meas, t_mod, sig["frf"], False)) ** 2)))
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
        parts += _shape_residual(psi[:, r], model.shapes[:, i], sig["shape"], False)
    return np.concatenate(parts)
