"""What the measured FRF says of the selection (thesis Section 3.3.3's check, made quantitative):
its clear, coherent peaks no selected mode explains (``unexplained_peaks``, at ``PEAK_RESOLUTION``);
the diagram's clusters at those peaks, which it proposes to the count
(``modes_at_unexplained_peaks``); the resonances the input does not drive (``undriven_resonances``);
and the candidates the modal-model check
(:mod:`armaxmodal.modes.modal_check`, at ``CHECK_RESOLUTION``) does not need, which leave the
count's start and are offered to it as additions (``modes_the_record_needs``). The count decides.

``mode_support`` is the check's test: its misfit with and without a mode, an overlapping
neighbour refitted in its place (``ModeSupport``: needed when the rise is large and significant).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from armaxmodal.modes.clusters import candidate_poles, cluster_poles
from armaxmodal.modes.modal_check import ModalCheck, check_modes, poles_of, rss_at
from armaxmodal.modes.notes import not_needed_note, undriven_resonance_note
from armaxmodal.modes.poles import NEGATIVE_DAMPING
from armaxmodal.modes.settings import DEFAULTS, PEAK_RESOLUTION, ClusterSettings, FrfSettings, SelectionSettings
from armaxmodal.modes.state import SelectionState
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording
from armaxmodal.spectra import coherent_lines, coherent_peaks, explains, resolving_nperseg


@dataclass(frozen=True)
class ModeSupport:
    """How much the check needs one mode: each output's relative misfit with and without it
    (a neighbour within its half-power band refitted in its place), and the F-test's p."""

    error_with: np.ndarray
    error_without: np.ndarray
    p_value: float
    refitted_neighbour: int | None
    settings: FrfSettings = DEFAULTS.frf
    alpha: float = DEFAULTS.agreement.alpha  #: the F-test's level: the selection's tests' one false-alarm rate

    @property
    def rise(self) -> float:
        """The largest relative rise of an output's misfit without the mode."""
        ratio = self.error_without / np.maximum(self.error_with, 1e-300)
        finite = ratio[np.isfinite(ratio)]
        return float(finite.max() - 1) if finite.size else float("nan")

    @property
    def needed(self) -> bool:
        """The rise is at least ``settings.model_error_rise`` and significant at ``alpha``."""
        return bool(self.rise >= self.settings.model_error_rise and self.p_value <= self.alpha)


def overlapping_neighbour(freq_hz, damping, m: int) -> int | None:
    """The nearest mode whose half-power band overlaps mode ``m``'s
    (``|f_i - f_m| < xi_i f_i + xi_m f_m``), or None."""
    f, x = np.asarray(freq_hz, dtype=float), np.asarray(damping, dtype=float)
    gap = np.abs(f - f[m])
    close = [i for i in range(f.size) if i != m and gap[i] < x[i] * f[i] + x[m] * f[m]]
    return min(close, key=lambda i: gap[i]) if close else None


def mode_support(
    recording: Recording,
    freq_hz,
    damping,
    m: int,
    check: ModalCheck,
    band=None,
    *,
    settings: FrfSettings = DEFAULTS.frf,
    alpha: float = DEFAULTS.agreement.alpha,
) -> ModeSupport:
    """How much the check of ``check`` needs mode ``m`` (see ``ModeSupport``; ``alpha``: the F-test's level).

    The fit without the mode keeps each output's delay. A neighbour, a mode whose half-power band
    overlaps this one's (:func:`overlapping_neighbour`), has its frequency and damping refitted
    (Nelder-Mead on the summed relative residual, residues projected out) so it may take over: two
    poles always fit one peak at least as well as one, so only a refitted single pole shows whether
    the record needs both. The F-test
    compares the summed relative residual sums with ``q = 2 n_outputs`` (the residues)
    ``+ 2`` (the pole, unless the neighbour's refit spends them) over ``sum(lines) -
    parameters`` degrees of freedom (one per complex line: the Hann-windowed,
    half-overlapped lines are correlated in pairs).
    """
    from scipy.optimize import minimize
    from scipy.special import fdtrc  # F survival function without scipy.stats' import

    f, x = np.asarray(freq_hz, dtype=float), np.asarray(damping, dtype=float)
    all_lines = coherent_lines(recording, check.nperseg, band)
    used = [k for k, lines in enumerate(all_lines) if np.isfinite(check.error[k])]
    norms = {k: float(np.sum(np.abs(all_lines[k].h) ** 2)) for k in used}

    def relative_rss(poles) -> np.ndarray:
        return np.array([rss_at(all_lines[k], poles, check.delay_s[k]) / norms[k] for k in used])

    keep = [i for i in range(f.size) if i != m]
    with_m = relative_rss(poles_of(f, x))
    j = overlapping_neighbour(f, x, m)
    fk, xk = f[keep], x[keep]
    if j is not None:
        at = keep.index(j)

        def cost(p):
            fj, xj = fk.copy(), xk.copy()
            fj[at], xj[at] = f[j] * np.exp(p[0]), min(x[j] * np.exp(p[1]), 0.9)
            return float(np.sum(relative_rss(poles_of(fj, xj))))

        best = minimize(cost, np.zeros(2), method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-9, "maxiter": 200})
        fk, xk = fk.copy(), xk.copy()
        fk[at], xk[at] = f[j] * np.exp(best.x[0]), min(x[j] * np.exp(best.x[1]), 0.9)
    without = relative_rss(poles_of(fk, xk))
    n_obs = sum(all_lines[k].freq_hz.size for k in used)
    q = 2 * len(used) + (0 if j is not None else 2)
    dof = n_obs - len(used) * (2 * f.size + 5) - 2 * f.size
    s1, s0 = float(with_m.sum()), float(without.sum())
    stat = ((s0 - s1) / q) / (s1 / dof) if dof > 0 and s1 > 0 else float("nan")
    p = float(fdtrc(q, dof, stat)) if np.isfinite(stat) and stat > 0 else 1.0
    return ModeSupport(np.sqrt(with_m), np.sqrt(without), p, j, settings, alpha)


def modes_the_record_needs(
    recording: Recording, work: SelectionState, band, settings: SelectionSettings = DEFAULTS, doubts: list | None = None
) -> SelectionState:
    """Selection by the data: drop, one at a time and least supported first, every mode the
    modal-model check does not need (``mode_support``: leaving it
    out, a neighbour inside its half-power band refitted in its place, raises no output's
    misfit by ``settings.frf.model_error_rise`` significantly). A dropped half
    of a split peak is a ``split_merged`` note, any other a ``mode_not_needed`` note. With
    ``doubts`` (a list), each dropped mode goes there as ``(Hz, ratio, note)`` instead of its note
    into the selection: the count tries it again and the note stands only if it stays out.
    Returns the selection of the modes kept, with their check."""
    frf, alpha = settings.frf, settings.agreement.alpha
    while True:
        modes = work.modes
        check = check_modes(recording, modes.freq_hz, modes.damping, band, settings=frf)
        work = replace(work, check=check)
        if len(modes) < 2 or not np.isfinite(check.error).any():
            return work
        support = [
            mode_support(recording, modes.freq_hz, modes.damping, m, check, band, settings=frf, alpha=alpha)
            for m in range(len(modes))
        ]
        weak = [m for m in range(len(modes)) if not support[m].needed]
        if not weak:
            return work
        # the least supported across orders goes first (of a split, the half the diagram
        # shows less), then the least needed
        rank = modes.sort_values(["support", "count", "energy"]).index.tolist()
        m = min(weak, key=lambda i: (rank.index(i), support[i].rise))
        s, f_m, x_m = support[m], modes.at[m, "freq_hz"], modes.at[m, "damping"]
        neighbour = None if s.refitted_neighbour is None else modes.at[s.refitted_neighbour, "freq_hz"]
        note = not_needed_note(f_m, x_m, neighbour, frf.model_error_rise, alpha, s.rise, s.p_value)
        work = work.kept(i for i in range(len(modes)) if i != m)
        if doubts is None:
            work = work.warned(note)
        else:
            doubts.append((float(f_m), float(x_m), note))


def modes_at_unexplained_peaks(
    diagram, modes: pd.DataFrame, band, nas, cluster: ClusterSettings = DEFAULTS.cluster
) -> list:
    """What the measured H1 proposes to the count: at each clear, coherent H1 peak no mode of
    ``modes`` explains (:func:`unexplained_peaks`), the largest cluster of the diagram's poles of at
    least ``cluster.min_orders`` orders (a stable pole's) within the clustering's reach
    ``cluster.freq`` of it, as its median ``(Hz, ratio)``. A proposal only: the count adds it where
    the likelihood, the record's halves and (where the model misfits) the diagram's columns take it,
    and leaves it out otherwise.
    Returns ``[(freq_hz, damping), ...]``, the largest cluster first."""
    cand = candidate_poles(diagram.poles, band)
    cand = cand[cand.damping > 0]
    found = []
    for peak in unexplained_peaks(diagram.recording, modes.freq_hz.to_numpy(), modes.damping.to_numpy(), band):
        near = cand[np.abs(cand.freq_hz / peak.value - 1) <= cluster.freq]
        clusters = [c for c in cluster_poles(near, nas, cluster.freq, None) if len(c) >= cluster.min_orders]
        if clusters:
            found.append(near.loc[max(clusters, key=len)])
    found.sort(key=len, reverse=True)
    return [(float(sub.freq_hz.median()), float(sub.damping.median())) for sub in found]


def undriven_resonances(
    diagram, freq_hz, band, nas, cluster: ClusterSettings = DEFAULTS.cluster
) -> list[QualityWarning]:
    """An ``undriven_resonance`` note for each column of the diagram's shared poles of negative
    damping beyond their intervals (``poles.rejection_reasons``; poles of at least
    ``cluster.min_orders`` orders within the clustering's reach) at a clear, coherent H1 peak
    (``PEAK_RESOLUTION``), where no reported mode (``freq_hz``) lies within that reach.
    The record resonates there, but the input does not drive the resonance as it drives a mode of a
    structure on one moving base: every order fits it with poles that grow. Of the measured records
    only Painter Street's 2021 and 2023 events hold such a column (4.34 Hz at 10 orders, 4.15 Hz at
    14), each beside the H1's coherent peak (4.25 and 4.21 Hz) that no mode of theirs is near: a
    bridge moved at its abutments as well as at the bent its input measures."""
    growing = candidate_poles(diagram.poles, band, rejected=(NEGATIVE_DAMPING,))
    columns = [growing.loc[c] for c in cluster_poles(growing, nas, cluster.freq, None) if len(c) >= cluster.min_orders]
    columns = [
        c for c in columns if not np.any(np.abs(np.log(np.asarray(freq_hz) / c.freq_hz.median())) <= cluster.freq)
    ]
    if not columns:
        return []
    res, rec = PEAK_RESOLUTION, diagram.recording
    centres = [(c.freq_hz.median(), -c.damping.median()) for c in columns]
    n = resolving_nperseg(rec, *zip(*centres, strict=True), res.lines_per_bandwidth, res.min_segments)
    peaks = coherent_peaks(rec, n, res.lines_per_bandwidth, band)
    found = []
    for column in columns:
        f = float(column.freq_hz.median())
        near = [p for p in peaks if abs(np.log(p[0] / f)) <= cluster.freq]
        if near:
            found.append(undriven_resonance_note(f, column.na.nunique(), column.damping.to_numpy(), near))
    return found


def unexplained_peaks(recording: Recording, freq_hz, damping, band=None) -> list[QualityWarning]:
    """Coherent peaks of the measured FRF (:func:`~armaxmodal.spectra.coherent_peaks`, at ``PEAK_RESOLUTION``)
    with no selected mode within its half-power bandwidth: each a ``unexplained_peak`` warning."""
    res = PEAK_RESOLUTION
    n = resolving_nperseg(recording, freq_hz, damping, res.lines_per_bandwidth, res.min_segments)
    df = recording.fs / n
    peaks = coherent_peaks(recording, n, res.lines_per_bandwidth, band)
    return _merged([p for p in peaks if not explains(p[0], df, freq_hz, damping)], df)


def _merged(peaks, df) -> list[QualityWarning]:
    """One warning per peak seen on several sensors (within 3 % or 3 lines of each other)."""
    groups: list[list] = []
    for p in sorted(peaks):
        if groups and p[0] - groups[-1][-1][0] <= max(0.03 * p[0], 3 * df):
            groups[-1].append(p)
        else:
            groups.append([p])
    warnings = []
    for g in groups:
        f0 = max(g, key=lambda p: p[2])[0]
        sensors = tuple(sorted({p[1] for p in g}))
        warnings.append(
            QualityWarning(
                "unexplained_peak",
                sensors,
                f"the measured FRF has a clear, coherent peak at {f0:.2f} Hz ({', '.join(sensors)}) that no "
                "selected mode explains: a mode the selection missed (widen --orders or --modes), or a disturbance "
                "(run 'armaxmodal diagnose')",
                f0,
                (f0,),
            )
        )
    return warnings
