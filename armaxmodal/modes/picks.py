"""Modes picked by hand: each frequency the analyst gives takes the nearest stable cluster of the
diagram, as the thesis picked its modes from its diagrams (and as MATLAB's ``modalfit``, pyOMA2's
``mpe(sel_freq=...)`` and sdypy-EMA's ``select_closest_poles`` take physical frequencies).

A pick is then refitted, checked and judged like an automatic mode; it is not dropped for want of
support, but the maximum-likelihood modal model says when the record does not need it.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from armaxmodal.exceptions import PickError
from armaxmodal.modes.clusters import candidate_poles, cluster_poles, mode_row, order_criteria, representative_pole
from armaxmodal.modes.settings import DEFAULTS, ClusterSettings

__all__ = ["check_picks", "picked_modes"]


def check_picks(picks, band, fs: float, cluster: ClusterSettings = DEFAULTS.cluster) -> np.ndarray:
    """The picked frequencies (Hz) as a sorted array, refused with the reason when one is not a
    finite positive number, lies outside ``band`` (Hz) or at or above the Nyquist frequency, or
    when two picks would take one cluster.

    Parameters
    ----------
    picks : sequence of float
        Frequencies in Hz.
    band : (float, float) or None
    fs : float
        Sampling rate of the analysed record, Hz.
    cluster : ClusterSettings
        The clustering's settings (a pick's reach is its frequency reach).

    Returns
    -------
    (n_picks,) ndarray
    """
    try:
        values = np.sort(np.asarray(list(picks), dtype=float))
    except (TypeError, ValueError) as exc:
        raise PickError(f"picks: expected frequencies in Hz, got {picks!r}.") from exc
    if values.size == 0:
        raise PickError("picks: no frequency given; give at least one (Hz), or leave picks out for an automatic pick.")
    if not np.all(np.isfinite(values) & (values > 0)):
        raise PickError(f"picks: every frequency must be a positive number of Hz, got {values.tolist()}.")
    if band is None and np.any(values >= fs / 2):
        raise PickError(f"picks {values[values >= fs / 2].tolist()} Hz lie at or above the Nyquist frequency "
                        f"({fs / 2:g} Hz): no mode of this record is there; pick below it.")  # fmt: skip
    outside = values[(values < band[0]) | (values > band[1])] if band is not None else values[:0]
    if outside.size:
        raise PickError(f"picks {outside.tolist()} Hz lie outside the band {band[0]:g}-{band[1]:g} Hz; pick inside "
                        "it, or widen --band.")  # fmt: skip
    close = np.flatnonzero(np.diff(values) / values[:-1] <= cluster.pick_reach)
    if close.size:
        i = int(close[0])
        raise PickError(
            f"picks {values[i]:g} and {values[i + 1]:g} Hz are within {100 * cluster.pick_reach:g} % of each other: "
            "both would take the same cluster of the diagram; give one."
        )
    return values


def picked_modes(diagram, picks: np.ndarray, band, nas, cluster: ClusterSettings = DEFAULTS.cluster
                 ) -> tuple[pd.DataFrame, list[np.ndarray]]:  # fmt: skip
    """For each pick, the nearest cluster of the diagram's shared poles that holds poles of at
    least ``cluster.min_orders`` orders, reported from its
    lowest-BIC fit as an automatic mode is (:func:`armaxmodal.modes.clusters.mode_row`).

    Parameters
    ----------
    diagram : StabilisationDiagram
    picks : (n_picks,) ndarray
        Checked frequencies (:func:`check_picks`), Hz.
    band : (float, float) or None
    nas : list of int
        The diagram's orders.
    cluster : ClusterSettings
        The clustering's settings.

    Returns
    -------
    modes : DataFrame
        One row per pick, by frequency, with ``picked_hz``.
    vectors : list of (n_sensors,) complex ndarray

    Raises
    ------
    PickError
        When no such cluster lies within the clustering's reach of a pick, naming the nearest.
    """
    cand = candidate_poles(diagram.poles, band)
    kept = cand[(cand.rejected == "") & (cand.damping > 0)]
    clusters = cluster_poles(kept, nas, cluster.freq, cluster.damping)
    clusters = [c for c in clusters if len(set(kept.loc[c].na)) >= cluster.min_orders]
    centres = np.array([float(kept.loc[c].freq_hz.median()) for c in clusters])
    bic = order_criteria(diagram)
    rows, vectors = [], []
    for f in picks:
        if not centres.size:
            raise PickError(f"pick {f:g} Hz: the diagram holds no pole stable over {cluster.min_orders} orders "
                            "in the band; extend --orders or check that the input excites the structure.")  # fmt: skip
        k = int(np.argmin(np.abs(np.log(centres / f))))
        if abs(centres[k] / f - 1) > cluster.pick_reach:
            raise PickError(
                f"pick {f:g} Hz: no stable cluster of the diagram within {100 * cluster.pick_reach:g} % (the nearest "
                f"is at {centres[k]:.3f} Hz, {len(clusters[k])} orders); pick a column of the diagram, or extend "
                "--orders."
            )
        sub = kept.loc[clusters[k]]
        rep = representative_pole(diagram, sub, bic, {}, cluster.finished_max_shift)
        if rep is None:
            raise PickError(
                f"pick {f:g} Hz: the cluster at {centres[k]:.3f} Hz has no order whose fit keeps a positive damping "
                "once finished; the record gives this mode no damping estimate."
            )
        rows.append({**mode_row(rep, sub, len(nas)), "orders_damping_unresolved": 0, "picked_hz": float(f)})
        vectors.append(rep.vector)
    modes = pd.DataFrame(rows)
    taken = modes.medoid_freq_hz.round(9)
    if taken.duplicated().any():
        twice = modes.picked_hz[taken.duplicated(keep=False)].tolist()
        raise PickError(f"picks {twice} Hz take the same cluster of the diagram; give one of them.")
    order = modes.sort_values("freq_hz").index
    return modes.loc[order].reset_index(drop=True), [vectors[i] for i in order]
