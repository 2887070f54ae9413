"""Each sensor's own view of the selected modes (thesis Section 3.3.4).

* ``per_sensor_table`` -- Table 3.2: each sensor's own frequency and damping of every
  selected mode (gaps where the sensor does not show it) and the Eq. 3.35-3.36
  residue-weighted averages.
* ``supplement_shapes`` -- a sensor whose own model does not show a mode leaves a gap in
  that mode's shape (the 'X' of Table 3.2). Eq. (3.34) fills it from the measured
  transmissibility at the damped natural frequency, ``phi_p = T_pl s_ql phi_l`` with the
  scale ``s_ql = |phi_q / phi_l| / |T_ql|`` taken from a known neighbour to reduce the
  influence of neighbouring modes.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

__all__ = ["per_sensor_table", "supplement_shapes", "transmissibility_at"]


def per_sensor_table(diagram, modes, shapes, cluster_freq):
    """Table 3.2 (per sensor, gaps as NaN) and the Eq. 3.35-3.36 weighted averages."""
    poles = diagram.poles
    sensors = diagram.recording.sensors
    rows = []
    for i, mode in enumerate(modes.itertuples(index=False)):
        for k, s in enumerate(sensors):
            nas = sorted(na for src, na in diagram.fits if src == s)
            own = poles[(poles.source == s) & (poles.rejected == "")]
            near = own[np.abs(own.freq_hz - mode.freq_hz) <= cluster_freq * mode.freq_hz]
            near = near.loc[near.groupby("na").energy.idxmax()] if len(near) else near
            relevant = [na for na in nas if na >= min(mode.na, nas[-1])] if nas else []
            shown = len(near) > 0 and len(near) >= 0.5 * len(relevant)
            own_const = np.nan + 0j
            if shown:
                at = near.iloc[int(np.argmin(np.abs(near.na.to_numpy() - mode.na)))]
                own_const = complex(at.vector[0])
            rows.append(
                {
                    "sensor": s,
                    "mode": i + 1,
                    "freq_hz": float(near.freq_hz.median()) if shown else np.nan,
                    "damping": float(near.damping.median()) if shown else np.nan,
                    "damped_freq_hz": float(near.damped_freq_hz.median()) if shown else np.nan,
                    "residue_mag": float(abs(shapes[k, i])),
                    "own_modal_constant": own_const,
                }
            )
    table = pd.DataFrame(rows)
    weighted = []
    for i, g in table.groupby("mode"):
        ok = g.dropna(subset=["freq_hz"])
        w = ok.residue_mag.to_numpy()
        weighted.append(
            {
                "mode": i,
                "freq_hz": float(np.sum(w * ok.freq_hz) / w.sum()) if len(ok) else np.nan,
                "damping": float(np.sum(w * ok.damping) / w.sum()) if len(ok) else np.nan,
                "sensors": len(ok),
            }
        )
    return table, pd.DataFrame(weighted)


def transmissibility_at(recording, freq_hz: float) -> np.ndarray:
    """Measured H1 of every sensor over the base input at one frequency (linear interpolation).

    Uses four averages only, for a fine frequency grid: a lightly damped resonance is
    narrower than the default plotting resolution, and Eq. (3.33) is read right at it.
    """
    from armaxmodal.spectra import measured_frf

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
