"""A mode's 95 % intervals, kept as their parts while the selection works and combined once, on output.

Each quantity ``q`` (``freq`` for ``freq_hz``, ``damping``) of a selection row has three parts:

``{q}_sd``
    the standard deviation of the reported value, from its estimator's information matrix (the
    ARMAX fit's, the band-limited refit's or the modal model's, whichever ``estimator`` names);
``{q}_other_lo``, ``{q}_other_hi``
    the reach of the same mode's 95 % intervals in the other model structures the record finds
    as good (:mod:`armaxmodal.modes.counted`: another number of modes, two poles reported as one);
    NaN where there are none;
``{q}_estimator_lo``, ``{q}_estimator_hi``
    the reach of the earlier estimator's 95 % interval (the diagram's fit) where the record shows
    the two estimators disagree (:mod:`armaxmodal.modes.estimators`); NaN elsewhere;
``{q}_segment_half``
    the half-width of the disjoint segments' interval where their spread exceeds the statistical
    one (:mod:`armaxmodal.modes.spread`); NaN where it does not.

The interval is the hull of ``value ± Z95 sd`` and the other three, scaled about the value by the
share of the record's samples that carry information (filled samples do not). Each stage sets its
own part and leaves the others', so no stage has to undo or re-derive another's widening.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from armaxmodal.stats import Z95

__all__ = ["QUANTITIES", "interval_columns", "not_separated", "with_intervals"]

#: ``(part prefix, value column)`` of each quantity that has an interval
QUANTITIES = (("freq", "freq_hz"), ("damping", "damping"))


def interval_columns(q: str) -> tuple[str, str]:
    """The output columns ``({q}_ci95_lo, {q}_ci95_hi)`` of quantity ``q``."""
    return f"{q}_ci95_lo", f"{q}_ci95_hi"


def with_intervals(modes: pd.DataFrame, scale: float = 1.0) -> pd.DataFrame:
    """``modes`` with its 95 % intervals computed from their parts (the module's docstring).

    Parameters
    ----------
    modes : DataFrame
        Selection rows: ``freq_hz``, ``damping``, ``freq_sd`` and ``damping_sd``; the ``other``,
        ``estimator`` and ``segment_half`` columns where a stage set them (absent: none).
    scale : float
        Factor every interval is widened by about its value (at least 1; 1 leaves them).

    Returns
    -------
    DataFrame
        A copy with ``freq_ci95_lo``, ``freq_ci95_hi``, ``damping_ci95_lo`` and ``damping_ci95_hi``.
        A NaN standard deviation gives a NaN interval unless the segments' part gives one: the
        other structures' and estimators' intervals are not this estimate's.
    """
    out = modes.copy()
    for q, value in QUANTITIES:
        v = out[value].to_numpy(float)
        sd = out[f"{q}_sd"].to_numpy(float)
        lo, hi = v - Z95 * sd, v + Z95 * sd
        for reach in ("other", "estimator"):
            reach_lo, reach_hi = _part(out, f"{q}_{reach}_lo"), _part(out, f"{q}_{reach}_hi")
            lo = np.where(np.isnan(reach_lo), lo, np.minimum(lo, reach_lo))
            hi = np.where(np.isnan(reach_hi), hi, np.maximum(hi, reach_hi))
        half = _part(out, f"{q}_segment_half")
        lo = np.where(np.isnan(half), lo, np.fmin(v - half, lo))
        hi = np.where(np.isnan(half), hi, np.fmax(v + half, hi))
        if scale != 1.0:
            lo, hi = v - scale * (v - lo), v + scale * (hi - v)
        out[f"{q}_ci95_lo"], out[f"{q}_ci95_hi"] = lo, hi
    return out


def _part(modes: pd.DataFrame, column: str) -> np.ndarray:
    """A part's column, all NaN where no stage set it."""
    if column not in modes:
        return np.full(len(modes), np.nan)
    return modes[column].to_numpy(float)


def not_separated(modes: pd.DataFrame, separation_sd: float) -> list[tuple[int, int, float]]:
    """The neighbouring rows ``(i, i + 1, gap in SD)`` whose frequencies differ by less than
    ``separation_sd`` standard deviations of the difference (each SD from its 95 % interval),
    taken left to right without overlap."""
    f = modes.freq_hz.to_numpy()
    sd = (modes.freq_ci95_hi.to_numpy() - modes.freq_ci95_lo.to_numpy()) / (2 * Z95)
    pairs, i = [], 0
    while i < len(f) - 1:
        gap = (f[i + 1] - f[i]) / float(np.hypot(sd[i], sd[i + 1]))
        if gap < separation_sd:
            pairs.append((i, i + 1, float(gap)))
            i += 1
        i += 1
    return pairs
