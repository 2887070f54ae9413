"""Uncertainty that includes model error: the spread of re-identification on disjoint segments.

A statistical interval (Cramér-Rao / delta method) assumes the model class is right. On real
structures it rarely is (a joint that softens with amplitude, a slow drift of the set-up, an
unmodelled mode), and two trials minutes apart then disagree far beyond their intervals.
Refitting the same orders on ``K`` disjoint segments measures that: under the model each
segment's estimate has variance ``K sigma^2`` (a K-th of the data), so
``(K - 1) s^2 / (K sigma^2)`` follows chi-square with ``K - 1`` degrees of freedom. When the
spread is significantly larger, the interval is widened to the segments' own
(``mean +- t_{K-1} s / sqrt(K)``) and the mode is flagged ``model_error_dominates``.
"""

from __future__ import annotations

from functools import partial

import numpy as np
import pandas as pd

from armaxmodal.modes.settings import DEFAULTS, N_SEGMENTS
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording

__all__ = ["segment_spread", "apply_segment_spread", "segment_jobs", "segment_poles", "split_segments", "N_SEGMENTS"]

def split_segments(recording: Recording, k: int = N_SEGMENTS) -> list[Recording]:
    """The record cut into ``k`` disjoint, equal parts (the remainder dropped)."""
    n = recording.n_samples // k
    return [
        Recording(recording.fs, recording.base[i * n : (i + 1) * n], recording.response[i * n : (i + 1) * n],
                  recording.sensors, recording.input_name)
        for i in range(k)
    ]  # fmt: skip


def segment_spread(
    recording: Recording,
    modes: pd.DataFrame,
    orders_of,
    n_segments: int = N_SEGMENTS,
    n_jobs: int | None = None,
    fitted: dict | None = None,
    match_freq: float = DEFAULTS.intervals.match_freq,
):
    """Between-segment standard deviation of each mode's frequency and damping.

    Parameters
    ----------
    recording : Recording
        The record the modes were identified on.
    modes : DataFrame
        ``freq_hz`` and ``damping`` per mode.
    orders_of : callable
        ``orders_of(i) -> (na, nb, nc, nk)``: the orders of mode ``i``'s representative fit.
    n_segments : int
    n_jobs : int, optional
        Worker threads for the segment fits (default: all cores).
    fitted : dict, optional
        Segment poles already computed, ``{(orders, k): poles}`` (:func:`segment_poles`);
        the jobs not in it are fitted here.
    match_freq : float
        A segment's pole is the mode's when within this relative frequency of it.

    Returns
    -------
    DataFrame
        Per mode: ``freq_segment_sd`` (Hz), ``damping_segment_sd``, ``segments_found``
        (segments in which a pole within ``match_freq`` of the mode's frequency was found).
    """
    from armaxmodal.estimate.pool import parallel_map

    wanted = sorted({tuple(orders_of(i)) for i in range(len(modes))})
    jobs = segment_jobs(wanted, n_segments)
    fitted = dict(fitted or {})
    todo = [job for job in jobs if job not in fitted]
    if todo:
        # every segment refit of every representative order at once, over the worker threads
        parts = split_segments(recording, n_segments)
        found = parallel_map(partial(segment_poles, parts), todo, n_jobs, cost=lambda job: job[0][0], min_items=2)
        fitted.update(zip(todo, found, strict=True))
    poles_by_orders: dict = {orders: [] for orders in wanted}
    for orders, k in jobs:
        poles_by_orders[orders].append(fitted[(orders, k)])
    rows = []
    freqs = modes.freq_hz.to_numpy(float)
    for i in range(len(modes)):
        matched = [_matched_pole(poles, freqs, i, match_freq) for poles in poles_by_orders[tuple(orders_of(i))]]
        f_seg = [pole[0] for pole in matched if pole is not None]
        x_seg = [pole[1] for pole in matched if pole is not None]
        found = len(f_seg)
        rows.append(
            {
                "freq_segment_sd": float(np.std(f_seg, ddof=1)) if found >= 2 else np.nan,
                "damping_segment_sd": float(np.std(x_seg, ddof=1)) if found >= 2 else np.nan,
                "segments_found": found,
            }
        )
    return pd.DataFrame(rows)


def _matched_pole(poles: pd.DataFrame | None, freqs: np.ndarray, i: int, match_freq: float):
    """``(freq_hz, damping)`` of the segment's pole that is mode ``i``'s, or None.

    A pole is mode ``i``'s when it is the nearest to mode ``i`` (within ``match_freq``) and mode
    ``i`` is the selected mode nearest to it; and only where the segment resolves the
    neighbourhood, that is where every other selected mode within ``match_freq`` finds its own
    pole in the same fit. A segment fit that finds one pole for a close pair estimates the pair's
    blend, not either mode, and its scatter is the pair's gap, not the record's model error (two
    modes 3 % apart were each widened to cover the other)."""
    if poles is None or poles.empty:
        return None
    poles = poles[poles.damping > 0]
    found = {j: _mutual_nearest(poles, freqs, j, match_freq)
             for j in np.flatnonzero(np.abs(freqs / freqs[i] - 1) <= match_freq)}  # fmt: skip
    return None if any(pole is None for pole in found.values()) else found[i]


def _mutual_nearest(poles: pd.DataFrame, freqs: np.ndarray, i: int, match_freq: float):
    """The pole nearest mode ``i`` within ``match_freq`` whose nearest selected mode is ``i``, as
    ``(freq_hz, damping)``; None where there is none."""
    f = poles.freq_hz.to_numpy(float)
    near = np.flatnonzero(np.abs(f / freqs[i] - 1) <= match_freq)
    if near.size == 0:
        return None
    k = near[int(np.argmin(np.abs(np.log(f[near] / freqs[i]))))]
    if int(np.argmin(np.abs(np.log(freqs / f[k])))) != i:
        return None
    return float(f[k]), float(poles.damping.iloc[k])


def segment_jobs(orders: list, n_segments: int = N_SEGMENTS) -> list:
    """The refits :func:`segment_spread` needs: ``(orders, segment)`` for each set of orders."""
    return [(tuple(o), k) for o in orders for k in range(n_segments)]


def segment_poles(parts: list[Recording], job) -> pd.DataFrame | None:
    """The shared-pole poles of one segment's refit at the given orders (None: not fitted)."""
    from armaxmodal.estimate.orders import fit_or_none
    from armaxmodal.modes.poles import SHARED, pole_rows

    orders, k = job
    fit = fit_or_none(parts[k], orders, shared_poles=True, max_iter=30, tol=1e-6, stop="decrease")
    return pd.DataFrame(pole_rows(fit, SHARED)) if fit is not None else None


def apply_segment_spread(modes: pd.DataFrame, spread: pd.DataFrame, n_segments: int = N_SEGMENTS,
                         alpha: float = DEFAULTS.intervals.spread_alpha):  # fmt: skip
    """Join the spread to ``modes``, set the segments' part of the intervals where it dominates, and say so.
    ``alpha``: the test's family-wise false-alarm rate over all modes and both parameters.

    Returns ``(modes, warnings)``; ``modes`` gains the spread columns, ``model_error_dominates``
    (bool) and ``freq_segment_half`` / ``damping_segment_half``: the half-width of the segments'
    95 % interval where their spread exceeds the statistical one, else NaN
    (:mod:`armaxmodal.modes.intervals` takes the hull on output).
    """
    from scipy.special import chdtri, stdtrit  # chi2 and t quantiles without scipy.stats' 0.5 s import

    modes = pd.concat([modes.reset_index(drop=True), spread.reset_index(drop=True)], axis=1)
    flagged = []
    crit = chdtri(n_segments - 1, alpha / (2 * max(1, len(modes))))  # upper-tail quantile
    t_k = stdtrit(n_segments - 1, 0.975)
    dominates = np.zeros(len(modes), dtype=bool)
    halves = {"freq": np.full(len(modes), np.nan), "damping": np.full(len(modes), np.nan)}
    for i, m in modes.iterrows():
        for q, sd_col, model_sd in (
            ("freq", "freq_segment_sd", "freq_sd_armax"),
            ("damping", "damping_segment_sd", "damping_sd_armax"),
        ):
            # judged against the interval of the estimator the segments use (ARMAX) when the
            # reported one is another's (the band-limited refit)
            sigma, s = m[model_sd], m[sd_col]
            if not (np.isfinite(s) and sigma > 0) or m.segments_found < n_segments:
                continue
            if (n_segments - 1) * s**2 / (n_segments * sigma**2) > crit:
                dominates[i] = True
                halves[q][i] = t_k * s / np.sqrt(n_segments)
        if dominates[i]:
            flagged.append(i)
    modes["model_error_dominates"] = dominates
    modes["freq_segment_half"], modes["damping_segment_half"] = halves["freq"], halves["damping"]
    warnings = []
    if flagged:
        listed = "; ".join(
            f"{modes.at[i, 'freq_hz']:.3g} Hz (segment SD {modes.at[i, 'freq_segment_sd']:.3g} Hz, "
            f"damping {modes.at[i, 'damping_segment_sd']:.2g})"
            for i in flagged
        )
        warnings.append(
            QualityWarning(
                "model_error_dominates",
                (),
                f"refitted on {n_segments} disjoint segments, {len(flagged)} mode(s) scatter beyond their statistical "
                f"intervals: {listed}. Their 95 % intervals were widened to the segments' spread. The model misses "
                "an effect of the data (amplitude-dependent or time-varying behaviour, a disturbance, a missing mode).",
                float(len(flagged)),
            )
        )
    return modes, warnings
