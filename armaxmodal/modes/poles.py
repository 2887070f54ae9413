"""The pole table of a sweep and its rules (thesis Section 3.3.2).

One row per pole of every fit (``pole_rows``), its stability class against the nearest
pole of the previous order of the same source (``stability_classes``: ``new``, ``f``,
``f+d``, ``f+d+v``) and the reason it is rejected, if any (``rejection_reasons``). The
thresholds are the :class:`Tolerances`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from armaxmodal.estimate.result import ArmaxFit
from armaxmodal.recording import Recording
from armaxmodal.spectra import excited_band
from armaxmodal.stats import MAX_DAMPING, Z95

__all__ = ["Tolerances", "pole_rows", "stability_classes", "rejection_reasons", "mac", "POLE_COLUMNS"]

SHARED = "shared"


CLASSES = ("new", "f", "f+d", "f+d+v")


#: rejection reason of a pole whose damping estimate is not positive but whose 95 % interval
#: reaches above zero: a lightly damped mode the record cannot resolve in damping. Such poles
#: count towards a mode's support, never as its estimate (see :func:`select_modes`).
UNRESOLVED_DAMPING = "damping not resolved"


@dataclass(frozen=True)
class Tolerances:
    """Stability tolerances between consecutive orders and the pole-rejection rules."""

    freq: float = 0.01  #: relative frequency change
    damping: float = 0.05  #: relative damping change
    shape: float = 0.02  #: 1 - MAC for shared shapes; relative residue change per sensor
    max_damping: float = MAX_DAMPING  #: heavier damping is not a vibration mode here
    min_freq_hz: float | None = None  #: default: 3 / record length
    max_freq_fraction: float = 0.45  #: of fs; poles near Nyquist are filter artefacts
    min_energy: float = 0.01  #: residue energy relative to the largest pole at that order (lower it
    #: to keep weakly excited modes; 0.1 % admits weak extra poles on real and band-limited data)
    min_input_db: float = -30.0  #: input PSD below this (dB re its peak): no excitation there


def mac(a: np.ndarray, b: np.ndarray) -> float:
    den = np.vdot(a, a).real * np.vdot(b, b).real
    return float(abs(np.vdot(a, b)) ** 2 / den) if den > 0 else 0.0


POLE_COLUMNS = [
    "source", "na", "freq_hz", "damping", "damped_freq_hz", "freq_sd", "damping_sd", "freq_ci95_lo",
    "freq_ci95_hi", "damping_ci95_lo", "damping_ci95_hi", "energy", "pole", "vector",
]  # fmt: skip


def pole_rows(fit: ArmaxFit, source: str) -> list[dict]:
    """Rows for one fit: shared fit -> one source with shapes over sensors."""
    rows = []
    if source == SHARED:
        table = fit.modes()
        frame = table[table.sensor == fit.sensors[0]]  # not query(): sensor names are free text
        mu = frame.pole.to_numpy()
        shapes = np.array([m.modal_constants(mu)[0] for m in fit.models]) if mu.size else np.zeros((0, 0))
        for i, r in enumerate(frame.itertuples(index=False)):
            rows.append(_row(source, fit, r, shapes[:, i], float(np.linalg.norm(shapes[:, i] * r.freq_hz))))
        return rows
    frame = fit.modes()
    mu = frame.pole.to_numpy()
    consts = fit.models[0].modal_constants(mu)[0] if mu.size else np.zeros(0)
    for i, r in enumerate(frame.itertuples(index=False)):
        rows.append(_row(source, fit, r, np.array([consts[i]]), float(abs(consts[i]) * r.freq_hz)))
    return rows


def _row(source, fit, r, shape, energy):
    return {
        "source": source,
        "na": fit.orders[0],
        "freq_hz": r.freq_hz,
        "damping": r.damping,
        "damped_freq_hz": r.damped_freq_hz,
        "freq_sd": r.freq_sd,
        "damping_sd": r.damping_sd,
        "freq_ci95_lo": r.freq_ci95_lo,
        "freq_ci95_hi": r.freq_ci95_hi,
        "damping_ci95_lo": r.damping_ci95_lo,
        "damping_ci95_hi": r.damping_ci95_hi,
        "energy": energy,
        "pole": r.pole,
        "vector": shape,
    }


def stability_classes(poles: pd.DataFrame, tol: Tolerances) -> list[str]:
    cls = ["new"] * len(poles)
    for _source, group in poles.groupby("source", sort=False):
        by_order = {na: g for na, g in group.groupby("na")}
        nas = sorted(by_order)
        for prev, cur in zip(nas[:-1], nas[1:], strict=True):
            p = by_order[prev]
            for idx, row in by_order[cur].iterrows():
                rel = np.abs(p.freq_hz.values - row.freq_hz) / row.freq_hz
                j = int(np.argmin(rel))
                if rel[j] > tol.freq:
                    continue
                label = "f"
                prev_row = p.iloc[j]
                if abs(prev_row.damping - row.damping) <= tol.damping * max(abs(row.damping), 1e-3):
                    label = "f+d"
                    if row.vector.size > 1:
                        same_shape = 1 - mac(row.vector, prev_row.vector) <= tol.shape
                    else:
                        same_shape = abs(abs(row.vector[0]) / max(abs(prev_row.vector[0]), 1e-300) - 1) <= 5 * tol.shape
                    if same_shape:
                        label = "f+d+v"
                cls[poles.index.get_loc(idx)] = label
    return cls


def rejection_reasons(poles: pd.DataFrame, tol: Tolerances, recording: Recording) -> list[str]:
    f_min = tol.min_freq_hz if tol.min_freq_hz is not None else 3.0 / recording.duration
    f_max = tol.max_freq_fraction * recording.fs
    band_lo, band_hi = excited_band(recording, tol.min_input_db)
    top = poles.groupby(["source", "na"]).energy.transform("max")
    reasons = []
    for row, e_max in zip(poles.itertuples(index=False), top, strict=True):
        if row.damping <= 0:
            sd = getattr(row, "damping_sd", 0.0)
            reasons.append(UNRESOLVED_DAMPING if row.damping + Z95 * sd > 0 else "negative damping")
        elif row.damping > tol.max_damping:
            reasons.append("over-damped")
        elif row.freq_hz < f_min:
            reasons.append("near 0 Hz")
        elif row.freq_hz > f_max:
            reasons.append("near Nyquist")
        elif row.freq_hz > band_hi * (1 + row.damping) or row.freq_hz < band_lo * (1 - row.damping):
            reasons.append("no input energy")
        elif row.energy < tol.min_energy * e_max:
            reasons.append("negligible residue")
        else:
            reasons.append("")
    return reasons
