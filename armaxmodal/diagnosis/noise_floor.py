"""The noise floor: what a perfect linear model of the base input would still leave in each
output's simulation error (the part not coherent with the input), against which the final
error is read."""

from __future__ import annotations

import numpy as np

from armaxmodal.diagnosis.model import PiecewiseModel, Signals
from armaxmodal.spectra import coherence, welch_spectra
from armaxmodal.stats import welch_nperseg

__all__ = ["FLOOR_SETTLED", "extra_input_response", "noise_floor"]


def extra_input_response(model) -> np.ndarray:
    """The response to the model's second inputs, (n, K): what the noise floor, a coherence
    with the base alone, must not count as noise. Not a nonlinear term's: built from the
    response to the base, it is collinear with it, and its B alone may be large where the
    base's B cancels it (on the F-16 the floor rose above the residual tenfold)."""
    if isinstance(model, PiecewiseModel):
        return model._join(*(extra_input_response(m) for m in (model.before, model.after)))
    u = model.signals.inputs(model.spec).copy()
    second = [1 + i for i, name in enumerate(model.spec.terms) if name in model.spec.inputs_from]
    u[:, [m for m in range(u.shape[1]) if m not in second]] = 0.0
    if not second:
        return np.zeros_like(model.signals.y)
    return np.column_stack([m.simulate(u) for m in model.fit.models])


def noise_floor(s: Signals, mask: np.ndarray, linear_error: dict | None = None) -> dict:
    """``{output: RMS}`` of the output part not coherent with the input (Welch H1): what a
    perfect linear model of this input would still leave in its simulation error; ``None``
    where the record cannot resolve it.

    Short segments smear a lightly damped peak, and the coherence there drops for want of
    resolution, not for noise: on the F-16 (0.5 % damping, 10 s segments) the floor came out
    three times the linear model's own held-out error. So the segment doubles from 10 s (at
    most an eighth of the record) while that lowers the floor by more than ``FLOOR_SETTLED``,
    the longer one up to a quarter of the record; a floor still falling there is not resolved.
    Nor is one above ``linear_error`` (``{output: RMS}``, a linear model's held-out simulation
    error, which the floor bounds from below): both segments may be far too short."""
    u, y = s.u[mask], s.y[mask]
    nperseg = welch_nperseg(u.size, s.fs)
    floor = _welch_floor(u, y, s.fs, nperseg)
    settled = np.zeros(floor.size, bool)
    while not settled.all() and 2 * nperseg <= u.size // 4:
        nperseg *= 2
        finer = _welch_floor(u, y, s.fs, nperseg)
        settled |= finer >= (1 - FLOOR_SETTLED) * floor
        floor = np.where(settled, floor, finer)
    bound = linear_error or {}
    settled &= np.array([floor[k] <= bound.get(name, np.inf) for k, name in enumerate(s.sensors)])
    return {name: float(v) if ok else None for name, v, ok in zip(s.sensors, floor, settled, strict=True)}


#: Relative drop of the noise floor on doubling the segment below which it has settled.
FLOOR_SETTLED = 0.2


def _welch_floor(u: np.ndarray, y: np.ndarray, fs: float, nperseg: int) -> np.ndarray:
    f, puu, puy, pyy = welch_spectra(u, y, fs, nperseg)
    coh = coherence(puu, puy, pyy)
    return np.sqrt(np.sum((1 - coh) * pyy, axis=0) * (f[1] - f[0]))
