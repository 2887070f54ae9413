"""The selection's last step: the modes counted by nested tests of the maximum-likelihood modal
model (:mod:`armaxmodal.modes.mode_count`), written back as the selection's rows, shapes and notes.

Poles the model needs but that are no modes of the band -- above the fitted band (they stand
for the modes above it, an upper residual), damped beyond ``armaxmodal.stats.MAX_DAMPING``,
or lines at the damping floor -- stay in the model and are not reported.

Each rule here turns the count into rows of the one working selection, in the order
``counted_modes`` states; the notes' words are :mod:`armaxmodal.modes.notes`'.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pandas as pd
from scipy.special import chdtrc

from armaxmodal.estimate.dft_model import DftLines, fit_modal_model
from armaxmodal.modal import mac, matched_poles, nearest_pole
from armaxmodal.modes.clusters import candidate_poles, cluster_poles, stable_in_diagram
from armaxmodal.modes.count_search import count_modes
from armaxmodal.modes.intervals import (
    EARLIER_COLUMNS,
    covering_both_estimators,
    earlier_estimate,
    not_separated,
    with_intervals,
)
from armaxmodal.modes.mode_count import ModeCount, halves_chi2
from armaxmodal.modes.notes import (
    confirmed_where_incoherent_note,
    count_notes,
    no_mode_kept_note,
    not_picked_note,
    pick_moved_note,
    pick_notes,
    reported_as_one_note,
    rule_notes,
)
from armaxmodal.modes.settings import DEFAULTS, SelectionSettings
from armaxmodal.modes.state import SelectionState
from armaxmodal.stats import MAX_DAMPING, Z95

__all__ = ["confirmed_where_incoherent", "counted_modes", "without_column"]

#: the sweep's rejection that leaves a stable cluster a candidate still (poles/rejection_reasons)
WEAK_RESIDUE = "negligible residue"


def _candidates(
    diagram, modes: pd.DataFrame, band, nas, settings: SelectionSettings = DEFAULTS
) -> list[tuple[float, float]]:
    """The diagram's stable clusters the selection left out: (Hz, ratio), the clean ones first
    (largest first), then those whose every pole the sweep rejected only for a small residue. A
    weakly driven or weakly seen mode is stable across orders with a small residue at each (a
    five-mass chain's 9.7 Hz at nine orders of a 400 s ride); whether the record needs it is the
    likelihood's to say, as for any addition."""
    cluster = settings.cluster
    cand = candidate_poles(diagram.poles, band, rejected=("", WEAK_RESIDUE))
    cand = cand[(cand.damping > 0) & (cand.damping <= MAX_DAMPING)]
    found = []
    for rank, rejected in enumerate(("", WEAK_RESIDUE)):
        kept = cand[cand.rejected == rejected]
        for members in cluster_poles(kept, nas, cluster.freq, cluster.damping):
            sub = kept.loc[members]
            f = float(sub.freq_hz.median())
            taken = [g for _, _, g, _ in found] + list(modes.freq_hz.to_numpy())
            if len(members) >= cluster.min_orders and np.min(np.abs(np.asarray(taken) / f - 1)) > cluster.freq:
                found.append((rank, -len(members), f, float(sub.damping.median())))
    return [(f, x) for _, _, f, x in sorted(found)[: settings.count.max_candidates]]


def _on_whole_record(count: ModeCount, whole: DftLines, hold: str) -> ModeCount:
    """The counted model fitted to the whole record's lines (``whole``) from where the search left it."""
    start = fit_modal_model(whole, count.model.freq_hz, count.model.damping, hold, 1, settings=count.dft)
    whole = whole.noise_weighted(start)
    final = fit_modal_model(
        whole, count.model.freq_hz, count.model.damping, hold, count.settings.final_nfev, settings=count.dft
    )
    return replace(count, model=final)


def counted_modes(
    diagram,
    work: SelectionState,
    band_hz,
    hold: str,
    nas,
    settings: SelectionSettings = DEFAULTS,
    band=None,
    *,
    picked: bool = False,
    n_jobs: int | None = None,
    counter: Callable = count_modes,
) -> SelectionState:
    """Count the modes from the selection's and return them as the selection reports modes.

    Parameters
    ----------
    diagram : StabilisationDiagram
    work : SelectionState
        The selection so far (its modes the start, one row per mode as
        :func:`armaxmodal.select_modes` builds them).
    band_hz : (float, float)
        The band the model is fitted in (Hz).
    hold : {"bandlimited", "zoh"}
        The inter-sample assumption the refit chose.
    nas : list of int
        The diagram's orders.
    settings : SelectionSettings
        The count's thresholds, and the clustering's reaches and the orders a stable pole needs.
    band : (float, float), optional
        The user's band, for the left-out clusters.
    picked : bool
        Modes were picked by hand (the rows with a finite ``picked_hz``): the model of every row
        and of the poles the selection's own model kept unreported (``work.count``) is fitted as it
        stands and its margins measured, and the picked modes are reported (``pick_not_supported``
        says which picks the record does not need); the rest stay in the model.
    n_jobs : int, optional
        Worker threads for the count's screening fits (default: all cores).
    counter : callable
        The count, as :func:`~armaxmodal.modes.count_search.count_modes` (a test's stands in for it).

    Returns
    -------
    SelectionState
        The counted modes with the count and its notes. When the model keeps no mode in the band,
        the modes stay the selection's, and a ``count_undecided`` note says so.
    """
    rec, modes = diagram.recording, work.modes
    # the search runs on the record's first settings.count.max_samples; the chosen model is then
    # fitted to the whole record, so a long ride costs one fit more, not a search more
    part = _counted_part(rec, settings.count.max_samples)
    data = DftLines.from_recording(part, band_hz)
    # the modes the FRF's check doubts and the clusters at its unexplained peaks are tried first, as
    # additions the likelihood and the halves (and, where the model misfits, the diagram) must accept;
    # then the diagram's other left-out clusters
    offered = [(f, x) for f, x, _ in work.doubts] + list(work.proposals)
    candidates = offered + [
        c
        for c in _candidates(diagram, modes, band, nas, settings)
        if all(abs(np.log(c[0] / f)) > settings.cluster.freq for f, _ in offered)
    ]
    halves = tuple(DftLines.from_recording(half, band_hz) for half in part.split(2))
    supported = stable_in_diagram(diagram, band, settings.cluster)
    start_f, start_x = modes.freq_hz.to_numpy(), modes.damping.to_numpy()
    if picked and work.count is not None:  # the poles the selection's model kept unreported stay in it
        model = work.count.model
        hidden = ~work.count.reported(band_hz)
        start_f, start_x = np.r_[start_f, model.freq_hz[hidden]], np.r_[start_x, model.damping[hidden]]
    count = counter(
        data,
        start_f,
        start_x,
        candidates,
        hold=hold,
        halves=halves,
        supported=supported,
        search=not picked,
        n_jobs=n_jobs,
        settings=settings.count,
        dft=settings.dft,
        agreement=settings.agreement,
        reach=settings.cluster.freq,
    )
    whole = data if part is rec else DftLines.from_recording(rec, band_hz)  # each cut's lines built once
    if part is not rec:
        count = _on_whole_record(count, whole, hold)
    lines = {"count": count, "count_lines": (data, halves)}
    verdicts = count.verdicts(data.band_hz)
    keep = np.isin(verdicts, ("needed", "undecided"))
    same_row = settings.cluster.same_row_freq
    if picked:
        return replace(_picked_result(_doubts_said(work, ()), count, keep, verdicts, hold, settings), **lines)
    if not keep.any():  # the model keeps no mode in the band: the selection's stand, undecided
        return _doubts_said(work, ()).warned(
            no_mode_kept_note(count, modes, data.band_hz), *rule_notes(count, rec.sensors), **lines
        )
    rows = pd.DataFrame([_row(modes, count, i, hold, same_row, verdicts[i]) for i in np.flatnonzero(keep)])
    rows, shapes, merged = _one_where_not_separated(
        rows, count.model.shapes[:, keep], count, keep, whole, hold, settings
    )
    rows, disagree = covering_both_estimators(rows, settings.agreement.alpha)
    # where two poles are reported as one, the check fits the model's poles, not the row's
    poles = tuple(zip(count.model.freq_hz[keep].tolist(), count.model.damping[keep].tolist(), strict=True))
    work = work.with_modes(rows, shapes, check_poles=poles if merged else None, counted=True, **lines)
    work = _doubts_said(work, count.model.freq_hz[keep], same_row)
    return work.warned(
        *count_notes(count, keep, data.band_hz, same_row),
        *merged,
        *disagree,
        *rule_notes(count, rec.sensors, without_column(count, keep, supported)),
    )


def without_column(count: ModeCount, keep: np.ndarray, supported) -> list[float]:
    """The reported modes the count's rule refuses where its model is not adequate: those the diagram
    holds no stable column for; none where the model is adequate.

    Parameters
    ----------
    count : ModeCount
        The count's result (its ``adequacy`` and ``model``).
    keep : (n_poles,) bool ndarray
        The poles reported as modes.
    supported : callable
        ``supported(freq_hz, damping)``: does the diagram hold a stable column there?

    Returns
    -------
    list of float
        Their frequencies, Hz.
    """
    if count.adequacy is None or count.adequacy.adequate:
        return []
    m = count.model
    return [float(m.freq_hz[i]) for i in np.flatnonzero(keep) if not supported(m.freq_hz[i], m.damping[i])]


def _doubts_said(work: SelectionState, reported_hz, reach: float = 0.0) -> SelectionState:
    """The notes of the modes the FRF's check doubted that the count did not take back (no reported
    mode within ``reach`` of it, relative): they stand; the others go unsaid."""
    reported_hz = np.asarray(reported_hz, float)
    left = [note for f, _, note in work.doubts if not np.any(np.abs(np.log(reported_hz / f)) <= reach)]
    return replace(work, doubts=()).warned(*left)


def _counted_part(rec, max_samples: int):
    """The part of the record the nested tests run on: the whole, or its first of equal parts of at
    most ``max_samples`` samples."""
    return rec if rec.n_samples <= max_samples else rec.split(rec.n_samples // max_samples)[0]


def _one_where_not_separated(
    rows: pd.DataFrame,
    shapes: np.ndarray,
    count: ModeCount,
    keep: np.ndarray,
    whole: DftLines,
    hold: str,
    settings: SelectionSettings = DEFAULTS,
):
    """Two counted modes the record does not separate -- neither by frequency (:func:`not_separated`,
    on the model's own intervals) nor by shape (MAC at least the merge's ``merge_mac``) -- reported as
    one: the
    model with one pole there (either of the two taken out, the rest refitted free; the lower
    criterion), whose mode's intervals are widened to cover both. The likelihood may need two poles
    for one resonance whose frequency moves during the record (a nonlinearity: the F-16 at its
    highest level had two poles at 6.356 and 6.395 Hz, 0.2 SD apart), but their values are not
    two modes. ``whole``: the whole record's lines. Returns ``(rows, shapes, notes)``; a
    ``modes_not_separated`` note per merge."""
    poles, m = np.flatnonzero(keep), count.model
    # judged on the model's own intervals and shapes: two bodies' heavily damped modes 7-8 % apart
    # were 1.8 and 2.3 SD apart, and their shapes told them apart (MAC 0.70 and 0.05); the F-16's
    # pair at its highest level, 0.2 SD apart, has one shape as far as three sensors can tell
    own = pd.DataFrame(
        {
            "freq_hz": m.freq_hz[poles],
            "freq_ci95_lo": m.freq_hz[poles] - Z95 * m.freq_sd[poles],
            "freq_ci95_hi": m.freq_hz[poles] + Z95 * m.freq_sd[poles],
        }
    )
    same_shape = settings.cluster.merge_mac
    pairs = [
        (a, b, gap)
        for a, b, gap in not_separated(own)
        if mac(m.shapes[:, poles[a]], m.shapes[:, poles[b]]) >= same_shape
    ]
    if not pairs:
        return rows, shapes, []
    data = whole.noise_weighted(count.model)
    rows, shapes, notes, gone = rows.copy(), shapes.copy(), [], []
    for a, b, gap in pairs:
        fits = [
            fit_modal_model(
                data,
                np.delete(m.freq_hz, k),
                np.delete(m.damping, k),
                hold,
                settings.count.final_nfev,
                settings=settings.dft,
            )
            for k in (poles[a], poles[b])
        ]
        one = min(fits, key=lambda fit: fit.bic())
        both = rows.loc[[a, b]]
        k = nearest_pole(one.freq_hz, float(both.freq_hz.mean()))
        f, x = float(one.freq_hz[k]), float(one.damping[k])
        rows.loc[a, ["freq_hz", "damping", "damped_freq_hz"]] = [f, x, f * np.sqrt(1 - x**2)]
        rows.loc[a, ["freq_sd", "damping_sd"]] = [one.freq_sd[k], one.damping_sd[k]]
        both = with_intervals(both)  # the two rows' intervals (each with its other counts) are the other structure's
        rows.loc[a, ["freq_other_lo", "freq_other_hi", "damping_other_lo", "damping_other_hi"]] = [
            both.freq_ci95_lo.min(),
            both.freq_ci95_hi.max(),
            both.damping_ci95_lo.min(),
            both.damping_ci95_hi.max(),
        ]
        rows.loc[a, "structure_widened"] = True
        shapes[:, a] = one.shapes[:, k]
        gone.append(b)
        notes.append(reported_as_one_note(tuple(both.freq_hz), gap, same_shape, f, x))
    kept = [i for i in range(len(rows)) if i not in gone]
    return rows.iloc[kept].reset_index(drop=True), shapes[:, kept], notes


def confirmed_where_incoherent(
    work: SelectionState, unconfirmed_hz, settings: SelectionSettings = DEFAULTS
) -> tuple[tuple[float, ...], list]:
    """Of the modes the modal-model check cannot confirm (``unconfirmed_hz``: no coherent H1 line near
    them), those the maximum-likelihood modal model confirms: the likelihood needs it decisively (its
    removal raises the criterion by the count's ``decisive_bic`` or more) and the record's two
    halves give it the same frequency and damping. The modal model fits the DFT of the record, not
    its H1, and has no coherence to lose near a sharp peak (the stiff 3-storey frame's 39.67 Hz
    mode, damping 0.006, under Northridge: no coherent line within 1.3 Hz of it). Returns
    ``(confirmed Hz, their notes)``; none without a count. Judged on the count's own lines
    (``work.count_lines``), not built again."""
    count = work.count
    if count is None or not unconfirmed_hz:  # a count always comes with its lines (count_lines)
        return (), []
    m, hold, (data, halves) = count.model, work.refinement.hold, work.count_lines  # the count's own lines
    data = data.noise_weighted(m)
    chi2 = halves_chi2(
        data,
        m,
        halves,
        hold,
        count.settings.halves_nfev,
        count.dft,
        agreement=settings.agreement,
        reach=settings.cluster.freq,
    )
    agree = chdtrc(2, chi2) >= settings.agreement.alpha  # each pole alone: 2 degrees of freedom
    reach, needed = settings.cluster.same_row_freq, count.verdicts() == "needed"
    confirmed, notes = [], []
    nearest = [int(np.argmin(np.abs(m.freq_hz - f))) for f in unconfirmed_hz]
    gaps = np.array([abs(np.log(m.freq_hz[i] / f)) for f, i in zip(unconfirmed_hz, nearest, strict=True)])
    for f, i, gap in zip(unconfirmed_hz, nearest, gaps, strict=True):
        # a pole confirms one mode, the nearest: three modes near one pole are not three confirmed
        # modes (a report said "the criterion rises by 8243.4" of three, from one pole)
        own = gap == gaps[np.asarray(nearest) == i].min()
        if own and abs(m.freq_hz[i] / f - 1) <= reach and needed[i] and agree[i]:
            confirmed.append(f)
            notes.append(confirmed_where_incoherent_note(f, count.removal_rise[i]))
    return tuple(confirmed), notes


def _picked_result(
    work: SelectionState,
    count: ModeCount,
    keep: np.ndarray,
    verdicts: np.ndarray,
    hold: str,
    settings: SelectionSettings,
) -> SelectionState:
    """The picked rows (finite ``picked_hz``) reported: from the modal model where it keeps the pick
    as a mode of the band, else as the selection had it (the diagram's or the refit's values) with a
    ``pick_not_supported`` note that says where the model took it. The rows not picked stay in the
    model, said in a note; the check judges every mode of the model in the band (``check_poles``).
    ``keep`` marks the poles that are modes of the band, by the count's ``verdicts``."""
    m, rows, shapes, same_row = count.model, [], [], settings.cluster.same_row_freq
    picked = np.isfinite(work.modes.picked_hz.to_numpy())
    pairs = dict((j, i) for i, j in matched_poles(work.modes.freq_hz.to_numpy(), m.freq_hz))  # row -> pole
    picked_poles = np.zeros(m.n_modes, dtype=bool)
    for j, i in pairs.items():
        picked_poles[i] = keep[i] and picked[j]
    notes = pick_notes(count, picked_poles)
    for j in np.flatnonzero(picked):
        i = pairs[j]
        if keep[i]:
            rows.append(
                {**_row(work.modes, count, i, hold, same_row, verdicts[i]), "picked_hz": work.modes.picked_hz.iloc[j]}
            )
            shapes.append(m.shapes[:, i])
            continue
        row = work.modes.iloc[j].to_dict()
        rows.append({**row, "count_undecided": True, "structure_widened": False})
        shapes.append(work.shapes[:, j])
        notes.append(pick_moved_note(float(row["freq_hz"]), m.freq_hz[i], m.damping[i]))
    others = [pairs[j] for j in np.flatnonzero(~picked) if keep[pairs[j]]]
    if others:
        notes.append(not_picked_note(m, others))
    order = np.argsort([r["freq_hz"] for r in rows])
    rows = pd.DataFrame([rows[k] for k in order])
    rows, disagree = covering_both_estimators(rows, settings.agreement.alpha)
    notes += disagree
    # the check stage judges the model the picks come from: the picks and the modes not picked
    f, x = np.r_[rows.freq_hz.to_numpy(), m.freq_hz[others]], np.r_[rows.damping.to_numpy(), m.damping[others]]
    work = work.with_modes(
        rows,
        np.column_stack([shapes[k] for k in order]),
        count=count,
        counted=True,
        check_poles=tuple(zip(f.tolist(), x.tolist(), strict=True)),
    )
    return work.warned(*notes)


def _row(modes: pd.DataFrame, count: ModeCount, i: int, hold: str, same_row_freq: float, verdict: str) -> dict:
    """Mode ``i`` of the counted model as a selection row: the nearest selected row's cluster
    facts when it lies within ``same_row_freq``, else none (``count`` 0); ``verdict`` is the
    count's (:meth:`~armaxmodal.modes.mode_count.ModeCount.verdicts`)."""
    m = count.model
    f, x = m.freq_hz[i], m.damping[i]
    dist = np.abs(modes.freq_hz.to_numpy() / f - 1)
    j = int(np.argmin(dist))
    row = modes.iloc[j].to_dict()
    if dist[j] <= same_row_freq:  # the selection's estimate of this mode, for covering_both_estimators
        row.update(earlier_estimate(row))
    else:  # a mode the diagram's clusters did not hold
        # nor an ARMAX estimate: the segments' spread is judged against the modal model's own
        # deviation (as a mode the FRF screen adds), not the neighbouring row's
        row.update(
            count=0,
            support=0.0,
            freq_spread=np.nan,
            damping_spread=np.nan,
            medoid_freq_hz=np.nan,
            medoid_damping=np.nan,
            orders_damping_unresolved=0,
            energy=np.nan,
            freq_sd_armax=m.freq_sd[i],
            damping_sd_armax=m.damping_sd[i],
            **dict.fromkeys(EARLIER_COLUMNS, np.nan),
        )
    other, widened = count.other_structures(i, same_row_freq)
    row.update(
        freq_hz=f,
        damping=x,
        damped_freq_hz=f * np.sqrt(1 - x**2),
        freq_sd=m.freq_sd[i],
        damping_sd=m.damping_sd[i],
        **other,
        estimator=f"ml-{hold}",
        count_undecided=verdict == "undecided",
        structure_widened=widened,
    )
    return row
