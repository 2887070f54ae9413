"""A mode the model lacks: the model's FRF against the measured H1, beyond the H1's own
random error (Bendat & Piersol's ``sqrt((1 - g^2) / (g^2 n_d))``, ``armaxmodal.spectra.h1_relative_error``)."""

from __future__ import annotations

import numpy as np

from armaxmodal.diagnosis.model import FittedModel, usable
from armaxmodal.spectra import coherence, h1_relative_error, welch_spectra
from armaxmodal.stats import MISFIT_COHERENCE, welch_nperseg

__all__ = ["mode_findings", "added_modes", "MODEL_CLASS_FLOOR"]

#: Relative FRF misfit a correct model may still show: the discrete ARMAX class differs from
#: band-limited data by a few per cent near the band edge (the reason the stabilise refit
#: exists). A missing mode misses its peak by tens of per cent.
MODEL_CLASS_FLOOR = 0.05


def _misfit(fitted: FittedModel):
    """Per Welch line and sensor, ``|H_model - H1|^2 / ((sigma^2 + floor^2) |H1|^2)``: about
    Exp(1) where the model is right. Every other line, as 50 %-overlapped Hann segments make
    neighbours correlated."""
    s = fitted.signals
    mask = usable(s.n, fitted.spec)
    u, y = s.u[mask], (s.y - fitted.disturbance())[mask]
    nperseg = welch_nperseg(u.size, s.fs)
    f, puu, puy, pyy = welch_spectra(u, y, s.fs, nperseg)
    h1 = puy / puu[:, None]
    coh = coherence(puu, puy, pyy)
    sigma = h1_relative_error(coh, u.size, nperseg)
    model = np.column_stack([m.frf(f)[:, 0] for m in fitted.fit.models])
    rel = np.abs(model - h1) / np.maximum(np.abs(h1), 1e-300)
    z = rel**2 / (sigma**2 + MODEL_CLASS_FLOOR**2)
    live = (coh >= MISFIT_COHERENCE) & (f[:, None] > 0) & (f[:, None] < 0.45 * s.fs)
    keep = slice(None, None, 2)
    return f[keep], np.where(live, z, 0.0)[keep], rel[keep], sigma[keep], live[keep]


def mode_findings(fitted: FittedModel, n_tests: int, table: dict) -> list:
    """Per sensor the largest misfit, its p-value under Exp(1) corrected for the lines and
    for sensors x tests (a Bonferroni bound)."""
    from armaxmodal.diagnosis.finding import Finding

    f, z, rel, sigma, live = _misfit(fitted)
    old = [float(v) for v in fitted.fit.models[0].modal_parameters()[1] if v > 0]
    out = []
    for k, name in enumerate(fitted.signals.sensors):
        n_lines = max(int(live[:, k].sum()), 1)
        i = int(np.argmax(z[:, k]))
        p = min(1.0, float(np.exp(-z[i, k])) * n_lines * n_tests)
        table.setdefault("frf_misfit_p", []).append(p)
        params = {"worst_misfit_hz": float(f[i]), "misfit_rel": float(rel[i, k]), "h1_error_rel": float(sigma[i, k])}
        out.append(Finding("unmodelled_mode", (name,), "frf_misfit_z", float(z[i, k]), p, params, payload=old))
    return out


def added_modes(before_hz: list[float], fitted: FittedModel) -> list[dict]:
    """The refitted model's modes with no counterpart (within 5 %) before the fix."""
    _, f, xi, _ = fitted.fit.models[0].modal_parameters()
    new = []
    for v, x in zip(f, xi, strict=True):
        if 0 < v < fitted.signals.fs / 2 and 0 < x < 1 and all(abs(v / b - 1) > 0.05 for b in before_hz):
            new.append({"freq_hz": float(v), "damping": float(x)})
    return new
