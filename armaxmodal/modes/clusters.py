"""Poles to mode candidates: the stable shared-pole poles clustered across orders, each
cluster's representative taken from its lowest-BIC fit finished to full convergence, and two
candidates that are one mode split by over-modelling merged.

**Picks** (``picked_modes``): each frequency the analyst gives takes the nearest stable cluster of
the diagram, as the thesis picked its modes from its diagrams (and as MATLAB's ``modalfit``, pyOMA2's
``mpe(sel_freq=...)`` and sdypy-EMA's ``select_closest_poles`` take physical frequencies).

A pick is then refitted, checked and judged like an automatic mode; it is not dropped for want of
support, but the maximum-likelihood modal model says when the record does not need it.
"""

from __future__ import annotations

from functools import partial

import numpy as np
import pandas as pd

from armaxmodal.estimate.fit import fit_armax
from armaxmodal.estimate.pool import parallel_map
from armaxmodal.estimate.result import ArmaxFit
from armaxmodal.exceptions import PickError
from armaxmodal.modal import mac
from armaxmodal.modes.diagram import StabilisationDiagram
from armaxmodal.modes.poles import SHARED, UNRESOLVED_DAMPING, pole_rows
from armaxmodal.modes.settings import DEFAULTS, PEAK_RESOLUTION, ClusterSettings
from armaxmodal.recording import Recording
from armaxmodal.spectra import coherent_peaks, explains, resolving_nperseg
from armaxmodal.stats import Z95


def clustered_modes(diagram, band, nas, cluster: ClusterSettings, n_jobs, bar=None):
    """One mode per supported cluster (the kept poles', then the rescued lightly damped
    ones), each from its representative fit: ``(modes, shape vectors)``. ``bar`` (tqdm)
    counts the finishing fits."""
    cand = candidate_poles(diagram.poles, band)
    clusters = cluster_poles(cand[cand.rejected == ""], nas, cluster.freq, cluster.damping)
    clusters = [c for c in clusters if _supported(len(c), len(nas), cluster)]
    left = cand.drop(index=[m for c in clusters for m in c])
    clusters += _rescued_clusters(diagram, left, nas, cluster, band)
    bic = diagram.order_bic
    firsts = [_ranked(cand.loc[c][cand.loc[c].damping > 0], bic) for c in clusters]
    finished = _finish_fits(diagram, {ranked[0] for ranked in firsts if ranked}, n_jobs, bar)
    rows, vectors = [], []
    for members in clusters:
        sub = cand.loc[members]
        rep = representative_pole(diagram, sub[sub.damping > 0], bic, finished, cluster.freq)
        if rep is None:
            continue
        rows.append({**mode_row(rep, sub, len(nas)), "orders_damping_unresolved": int((sub.damping <= 0).sum())})
        vectors.append(rep.vector)
    return pd.DataFrame(rows), vectors


def representative_pole(
    diagram, resolved: pd.DataFrame, bic: dict, finished: dict, max_shift: float = DEFAULTS.cluster.freq
) -> pd.Series | None:
    """The cluster's pole from the fit of lowest BIC, finished to full convergence; the next
    order's when finishing takes a lightly damped pole's damping to zero or below (None when
    every one does: the record gives this mode no damping estimate)."""
    for na in _ranked(resolved, bic):
        rep = _finished_pole(diagram, resolved[resolved.na == na].iloc[0], finished, max_shift)
        if rep.damping > 0:
            return rep
    return None


def _ranked(poles: pd.DataFrame, bic: dict) -> list[int]:
    """The orders of ``poles`` (one pole each), lowest BIC first."""
    return sorted((int(na) for na in poles.na), key=lambda na: (bic.get(na, np.inf), na))


def _finish_fits(diagram: StabilisationDiagram, nas, n_jobs: int | None, bar=None) -> dict:
    """``{na: poles}`` of the shared fits of orders ``nas`` continued to :func:`fit_armax`'s
    default tolerance (the sweep stops its fits early), over the worker threads."""
    nas = sorted(nas)
    fits = [diagram.fits[(SHARED, na)] for na in nas]
    finish = partial(_finished_poles, diagram.recording)
    done = parallel_map(finish, fits, n_jobs, bar, cost=lambda fit: fit.orders[0], min_items=2)
    return dict(zip(nas, done, strict=True))


def _finished_poles(recording: Recording, fit: ArmaxFit) -> pd.DataFrame:
    done = fit_armax(recording, *fit.orders, shared_poles=True, max_iter=100, start=fit, warn=False)
    return pd.DataFrame(pole_rows(done, SHARED))


def _supported(count: int, n_orders: int, cluster: ClusterSettings) -> bool:
    """A cluster is a mode when it holds poles of at least ``cluster.min_orders`` orders and
    ``cluster.min_support`` of the swept ones."""
    return count >= cluster.min_orders and count / n_orders >= cluster.min_support


def why_no_mode(diagram: StabilisationDiagram, band, nas, cluster: ClusterSettings) -> str:
    """Why no cluster of the diagram is a mode, in a sentence: the shared poles in the band,
    those rejected and for what, and how many orders the best-supported cluster of the rest
    holds against the support a mode needs."""
    shared = diagram.poles[diagram.poles.source == SHARED]
    if band is not None:
        shared = shared[(shared.freq_hz >= band[0]) & (shared.freq_hz <= band[1])]
    where = f" in {band[0]:g}-{band[1]:g} Hz" if band else ""
    if shared.empty:
        return f"no stable mode found{where}: the sweep has no shared pole there"
    reasons = shared.rejected[shared.rejected != ""].value_counts()
    said = "; ".join(f"{why}: {n}" for why, n in reasons.items())
    facts = [f"of {len(shared)} shared poles{where}, {int(reasons.sum())} were rejected{f' ({said})' if said else ''}"]
    cand = candidate_poles(diagram.poles, band)
    clusters = cluster_poles(cand[cand.rejected == ""], nas, cluster.freq, cluster.damping)
    need = max(cluster.min_orders, int(np.ceil(cluster.min_support * len(nas))))
    if clusters:
        best = max(clusters, key=len)
        f = float(cand.loc[best].freq_hz.median())
        facts.append(
            f"the best-supported cluster of the rest ({len(clusters)} in all), at {f:.3g} Hz, holds "
            f"poles of {len(best)} of {len(nas)} orders, where a mode needs {need}"
        )
    return f"no stable mode found{where}: " + "; ".join(facts)


def candidate_poles(poles: pd.DataFrame, band, rejected=("", UNRESOLVED_DAMPING)) -> pd.DataFrame:
    """Shared-pole poles in ``band`` that may form a mode: by default the kept ones and those
    whose damping the record does not resolve (they count towards support, see
    :func:`select_modes`); ``rejected`` names the rejection reasons let in."""
    cand = poles[(poles.source == SHARED) & poles.rejected.isin(list(rejected))]
    if band is not None:
        cand = cand[(cand.freq_hz >= band[0]) & (cand.freq_hz <= band[1])]
    return cand


def cluster_poles(cand: pd.DataFrame, nas, cluster_freq: float, cluster_damping: float | None) -> list[list[int]]:
    """Greedy clustering across orders (see :func:`select_modes`): lists of ``cand`` indices.
    ``cluster_damping=None`` groups by frequency alone."""
    clusters: list[list[int]] = []
    # per cluster: its orders and its median frequency and damping, updated as members join
    # (plain lists: per-element pandas lookups made this loop 0.25 s on a 20,000-sample record)
    orders: list[set] = []
    values: list[tuple[list, list]] = []
    centres: list[tuple[float, float]] = []
    for na in nas:
        group = cand[cand.na == na].sort_values("energy", ascending=False)
        for idx, freq, damping in zip(group.index, group.freq_hz.to_numpy(), group.damping.to_numpy(), strict=True):
            best, best_d = None, np.inf
            for ci, (f_c, x_c) in enumerate(centres):
                if na in orders[ci]:
                    continue
                df = abs(freq - f_c) / f_c
                dx = 0.0 if cluster_damping is None else abs(damping - x_c) / x_c
                if df <= cluster_freq and (cluster_damping is None or dx <= cluster_damping) and df + 0.1 * dx < best_d:
                    best, best_d = ci, df + 0.1 * dx
            if best is None:
                clusters.append([])
                orders.append(set())
                values.append(([], []))
                centres.append((freq, damping))
                best = len(clusters) - 1
            clusters[best].append(idx)
            orders[best].add(na)
            values[best][0].append(freq)
            values[best][1].append(damping)
            centres[best] = (float(np.median(values[best][0])), float(np.median(values[best][1])))
    return clusters


def _rescued_clusters(diagram, rest: pd.DataFrame, nas, cluster: ClusterSettings, band) -> list:
    """Lightly damped modes the damping rule splits: poles the selection left, whose damping
    the record does not resolve (the 95 % interval reaches zero, or the estimate crosses it),
    grouped by frequency alone. A group is a mode when it has the usual support, a positive
    estimate at some order, and the measured FRF a clear, coherent peak there -- the data's
    own evidence, which noise poles lack."""
    light = rest[rest.damping - Z95 * rest.damping_sd <= 0]
    found = []
    for members in cluster_poles(light, nas, cluster.freq, None):
        sub = light.loc[members]
        if not _supported(len(members), len(nas), cluster) or not (sub.damping > 0).any():
            continue
        if peak_support(diagram.recording, float(sub.freq_hz.median()), 0.0, band) is not None:
            found.append(members)
    return found


def mode_row(rep: pd.Series, sub: pd.DataFrame, n_orders: int) -> dict:
    """One selected mode: the representative pole's estimate, the cluster's medoid and spread."""
    f, x = sub.freq_hz.to_numpy(), sub.damping.to_numpy()
    x_scale = max(abs(float(np.mean(x))), float(np.median(sub.damping_sd)), 1e-12)  # damping may cross zero
    dist = np.abs(f[:, None] - f[None]) / f.mean() + np.abs(x[:, None] - x[None]) / x_scale
    medoid = sub.iloc[int(np.argmin(dist.sum(axis=1)))]
    row = {k: rep[k] for k in _ESTIMATE_COLUMNS}
    row.update(
        na=int(rep.na),
        count=len(sub),
        support=len(sub) / n_orders,
        freq_spread=float(np.std(f, ddof=1)),
        damping_spread=float(np.std(x, ddof=1)),
        medoid_freq_hz=medoid.freq_hz,
        medoid_damping=medoid.damping,
        energy=float(sub.energy.median()),
    )
    return row


# the interval as its parts: the standard deviations (armaxmodal.modes.intervals)
_ESTIMATE_COLUMNS = ("freq_hz", "damping", "damped_freq_hz", "freq_sd", "damping_sd")


def _finished_pole(diagram: StabilisationDiagram, pole: pd.Series, cache: dict, max_shift: float) -> pd.Series:
    """The pole as estimated by its order's fit continued to :func:`fit_armax`'s default
    tolerance (the sweep stops its fits early); ``cache`` holds the finished fits' poles. A
    finished pole farther than ``max_shift`` (relative frequency) is another pole."""
    na = int(pole.na)
    if na not in cache:
        cache[na] = _finished_poles(diagram.recording, diagram.fits[(SHARED, na)])
    poles = cache[na]
    if poles.empty:
        return pole
    nearest = poles.iloc[int(np.argmin(np.abs(poles.pole.to_numpy() - pole.pole)))]
    if abs(nearest.freq_hz / pole.freq_hz - 1) > max_shift:
        return pole  # finishing moved this pole away (a weak one): the sweep's estimate stands
    # the finished estimate, with the diagram's own columns (class, rejection) kept
    return pd.concat([nearest, pole.drop(nearest.index, errors="ignore")])


def merge_duplicates(modes: pd.DataFrame, vectors: list, merge_mac: float, duration_s: float) -> list[int]:
    """Indices of the modes to keep after merging split (near-duplicate) modes.

    A weaker mode is the better-supported one split by over-modelling when it lies within
    that mode's half-power bandwidth (``2 xi f``) with a similar shape (MAC >= ``merge_mac``),
    or, whatever its shape, within ``2 / duration_s`` of it: two frequencies that close cannot
    be told apart by a record of this length. (Heavily damped modes are often closer than
    their bandwidths -- the supine human's -- so the bandwidth alone decides nothing.)
    """
    ranked = modes.sort_values(["support", "count", "energy"], ascending=False).index
    kept: list[int] = []
    for i in ranked:
        if not any(_is_split(modes, vectors, i, j, merge_mac, duration_s) for j in kept):
            kept.append(i)
    return sorted(kept)


def _is_split(modes, vectors, i, j, merge_mac, duration_s) -> bool:
    """Mode ``i`` is mode ``j`` split in two (see :func:`merge_duplicates`)."""
    gap = abs(modes.at[i, "freq_hz"] - modes.at[j, "freq_hz"])
    half_power = 2 * modes.at[j, "damping"] * modes.at[j, "freq_hz"]
    unresolvable = gap <= 2.0 / duration_s
    return unresolvable or (gap <= half_power and mac(vectors[i], vectors[j]) >= merge_mac)


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
        raise PickError(
            f"picks {values[values >= fs / 2].tolist()} Hz lie at or above the Nyquist frequency "
            f"({fs / 2:g} Hz): no mode of this record is there; pick below it."
        )
    outside = values[(values < band[0]) | (values > band[1])] if band is not None else values[:0]
    if outside.size:
        raise PickError(
            f"picks {outside.tolist()} Hz lie outside the band {band[0]:g}-{band[1]:g} Hz; pick inside "
            "it, or widen --band."
        )
    close = np.flatnonzero(np.diff(values) / values[:-1] <= cluster.pick_reach)
    if close.size:
        i = int(close[0])
        raise PickError(
            f"picks {values[i]:g} and {values[i + 1]:g} Hz are within {100 * cluster.pick_reach:g} % of each other: "
            "both would take the same cluster of the diagram; give one."
        )
    return values


def picked_modes(
    diagram, picks: np.ndarray, band, nas, cluster: ClusterSettings = DEFAULTS.cluster
) -> tuple[pd.DataFrame, list[np.ndarray]]:
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
    bic = diagram.order_bic
    rows, vectors = [], []
    for f in picks:
        if not centres.size:
            raise PickError(
                f"pick {f:g} Hz: the diagram holds no pole stable over {cluster.min_orders} orders "
                "in the band; extend --orders or check that the input excites the structure."
            )
        k = int(np.argmin(np.abs(np.log(centres / f))))
        if abs(centres[k] / f - 1) > cluster.pick_reach:
            raise PickError(
                f"pick {f:g} Hz: no stable cluster of the diagram within {100 * cluster.pick_reach:g} % (the nearest "
                f"is at {centres[k]:.3f} Hz, {len(clusters[k])} orders); pick a column of the diagram, or extend "
                "--orders."
            )
        sub = kept.loc[clusters[k]]
        rep = representative_pole(diagram, sub, bic, {}, cluster.freq)
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


def stable_in_diagram(diagram, band, cluster: ClusterSettings):
    """``supported(f, x)``: poles of at least ``cluster.min_orders`` orders of the diagram
    lie within the clustering's reach of frequency ``f`` (Hz) and damping ``x``. Poles rejected
    for their residue count: stability across orders is the pole's, and a weakly driven mode (a
    light chain's 9.32 Hz, rejected as a negligible residue at every order) is still a mode."""
    poles = diagram.poles[diagram.poles.source == SHARED]
    if band is not None:
        poles = poles[(poles.freq_hz >= band[0]) & (poles.freq_hz <= band[1])]
    kept = poles[poles.damping > 0]
    f, x, na = kept.freq_hz.to_numpy(), kept.damping.to_numpy(), kept.na.to_numpy()

    def supported(freq_hz: float, damping: float) -> bool:
        near = (np.abs(f / freq_hz - 1) <= cluster.freq) & (np.abs(x / damping - 1) <= cluster.damping)
        return len(set(na[near].tolist())) >= cluster.min_orders

    return supported


def peak_support(recording: Recording, freq_hz: float, damping: float, band=None) -> float | None:
    """Frequency of the clear, coherent FRF peak (:func:`~armaxmodal.spectra.coherent_peaks`) that a mode at
    ``freq_hz`` explains, or None: the data's own evidence for a mode whose poles alone are
    not conclusive (a lightly damped pole whose damping estimate crosses zero)."""
    res = PEAK_RESOLUTION
    n = resolving_nperseg(recording, [freq_hz], [max(damping, 1e-6)], res.lines_per_bandwidth, res.min_segments)
    df = recording.fs / n
    peaks = coherent_peaks(recording, n, res.lines_per_bandwidth, band)
    near = [p for p in peaks if explains(p[0], df, [freq_hz], [max(damping, 0.0)])]
    return max(near, key=lambda p: p[2])[0] if near else None
