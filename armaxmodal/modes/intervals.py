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
    the two estimators disagree (``covering_both_estimators``); NaN elsewhere;
``{q}_segment_half``
    the half-width of the disjoint segments' interval where their spread exceeds the statistical
    one (``apply_segment_spread``, below); NaN where it does not.

The interval is the hull of ``value ± Z95 sd`` and the other three, scaled about the value by the
share of the record's samples that carry information (filled samples do not). A damping ratio's
parts are taken on its logarithm (``interval``; ``armaxmodal.stats.damping_interval``), so no
damping interval reaches zero: one that spans a factor e^2 (where the symmetric interval of the
same deviation reaches zero) or reaches critical damping is the record's ``damping_unresolved``. Each stage sets its
own part and leaves the others', so no stage has to undo or re-derive another's widening.

**Two estimators that disagree** (``covering_both_estimators``): the intervals cover both.

The selection estimates every mode twice before it reports it: first the diagram's ARMAX fit (or
its band-limited refit, where the record is band-limited), then the maximum-likelihood modal model
that counts the modes (:mod:`armaxmodal.modes.counted`). For a linear structure and the noise each
of them weights by, both are consistent, and their differences are noise: each

    z = (value - earlier) / sqrt(sd^2 + sd_earlier^2)

is at most standard normal (the two fits share the record, so the difference varies less than the
sum of the variances says). Where the sum of ``z^2`` over every mode's frequency and damping ratio
exceeds the ``AgreementSettings.alpha`` (1 %) point of its chi-squared distribution -- Hausman's specification test
(Econometrica 46 (1978) 1251), with the two estimates taken as independent, which makes it
conservative -- one of them is biased on this record: by model error the two weight differently
(a nonlinearity, a hold the model lacks, leakage), or by diagram orders too low for a mode (a light
chain's top mode, 10 of its SDs off in the ARMAX fit). One record cannot say which is then right,
so every mode's 95 % interval covers the earlier estimator's 95 % interval too (the
``{q}_estimator_lo/hi`` parts), and an ``estimators_disagree`` note gives the statistic.

Why a test on the record, not on each mode: the model error is the record's (the F-16's joint
distorts every mode it moves; on its four multisine levels the statistic is 58, 59, 30 and 25.5 for
12 degrees of freedom, 1 % point 26.2), so a mode 1.8 standard deviations off carries it as much as one at 3.6.

**Model error** (``segment_spread``, ``apply_segment_spread``): a statistical interval assumes the
model class is right, which on real structures it rarely is (a joint that softens with amplitude,
a drifting set-up, an unmodelled mode). Refitting the same orders on ``K`` disjoint segments
measures that: under the model each segment's estimate has variance ``K sigma^2``, so
``(K - 1) s^2 / (K sigma^2)`` is chi-square with ``K - 1`` degrees of freedom. Where the spread is
significantly larger, the interval widens to the segments' own (``mean +- t_{K-1} s / sqrt(K)``)
and the mode is flagged ``model_error_dominates``.
"""

from __future__ import annotations

from functools import partial

import numpy as np
import pandas as pd
import scipy.stats

from armaxmodal.modes.settings import DEFAULTS, N_SEGMENTS
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording
from armaxmodal.stats import Z95, damping_interval

__all__ = [
    "EARLIER_COLUMNS",
    "QUANTITIES",
    "N_SEGMENTS",
    "apply_segment_spread",
    "covering_both_estimators",
    "earlier_estimate",
    "interval",
    "interval_columns",
    "not_separated",
    "segment_jobs",
    "segment_poles",
    "segment_spread",
    "with_intervals",
]

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
        lo, hi = interval(q, v, Z95 * out[f"{q}_sd"].to_numpy(float))
        for reach in ("other", "estimator"):
            reach_lo, reach_hi = _part(out, f"{q}_{reach}_lo"), _part(out, f"{q}_{reach}_hi")
            lo = np.where(np.isnan(reach_lo), lo, np.minimum(lo, reach_lo))
            hi = np.where(np.isnan(reach_hi), hi, np.maximum(hi, reach_hi))
        seg_lo, seg_hi = interval(q, v, _part(out, f"{q}_segment_half"))
        lo = np.where(np.isnan(seg_lo), lo, np.fmin(seg_lo, lo))
        hi = np.where(np.isnan(seg_hi), hi, np.fmax(seg_hi, hi))
        if scale != 1.0 and q == "damping":  # widened on the logarithm, where the interval is taken
            lo, hi = v * (lo / v) ** scale, np.minimum(v * (hi / v) ** scale, 1.0)
        elif scale != 1.0:
            lo, hi = v - scale * (v - lo), v + scale * (hi - v)
        out[f"{q}_ci95_lo"], out[f"{q}_ci95_hi"] = lo, hi
    return out


def interval(q: str, value, half_width):
    """The interval ``(lo, hi)`` of quantity ``q`` about ``value`` with a symmetric ``half_width``:
    symmetric for a frequency, on the logarithm for a damping ratio
    (:func:`armaxmodal.stats.damping_interval`: it never reaches zero)."""
    if q == "damping":
        return damping_interval(value, half_width)
    value, half_width = np.asarray(value, float), np.asarray(half_width, float)
    return value - half_width, value + half_width


def _part(modes: pd.DataFrame, column: str) -> np.ndarray:
    """A part's column, all NaN where no stage set it."""
    if column not in modes:
        return np.full(len(modes), np.nan)
    return modes[column].to_numpy(float)


def not_separated(modes: pd.DataFrame) -> list[tuple[int, int, float]]:
    """The neighbouring rows ``(i, i + 1, gap in SD)`` the record does not separate: the 95 %
    interval of their frequencies' difference holds zero (they differ by less than ``Z95``
    standard deviations of the difference, each SD from its row's 95 % interval), taken left to
    right without overlap. The level of every interval the selection reports."""
    f = modes.freq_hz.to_numpy()
    sd = (modes.freq_ci95_hi.to_numpy() - modes.freq_ci95_lo.to_numpy()) / (2 * Z95)
    pairs, i = [], 0
    while i < len(f) - 1:
        gap = (f[i + 1] - f[i]) / float(np.hypot(sd[i], sd[i + 1]))
        if gap < Z95:
            pairs.append((i, i + 1, float(gap)))
            i += 1
        i += 1
    return pairs


#: the columns a counted row keeps of the selection's earlier estimate of its mode
EARLIER_COLUMNS = tuple(f"{q}_{part}" for q, _ in QUANTITIES for part in ("earlier", "earlier_sd"))


def earlier_estimate(row: dict) -> dict:
    """The selection's estimate of a mode (``row``: a selection row as the diagram's ARMAX fit or
    the band-limited refit left it) as the ``{q}_earlier``, ``{q}_earlier_sd`` columns; all NaN
    where the row is the modal model's already (``estimator`` ``ml-...``)."""
    mine = not str(row.get("estimator", "")).startswith("ml-")
    columns = {}
    for q, value in QUANTITIES:
        columns[f"{q}_earlier"] = float(row[value]) if mine else np.nan
        # a row without a deviation (no interval of its own) is not tested: its z is NaN
        columns[f"{q}_earlier_sd"] = float(row.get(f"{q}_sd", np.nan)) if mine else np.nan
    return columns


def covering_both_estimators(
    rows: pd.DataFrame, alpha: float = DEFAULTS.agreement.alpha
) -> tuple[pd.DataFrame, list[QualityWarning]]:
    """Counted ``rows`` (with :data:`EARLIER_COLUMNS`) with their intervals covering the earlier
    estimator's where the record shows the two disagree (the module's docstring).

    Parameters
    ----------
    rows : DataFrame
        The counted modes: ``freq_hz``, ``damping``, ``freq_sd``, ``damping_sd`` and the
        earlier estimate's columns (NaN where a mode has none).
    alpha : float
        The test's level (:class:`~armaxmodal.modes.settings.AgreementSettings`).

    Returns
    -------
    (DataFrame, list of QualityWarning)
        A copy with ``{q}_estimator_lo``, ``{q}_estimator_hi`` (the earlier estimate's 95 %
        interval where the test rejects, else NaN) and ``estimator_widened`` (the interval
        reaches beyond the mode's own); an ``estimators_disagree`` note when the test rejects.
    """
    out = rows.copy()
    for column in EARLIER_COLUMNS:  # rows from the selection itself (a pick the model left) have none
        if column not in out:
            out[column] = np.nan
    z = []
    for q, value in QUANTITIES:
        out[f"{q}_estimator_lo"] = out[f"{q}_estimator_hi"] = np.nan
        diff = out[value].to_numpy(float) - out[f"{q}_earlier"].to_numpy(float)
        z.append(diff / np.hypot(out[f"{q}_sd"].to_numpy(float), out[f"{q}_earlier_sd"].to_numpy(float)))
    z = np.concatenate(z)
    z = z[np.isfinite(z)]
    out["estimator_widened"] = False
    if z.size == 0:
        return out, []
    statistic, critical = float(np.sum(z**2)), float(scipy.stats.chi2.isf(alpha, z.size))
    if statistic <= critical:
        return out, []
    widened = np.zeros(len(out), dtype=bool)
    for q, value in QUANTITIES:
        earlier, sd = out[f"{q}_earlier"].to_numpy(float), out[f"{q}_earlier_sd"].to_numpy(float)
        lo, hi = interval(q, earlier, Z95 * sd)
        out[f"{q}_estimator_lo"], out[f"{q}_estimator_hi"] = lo, hi
        own_lo, own_hi = interval(q, out[value].to_numpy(float), Z95 * out[f"{q}_sd"].to_numpy(float))
        widened |= np.isfinite(lo) & ((lo < own_lo) | (hi > own_hi))
    out["estimator_widened"] = widened
    where = ", ".join(f"{f:.3f}" for f in out.freq_hz[widened])
    note = QualityWarning(
        "estimators_disagree",
        (),
        f"the modal model's modes and the diagram's fit of them differ beyond their noise (sum of squared "
        f"standardised differences {statistic:.1f} for {z.size} values, its {100 * (1 - alpha):g} % point "
        f"{critical:.1f}): one of them is biased here, by model error the two weight differently (a nonlinearity, the "
        "inter-sample behaviour, leakage) or by orders too low for a mode. One record cannot say which, so every "
        "mode's interval covers both estimates" + (f"; widened at {where} Hz" if where else ""),
        statistic,
        tuple(out.freq_hz[widened]),
    )
    return out, [note]


def segment_spread(
    recording: Recording,
    modes: pd.DataFrame,
    orders_of,
    n_segments: int = N_SEGMENTS,
    n_jobs: int | None = None,
    fitted: dict | None = None,
    match_freq: float = DEFAULTS.cluster.freq,
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
        parts = recording.split(n_segments)
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
    found = {
        j: _mutual_nearest(poles, freqs, j, match_freq)
        for j in np.flatnonzero(np.abs(freqs / freqs[i] - 1) <= match_freq)
    }
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


def apply_segment_spread(
    modes: pd.DataFrame, spread: pd.DataFrame, n_segments: int = N_SEGMENTS, alpha: float = DEFAULTS.agreement.alpha
):
    """Join the spread to ``modes``, set the segments' part of the intervals where it dominates, and say so.
    ``alpha``: the test's family-wise false-alarm rate over all modes and both parameters (Bonferroni).

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
                tuple(modes.freq_hz[flagged]),
            )
        )
    return modes, warnings
