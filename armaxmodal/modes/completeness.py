"""Which candidates the record needs: the modal-model check (:mod:`armaxmodal.modes.modal_check`)
drops a mode the measured FRF does not need and adds a left-out cluster that explains a clear
peak no selected mode explains.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pandas as pd

from armaxmodal.modes.clusters import candidate_poles, cluster_poles, mode_row, order_criteria, representative_pole
from armaxmodal.modes.modal_check import check_modes
from armaxmodal.modes.selected_refit import RefitFailure, refined_modes, refit_band, selection_job
from armaxmodal.modes.settings import DEFAULTS, SelectionSettings
from armaxmodal.modes.state import SelectionState
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording


def modes_the_record_needs(recording: Recording, work: SelectionState, band, settings: SelectionSettings = DEFAULTS,
                           doubts: list | None = None) -> SelectionState:  # fmt: skip
    """Selection by the data: drop, one at a time and least supported first, every mode the
    modal-model check does not need (:func:`armaxmodal.modes.support.mode_support`: leaving it
    out, a neighbour inside its half-power band refitted in its place, raises no output's
    misfit by ``settings.frf.model_error_rise`` significantly). A dropped half
    of a split peak is a ``split_merged`` note, any other a ``mode_not_needed`` note. With
    ``doubts`` (a list), each dropped mode goes there as ``(Hz, ratio, note)`` instead of its note
    into the selection: the count tries it again and the note stands only if it stays out.
    Returns the selection of the modes kept, with their check."""
    from armaxmodal.modes.support import mode_support

    frf = settings.frf
    while True:
        modes = work.modes
        check = check_modes(recording, modes.freq_hz, modes.damping, band, settings=frf)
        work = replace(work, check=check)
        if len(modes) < 2 or not np.isfinite(check.error).any():
            return work
        support = [mode_support(recording, modes.freq_hz, modes.damping, m, check, band, settings=frf)
                   for m in range(len(modes))]  # fmt: skip
        weak = [m for m in range(len(modes)) if not support[m].needed]
        if not weak:
            return work
        # the least supported across orders goes first (of a split, the half the diagram
        # shows less), then the least needed
        rank = modes.sort_values(["support", "count", "energy"]).index.tolist()
        m = min(weak, key=lambda i: (rank.index(i), support[i].rise))
        s, f_m, x_m = support[m], modes.at[m, "freq_hz"], modes.at[m, "damping"]
        evidence = (
            f"without it no output's misfit rises by {100 * frf.model_error_rise:g} % "
            f"(at most {100 * s.rise:+.1f} %, p = {s.p_value:.2g})"
        )
        if s.refitted_neighbour is not None:
            f_n = modes.at[s.refitted_neighbour, "freq_hz"]
            note = QualityWarning(
                "split_merged", (),
                f"modes at {f_n:.3f} and {f_m:.3f} Hz overlap within their half-power bands and the measured FRF does "
                f"not need both: {evidence} once {f_n:.3f} Hz may take the whole peak; one peak split by the model, "
                f"{f_n:.3f} Hz is reported", float(f_m),
            )  # fmt: skip
        else:
            note = QualityWarning(
                "mode_not_needed", (),
                f"a stable pole at {f_m:.3f} Hz (damping {x_m:.3f}) is left out: the measured FRF does not need it, "
                f"{evidence}: a spurious pole of the model (noise, a nonlinearity, leakage), not a mode of the record",
                float(f_m),
            )  # fmt: skip
        work = work.kept(i for i in range(len(modes)) if i != m)
        if doubts is None:
            work = work.warned(note)
        else:
            doubts.append((float(f_m), float(x_m), note))


def each_once(doubts) -> tuple:
    """The doubts by frequency, a mode the check dropped in both of its passes once (its first note)."""
    once = {f: (f, x, note) for f, x, note in reversed(doubts)}
    return tuple(sorted(once.values(), key=lambda d: d[0]))


def refit_with_added(diagram, work: SelectionState, band, settings: SelectionSettings = DEFAULTS) -> SelectionState:
    """The frequency-domain refit again, of every mode once the check has added some: a mode
    missing from a refit biases its neighbours (a five-segment chain's 13.5 Hz mode came out
    at 12.5 Hz while the 24.8 Hz one was missing, and its refit was refused as too far; now
    13.3 Hz for the exact 13.54). A refit that cannot be made leaves the modes, said."""
    refit = selection_job(diagram.recording, [], work.modes, ("refit", refit_band(diagram.recording, band)),
                          settings.dft)  # fmt: skip
    if isinstance(refit, RefitFailure):
        work = work.warned(*refit.notes("the modes with those the check added", uncounted=False))
    else:  # the first refit's start lacked these modes: its refusals may not stand
        c = settings.cluster
        work = refined_modes(diagram, work, refit, c.freq, c.damping, c.merge_mac, relaxed=True)
    check = check_modes(diagram.recording, work.modes.freq_hz, work.modes.damping, band, settings=settings.frf)
    return replace(work, check=check)


def modes_the_check_adds(diagram, work: SelectionState, band, nas, settings: SelectionSettings = DEFAULTS
                        ) -> SelectionState:  # fmt: skip
    """Stable clusters the support rule left out enter when the modal-model check needs them
    (as :func:`modes_the_record_needs` judges, but with the nearest mode refitted in its place,
    not only an overlapping one: one at a time, the largest first): the
    candidates are the cluster of poles of at least ``frf.peak_cluster_min_orders`` orders
    within ``frf.peak_cluster_freq`` of each clear, coherent H1 peak no selected mode
    explains (:func:`armaxmodal.modes.frf.unexplained_peaks`), and every cluster of kept
    poles of at least three orders away from the selected modes (heavily damped modes make
    no clear peak, and their poles scatter over the orders; these need a damping the record
    resolves, as a peak's cluster does not). A peak left unexplained is listed at the end as
    before. Returns the selection with those added, by frequency, and its check."""
    from armaxmodal.modes.support import mode_support

    bic, frf = order_criteria(diagram), settings.frf
    modes, shapes, check = work.modes, work.shapes, work.check
    for sub, at_peak in _left_out_clusters(diagram, modes, band, nas, settings):
        # the cluster's centre is tried: its lowest-BIC pole may sit at its edge
        centre = float(sub.freq_hz.median()), float(sub.damping.median())
        if np.any(np.abs(modes.freq_hz.to_numpy() / centre[0] - 1) <= frf.duplicate_freq):
            continue  # a selected mode's own pole
        trial = np.r_[modes.freq_hz, centre[0]], np.r_[modes.damping, centre[1]]
        trial_check = check_modes(diagram.recording, *trial, band, settings=frf)
        if centre[0] in trial_check.unconfirmed_hz:
            continue  # no coherent line there: the check cannot judge it, so it cannot enter
        if not mode_support(diagram.recording, *trial, len(modes), trial_check, band, reach="nearest",
                            settings=frf).needed:  # fmt: skip
            continue
        core = sub[np.abs(sub.freq_hz / centre[0] - 1) <= frf.peak_cluster_freq]  # reported from near the centre
        rep = representative_pole(diagram, core if len(core) else sub, bic, {}, settings.cluster.finished_max_shift)
        if rep is None or (not at_peak and not rep.damping_ci95_lo > 0):
            continue  # without a peak, a pole whose damping the record does not resolve is no evidence
        row = {**mode_row(rep, sub, len(nas)), "orders_damping_unresolved": 0, "estimator": "armax"}
        row["freq_sd_armax"], row["damping_sd_armax"] = row["freq_sd"], row["damping_sd"]
        modes = pd.concat([modes, pd.DataFrame([row])], ignore_index=True)
        shapes = np.column_stack([shapes, rep.vector])
        check = check_modes(diagram.recording, modes.freq_hz, modes.damping, band, settings=frf)
    return work.with_modes(modes, shapes, check=check).kept(modes.sort_values("freq_hz").index)


def _left_out_clusters(diagram, modes: pd.DataFrame, band, nas, settings: SelectionSettings
                       ) -> list[tuple[pd.DataFrame, bool]]:  # fmt: skip
    """The candidate clusters of :func:`modes_the_check_adds`, the largest first, each with
    whether it stands at an unexplained peak."""
    from armaxmodal.modes.frf import unexplained_peaks

    cluster, frf = settings.cluster, settings.frf
    cand = candidate_poles(diagram.poles, band)
    cand = cand[cand.damping > 0]
    found = []
    for peak in unexplained_peaks(diagram.recording, modes.freq_hz.to_numpy(), modes.damping.to_numpy(), band):
        near = cand[np.abs(cand.freq_hz / peak.value - 1) <= frf.peak_cluster_freq]
        clusters = [c for c in cluster_poles(near, nas, frf.peak_cluster_freq, None)
                    if len(c) >= frf.peak_cluster_min_orders]  # fmt: skip
        if clusters:
            found.append((near.loc[max(clusters, key=len)], True))
    # away from a peak, a cluster in the top of the input's band is its edge's, not a mode
    top = frf.edge_fraction * refit_band(diagram.recording, band)[1]
    kept = cand[(cand.rejected == "") & (cand.freq_hz <= top)]
    selected = modes.freq_hz.to_numpy()
    for members in cluster_poles(kept, nas, cluster.freq, cluster.damping):
        sub = kept.loc[members]
        if len(members) >= cluster.min_orders and np.min(np.abs(selected / sub.freq_hz.median() - 1)) > cluster.freq:
            found.append((sub, False))
    return sorted(found, key=lambda item: len(item[0]), reverse=True)
