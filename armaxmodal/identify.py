"""One fixed- or automatically-ordered identification: fit, physical modes, shapes, JSON.

The modes come from the shared-pole fit (every sensor sees the same poles); the per-sensor
table lists, for each mode, how strongly each sensor shows it (the residue magnitude).
Physical poles are those with damping in (0, ``max_damping``] inside ``band``; the full
stabilisation-based selection lives in the stabilisation module.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .fit import ArmaxFit, fit_armax
from .orders import OrderChoice, choose_orders
from .recording import Recording

__all__ = ["identify", "Identification", "DEFAULT_MAX_DAMPING"]

#: Heavily damped biomechanical modes reach 0.4-0.5; 0.6 keeps them and drops filter poles.
DEFAULT_MAX_DAMPING = 0.6


@dataclass(frozen=True)
class Identification:
    """Modes of one recording.

    Attributes
    ----------
    fit : ArmaxFit
    modes : DataFrame
        One row per physical mode: freq_hz, damping, damped_freq_hz, CI bounds.
    shapes : (n_sensors, n_modes) complex ndarray
        EPFRF modal constants per sensor (Eq. 3.24), the mode-shape components.
    recording : Recording
    order_table : DataFrame or None
        The criterion table when the orders were chosen automatically.
    """

    fit: ArmaxFit
    modes: pd.DataFrame
    shapes: np.ndarray
    recording: Recording
    order_table: pd.DataFrame | None = None

    def to_dict(self) -> dict:
        """The JSON contract: fs, input, outputs, modes (with shapes) and per_sensor rows."""
        rec = self.recording
        modes = [mode_record(row, self.shapes[:, i], rec.sensors) for i, row in enumerate(self.modes.itertuples())]
        per_sensor = [
            {
                "sensor": s,
                "mode": i + 1,
                "freq_hz": float(row.freq_hz),
                "damping": float(row.damping),
                "residue_mag": float(abs(self.shapes[k, i])),
            }
            for i, row in enumerate(self.modes.itertuples(index=False))
            for k, s in enumerate(rec.sensors)
        ]
        na, nb, nc, nk = self.fit.orders
        return {
            "fs": rec.fs,
            "input": rec.input_name,
            "outputs": list(rec.sensors),
            "orders": {"na": na, "nb": nb, "nc": nc, "nk": nk, "shared_poles": self.fit.shared_poles},
            "converged": bool(np.all(self.fit.converged)),
            "fit_percent": dict(zip(rec.sensors, map(float, self.fit.fit_percent), strict=True)),
            "modes": modes,
            "per_sensor": per_sensor,
        }


def mode_record(row, shape: np.ndarray, sensors, supplemented=None) -> dict:
    """One mode of the JSON contract: frequency, damping, 95 % intervals and the shape
    (normalised to a unit largest component on the positive real axis) per sensor."""
    big = shape[np.argmax(np.abs(shape))]
    shape = shape / big if abs(big) > 0 else shape
    flags = np.zeros(len(sensors), dtype=bool) if supplemented is None else supplemented
    return {
        "freq_hz": float(row.freq_hz),
        "damping": float(row.damping),
        "damped_freq_hz": float(row.damped_freq_hz),
        "freq_ci95": [float(row.freq_ci95_lo), float(row.freq_ci95_hi)],
        "damping_ci95": [float(row.damping_ci95_lo), float(row.damping_ci95_hi)],
        "shape": {
            s: {"mag": float(abs(v)), "phase_deg": float(np.degrees(np.angle(v))), "supplemented": bool(f)}
            for s, v, f in zip(sensors, shape, flags, strict=True)
        },
    }


def identify(
    recording: Recording,
    orders: tuple[int, int, int, int] | None = None,
    *,
    band: tuple[float, float] | None = None,
    max_damping: float = DEFAULT_MAX_DAMPING,
    progress: bool = False,
) -> Identification:
    """Fit the shared-pole ARMAX model and report its physical modes.

    Parameters
    ----------
    recording : Recording
    orders : (na, nb, nc, nk), optional
        Fixed orders; by default chosen by BIC (:func:`armaxmodal.orders.choose_orders`).
    band : (lo, hi), optional
        Frequency band of interest, Hz (default: 0 to 0.45 fs).
    max_damping : float
        Poles damped more than this are not reported as modes.
    progress : bool
        Show a progress bar during the automatic order search.
    """
    choice: OrderChoice | None = None
    if orders is None:
        choice = choose_orders(recording, progress=progress)
        fit = choice.fit
    else:
        fit = fit_armax(recording, *orders, shared_poles=True)
    lo, hi = band if band is not None else (0.0, 0.45 * recording.fs)
    first = fit.modes().query(f"sensor == '{fit.sensors[0]}'")
    keep = (first.damping > 0) & (first.damping <= max_damping) & (first.freq_hz >= lo) & (first.freq_hz <= hi)
    modes = first[keep].drop(columns=["sensor", "residue", "residue_mag", "residue_phase_deg"]).reset_index(drop=True)
    mu = modes.pole.to_numpy()
    shapes = np.array([m.modal_constants(mu)[0] for m in fit.models]) if mu.size else np.zeros((len(fit.models), 0))
    return Identification(fit, modes, shapes, recording, None if choice is None else choice.table)
