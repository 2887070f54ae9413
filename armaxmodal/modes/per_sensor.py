"""Table 3.2 of the thesis: each sensor's own frequency and damping of every selected mode
(gaps where the sensor does not show it) and the Eq. 3.35-3.36 residue-weighted averages.
"""

from __future__ import annotations

import numpy as np
import pandas as pd


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
