"""From per-sensor results to modes, and from subjects to a group (thesis Sections 3.3.4, 3.4).

* :func:`supplement_shapes` -- a sensor whose own model does not show a mode leaves a gap in
  that mode's shape (the 'X' of Table 3.2). Eq. (3.34) fills it from the measured
  transmissibility at the damped natural frequency, ``phi_p = T_pl s_ql phi_l`` with the
  scale ``s_ql = |phi_q / phi_l| / |T_ql|`` taken from a known neighbour to reduce the
  influence of neighbouring modes.
* :func:`summarise_subjects` -- Table 3.3: per subject the |M|-weighted frequency and
  damping (Eqs. 3.35-3.36), then the mean and standard deviation over subjects, and the
  geometric-mean mode-shape magnitudes (Fig. 3.7).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pandas as pd

from armaxmodal.exceptions import DataError

__all__ = ["supplement_shapes", "summarise_subjects", "transmissibility_at"]


def transmissibility_at(recording, freq_hz: float) -> np.ndarray:
    """Measured H1 of every sensor over the base input at one frequency (linear interpolation).

    Uses four averages only, for a fine frequency grid: a lightly damped resonance is
    narrower than the default plotting resolution, and Eq. (3.33) is read right at it.
    """
    from armaxmodal.prepare.frf import measured_frf

    f, h, _ = measured_frf(recording, nperseg=max(recording.n_samples // 4, 16))
    return np.array(
        [np.interp(freq_hz, f, h[:, k].real) + 1j * np.interp(freq_hz, f, h[:, k].imag) for k in range(h.shape[1])]
    )


def supplement_shapes(selection) -> tuple[np.ndarray, np.ndarray]:
    """Per-sensor mode shapes with the gaps filled by Eq. (3.34).

    Parameters
    ----------
    selection : ModeSelection

    Returns
    -------
    shapes : (n_sensors, n_modes) complex ndarray
        Each sensor's own modal constant where it shows the mode, Eq. (3.34) elsewhere.
    supplemented : (n_sensors, n_modes) bool ndarray
        True where a component was filled from the transmissibility.
    """
    table = selection.per_sensor
    sensors = list(selection.diagram.recording.sensors)
    n_modes = len(selection.modes)
    shapes = np.full((len(sensors), n_modes), np.nan + 0j)
    for row in table.itertuples(index=False):
        shapes[sensors.index(row.sensor), row.mode - 1] = row.own_modal_constant
    supplemented = np.zeros(shapes.shape, dtype=bool)
    for r, mode in enumerate(selection.modes.itertuples(index=False)):
        known = np.flatnonzero(~np.isnan(shapes[:, r]))
        missing = np.flatnonzero(np.isnan(shapes[:, r]))
        if missing.size == 0:
            continue
        if known.size == 0:
            # no sensor shows it on its own: fall back on the shared-pole shape, all flagged
            shapes[:, r] = selection.shapes[:, r]
            supplemented[:, r] = True
            continue
        t = transmissibility_at(selection.diagram.recording, mode.damped_freq_hz)
        order = known[np.argsort(-np.abs(shapes[known, r]))]
        ell = order[0]  # reference: the largest known component
        scale = 1.0
        if order.size > 1:
            q = order[1]  # a known neighbour fixes the scale (s_ql)
            scale = abs(shapes[q, r] / shapes[ell, r]) / abs(t[q] / t[ell])
        for p in missing:
            shapes[p, r] = (t[p] / t[ell]) * scale * shapes[ell, r]
            supplemented[p, r] = True
    return shapes, supplemented


def summarise_subjects(
    weighted: Sequence[pd.DataFrame], shapes: Sequence[np.ndarray] | None = None, subjects: Sequence[str] | None = None
) -> dict:
    """Table 3.3 and the Fig. 3.7 geometric-mean shapes over subjects.

    Parameters
    ----------
    weighted : sequence of DataFrame
        Per subject, one row per mode with ``freq_hz`` and ``damping`` (the Eq. 3.35-3.36
        weighted values, e.g. ``ModeSelection.weighted``); every subject must have the
        same modes in the same order.
    shapes : sequence of (n_sensors, n_modes) arrays, optional
        Per subject mode shapes; magnitudes are normalised to a unit largest component.
    subjects : sequence of str, optional

    Returns
    -------
    dict with ``table`` (one row per subject plus ``Average`` and ``SD`` rows, sample SD)
    and ``shape_geomean`` ((n_sensors, n_modes), when shapes are given).
    """
    counts = {len(w) for w in weighted}
    if len(counts) != 1:
        raise DataError(
            f"subjects have different numbers of modes {sorted(counts)}; select the same number "
            "for each (select_modes(..., n_modes=N), CLI --modes N) before summarising."
        )
    names = list(subjects) if subjects is not None else [f"Sub{i + 1}" for i in range(len(weighted))]
    n_modes = counts.pop()
    f = np.array([w.freq_hz.to_numpy() for w in weighted], dtype=float)
    x = np.array([w.damping.to_numpy() for w in weighted], dtype=float)
    cols = [f"f{i + 1}_hz" for i in range(n_modes)] + [f"damping{i + 1}" for i in range(n_modes)]
    table = pd.DataFrame(np.hstack([f, x]), index=names, columns=cols)
    table.loc["Average"] = np.hstack([f.mean(axis=0), x.mean(axis=0)])
    table.loc["SD"] = np.hstack([f.std(axis=0, ddof=1), x.std(axis=0, ddof=1)])
    out = {"table": table}
    if shapes is not None:
        mags = np.array([np.abs(s) / np.abs(s).max(axis=0, keepdims=True) for s in shapes])
        out["shape_geomean"] = np.exp(np.mean(np.log(mags), axis=0))
    return out
