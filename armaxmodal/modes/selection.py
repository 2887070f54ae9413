"""Automatic mode selection from a stabilisation diagram (thesis Section 3.4).

:func:`~armaxmodal.select_modes` clusters the stable shared-pole estimates across orders, keeps the
clusters supported by a good share of the orders, reports each from its lowest-BIC fit,
refits them to the recording's DFT, lets the modal-model check drop or add modes, and widens
the intervals by the segment spread. It is deterministic: the same data gives the same
modes. :class:`ModeSelection` is the result and its JSON contract.

One module of about 530 lines on purpose: :class:`ModeSelection` is the JSON contract of
``stabilise`` and its verdict, and :func:`~armaxmodal.select_modes` the order of the stages that fill it;
each stage's work is in its own module.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
import pandas as pd

from armaxmodal._threads import one_blas_thread
from armaxmodal.exceptions import PickError
from armaxmodal.modal import mode_record
from armaxmodal.modes.clusters import clustered_modes, merge_duplicates, why_no_mode
from armaxmodal.modes.completeness import modes_the_check_adds, modes_the_record_needs, refit_with_added
from armaxmodal.modes.counted import (
    SEPARATION_SD,
    confirmed_where_incoherent,
    counted_modes,
    dropped_where_peaks_remain,
    not_separated,
)
from armaxmodal.modes.diagram import StabilisationDiagram
from armaxmodal.modes.header import oversampling_note, record_header
from armaxmodal.modes.intervals import with_intervals
from armaxmodal.modes.modal_check import ModalCheck, check_modes
from armaxmodal.modes.mode_count import ModeCount
from armaxmodal.modes.per_sensor import per_sensor_table
from armaxmodal.modes.picks import PICK_REACH, check_picks, picked_modes
from armaxmodal.modes.refine import ModalRefinement
from armaxmodal.modes.selected_refit import RefitFailure, refined_modes, refit_and_segment_fits
from armaxmodal.modes.spread import (
    N_SEGMENTS,
    apply_segment_spread,
    segment_spread,
)
from armaxmodal.modes.working import WorkingSelection
from armaxmodal.quality_warnings import UNCERTAIN_CODES, QualityWarning

__all__ = ["select_modes", "ModeSelection", "verdict"]


# -- automatic selection -----------------------------------------------------------------------
@dataclass(frozen=True)
class ModeSelection:
    """Physical modes picked from a stabilisation diagram.

    Attributes
    ----------
    modes : DataFrame
        One row per mode, by frequency: freq_hz, damping, damped_freq_hz and 95 % intervals
        (``*_ci95_lo/hi``), the parts the intervals combine (the estimate's ``freq_sd`` and
        ``damping_sd``, the other structures' ``*_other_lo/hi``, the segments'
        ``*_segment_half``: :mod:`armaxmodal.modes.intervals`), na of the representative fit,
        count and support of the cluster, its spread (standard deviation over orders) and medoid.
    shapes : (n_sensors, n_modes) complex ndarray
        EPFRF modal constants per sensor (Eq. 3.24) from the representative fit.
    per_sensor : DataFrame
        Table 3.2 form: one row per sensor and mode with the sensor's own frequency, damping
        and residue magnitude, NaN where the sensor does not show the mode (the thesis's X).
    weighted : DataFrame
        Eqs. 3.35-3.36: per mode, the mean of the per-sensor values weighted by ``|M_ij|``.
    diagram : StabilisationDiagram
    refinement : ModalRefinement or None
        The frequency-domain refit (:mod:`armaxmodal.modes.refine`); its ``hold`` is the
        inter-sample behaviour the data chose. ``modes.estimator`` says which values are
        reported: the refit for a band-limited recording, the ARMAX fit (the exact model
        class) for a held input.
    """

    modes: pd.DataFrame
    shapes: np.ndarray
    per_sensor: pd.DataFrame
    weighted: pd.DataFrame
    diagram: StabilisationDiagram
    refinement: ModalRefinement | None = None
    own_warnings: tuple[QualityWarning, ...] = ()
    check: ModalCheck | None = None
    count: ModeCount | None = None

    @property
    def picks(self) -> list[float] | None:
        """The frequencies (Hz) the modes were picked at by hand, or None for an automatic pick."""
        if "picked_hz" not in self.modes:
            return None
        return sorted(float(f) for f in self.modes.picked_hz if np.isfinite(f))

    @property
    def reconstruction_error(self) -> float:
        """The modal-model check's relative misfit (:mod:`armaxmodal.modes.modal_check`): the
        largest output's relative RMS difference between the measured H1 and its LSFD fit
        by the selected poles with residual terms and a delay. Computed once, in
        :func:`~armaxmodal.select_modes`: the CLI, the figure and the JSON report the same number."""
        return self.check.overall_error if self.check is not None else float("nan")

    @property
    def quality(self) -> str:
        """``"poor"`` when the modal-model check fails; ``"uncertain"`` when it passes but a
        warning of ``armaxmodal.quality_warnings.UNCERTAIN_CODES`` stands (the record does not decide
        the number of modes, two modes are closer than it separates, or the preparation found a
        fault that moves modes); else ``"good"``."""
        if self.check is None or not self.check.passed:
            return "poor"
        return "uncertain" if self.uncertain_because else "good"

    @property
    def verdict(self) -> str:
        """The closing line of ``stabilise``: the quality and why (:func:`verdict`)."""
        return verdict(self.check, len(self.modes), self.uncertain_because)

    def _repr_html_(self) -> str:
        """A notebook's view: the verdict and the modes with their intervals."""
        import html

        from armaxmodal.modes.report import modes_table

        table = modes_table(self).to_html(index=False, float_format=lambda v: f"{v:.4g}", border=0)
        return f"<p><b>{html.escape(self.verdict)}</b></p>{table}"

    @property
    def uncertain_because(self) -> list[str]:
        """The codes of the warnings that make a passing selection uncertain, sorted."""
        return sorted({w.code for w in self.warnings if w.code in UNCERTAIN_CODES})

    @property
    def warnings(self) -> list[QualityWarning]:
        """The diagram's data-quality warnings and the selection's own."""
        return self.diagram.warnings + list(self.own_warnings)

    def to_dict(self, shapes: str = "shared") -> dict:
        """The JSON contract of the ``stabilise`` command.

        ``shapes="shared"`` reports the shared-pole residues (complete by construction);
        ``"per_sensor"`` each sensor's own residue, with gaps filled by Eq. (3.34) and
        flagged ``supplemented``.

        Parameters
        ----------
        shapes : {"shared", "per_sensor"}
            Which residues give the mode shapes.

        Returns
        -------
        dict
            Strict-JSON-ready (no NaN), as ``schemas/stabilise.schema.json`` describes.
        """
        if shapes not in ("shared", "per_sensor"):
            raise ValueError(f"shapes: expected 'shared' or 'per_sensor', got {shapes!r}.")
        rec = self.diagram.recording
        if shapes == "shared":
            matrix, flags = self.shapes, np.zeros(self.shapes.shape, dtype=bool)
        else:
            from armaxmodal.modes.per_sensor import supplement_shapes

            matrix, flags = supplement_shapes(self)
        modes = []
        for i, row in enumerate(self.modes.itertuples(index=False)):
            record = mode_record(row, matrix[:, i], rec.sensors, flags[:, i])
            record.update(
                orders_supporting=int(row.count),
                freq_spread_hz=float(row.freq_spread),
                damping_spread=float(row.damping_spread),
            )
            if "segments_found" in self.modes:
                record["segment_spread"] = {
                    "segments_found": int(row.segments_found),
                    "freq_sd_hz": _finite_or_none(row.freq_segment_sd),
                    "damping_sd": _finite_or_none(row.damping_segment_sd),
                }
                record["model_error_dominates"] = bool(row.model_error_dominates)
            record["picked"] = bool(np.isfinite(getattr(row, "picked_hz", np.nan)))
            if "structure_widened" in self.modes:  # the modal model's count (modes/counted.py)
                record["count_undecided"] = bool(row.count_undecided)
                record["interval_covers_other_counts"] = bool(row.structure_widened)
            if "estimator_widened" in self.modes:  # the two estimators disagree (modes/estimators.py)
                record["interval_covers_other_estimator"] = bool(row.estimator_widened)
            modes.append(record)
        per_sensor = [
            {k: (None if isinstance(v, float) and np.isnan(v) else v) for k, v in r.items()}
            for r in self.per_sensor.drop(columns=["own_modal_constant"]).to_dict("records")
        ]
        t = self.diagram.tolerances
        prep = self.diagram.preparation
        return {
            **record_header(rec, prep, self.warnings),
            "nk": self.diagram.orders[0].nk,
            "orders_na": [o.na for o in self.diagram.orders],
            "tolerances": {"freq": t.freq, "damping": t.damping, "shape": t.shape, "max_damping": t.max_damping},
            "quality": self.quality,
            "reconstruction_error": _finite_or_none(self.reconstruction_error),
            "modal_check": None if self.check is None else self.check.to_dict(),
            "intersample_hold": None if self.refinement is None else self.refinement.hold,
            "estimator": sorted(set(self.modes.estimator)),
            "picks": self.picks,
            "modes": modes,
            "per_sensor": per_sensor,
        }


def select_modes(
    diagram: StabilisationDiagram,
    n_modes: int | None = None,
    band: tuple[float, float] | None = None,
    *,
    min_support: float = 0.4,
    cluster_freq: float = 0.05,
    cluster_damping: float = 0.5,
    merge_mac: float = 0.8,
    refine: bool = True,
    segments: int = N_SEGMENTS,
    n_jobs: int | None = None,
    progress: bool = False,
    picks=None,
) -> ModeSelection:
    """Pick the physical modes from the shared-pole poles of a diagram.

    Kept, non-rejected poles are clustered across orders (greedy, in order of increasing
    ``na``; a pole joins the nearest cluster whose median lies within ``cluster_freq``
    relative frequency and ``cluster_damping`` relative damping and which has no pole of that
    order yet). A cluster is a mode when it holds poles of at least ``min_support`` of the
    swept orders. Each mode is reported from the
    fit of lowest BIC among the orders in its cluster -- the most parsimonious adequate model;
    over-parameterised orders scatter heavily damped modes -- with the cluster's medoid,
    spread and count alongside. Two modes closer than the half-power bandwidth of the
    better-supported one (``2 xi f``) whose shapes agree (MAC >= ``merge_mac``) are one mode
    split by over-modelling; the weaker is dropped.

    Parameters
    ----------
    diagram : StabilisationDiagram
    n_modes : int, optional
        Keep the ``n_modes`` best-supported modes (the modal-model check then judges them but
        neither drops nor adds any).
    band : (lo, hi), optional
        Frequency band in Hz (default: the diagram's band, if it was given one).
    refine : bool
        Refit the selected modes to the recording's DFT under the inter-sample behaviour the
        data choose (``armaxmodal.modes.refine.refine_modes``) and report the refit when the
        recording is band-limited, where the discrete ARMAX class is biased.
    segments : int
        Refit each mode's representative orders on this many disjoint segments and widen
        the intervals where their spread exceeds them (:mod:`armaxmodal.modes.spread`); 0 skips.
    n_jobs : int, optional
        Worker threads for the finishing and segment fits (default: all cores; 1 inside a
        worker that has one core already, e.g. a study's).
    picks : sequence of float, optional
        Frequencies (Hz) picked by hand: each takes the nearest cluster of the diagram holding
        poles of at least 3 orders within ``armaxmodal.modes.picks.PICK_REACH`` (a
        :class:`~armaxmodal.exceptions.PickError` says when none does). The picks are refitted,
        checked and judged as automatic modes are, but none is dropped or added: a pick the
        record does not need is said to be (``pick_not_supported``). Not with ``n_modes``.
    progress : bool
        Show a count of the fits the selection runs (finishing fits, the refit and the
        segment refits: on a long record they take as long as the sweep). A count, not a
        fraction: how many there are is known only as the selection goes.
    min_support : float
        Fraction of the swept orders a cluster must hold poles of to be a mode.
    cluster_freq : float
        Relative frequency distance within which a pole joins a cluster.
    cluster_damping : float
        Relative damping distance within which a pole joins a cluster.
    merge_mac : float
        Shape agreement (MAC) above which two close modes are one mode split.

    Returns
    -------
    ModeSelection
        The modes with their intervals and shapes, the modal-model check, the count's
        evidence and the verdict.

    Examples
    --------
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 120.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> selection = am.select_modes(am.stabilisation_diagram(ride, range(4, 13, 2)))
    >>> selection.quality
    'good'
    >>> exact = am.supine_human().modes().freq_hz  # 5.83, 8.31, 13.50, 16.25 Hz
    >>> bool(np.allclose(selection.modes.freq_hz, exact, rtol=0.02))
    True
    >>> bool(np.all(selection.modes.freq_ci95_lo < selection.modes.freq_ci95_hi))
    True
    """
    from tqdm import tqdm

    with one_blas_thread(), tqdm(desc="mode selection", unit="fit", disable=not progress) as bar:
        if band is None and diagram.preparation is not None:
            band = diagram.preparation.band
        nas = sorted({o.na for o in diagram.orders})
        clustering = (cluster_freq, cluster_damping)
        if picks is not None:  # each takes its cluster now: a pick the diagram does not offer stops here
            if n_modes is not None:
                raise PickError("picks and n_modes do not mix: pick the modes, or give their number, not both.")
            picked = picked_modes(diagram, check_picks(picks, band, diagram.recording.fs), band, nas, clustering)
        modes, vectors = _automatic(diagram, band, nas, min_support, clustering, merge_mac, n_modes, n_jobs, bar)
        if modes.empty and picks is not None:  # no automatic mode: the picks stand alone
            modes, vectors = picked
        if modes.empty:  # a result, not a stop: the diagram, its poles and why each cluster failed
            why = why_no_mode(diagram, band, nas, min_support, cluster_freq, cluster_damping)
            return _no_mode_selection(diagram, why)
        work = WorkingSelection(modes, np.column_stack(vectors))
        limits = (cluster_freq, cluster_damping, merge_mac)
        orders = {o.na: o for o in diagram.orders}
        work = replace(work, modes=_armax_intervals(work.modes))
        fitted = refit_and_segment_fits(diagram, work.modes, band, refine, segments, orders, n_jobs, bar)
        refit_notes = []
        if refine:
            refit = fitted.pop("refit")
            work = refined_modes(diagram, work, refit, *limits)
            refit_notes = refit.notes() if isinstance(refit, RefitFailure) else []
        if n_modes is None:
            work = _by_the_check(diagram, work, band, nas, clustering, limits, refine)
            if work.refinement is not None and len(work.modes):
                # the last word on the number of modes: nested tests of the modal model with every pole free
                hold, band_hz = work.refinement.hold, work.refinement.band_hz
                work = counted_modes(diagram, work, band_hz, hold, nas, clustering, band, n_jobs=n_jobs)
                bar.update(work.count.trials)
            if picks is not None:
                work = _with_picks(diagram, work, picked, nas, clustering, band, n_jobs)
            work = work.warned(*_not_separated(work.modes))
        if picks is None or work.check is None:
            f, x = work.modes.freq_hz, work.modes.damping
            if work.check_poles:  # two poles reported as one: the check fits the model's poles
                f, x = zip(*work.check_poles, strict=True)
            work = replace(work, check=check_modes(diagram.recording, np.array(f), np.array(x), band))
        work = confirmed_where_incoherent(diagram, work)
        if segments >= 2:
            modes = work.modes
            spread = segment_spread(diagram.recording, modes, lambda i: orders[int(modes.at[i, "na"])], segments,
                                    n_jobs, fitted)  # fmt: skip
            modes, spread_notes = apply_segment_spread(modes, spread, segments)
            work = replace(work, modes=modes).warned(*spread_notes)
        return _finished(diagram, work.warned(*refit_notes), band, cluster_freq, len(nas))


def _with_picks(diagram, work: WorkingSelection, picked, nas, clustering, band, n_jobs=None) -> WorkingSelection:
    """The picks as the modes reported. A pick is the automatic mode within
    ``armaxmodal.modes.picks.PICK_REACH`` of it or of its cluster; a pick no automatic mode
    answers is added from its cluster. The modal model is then fitted with every mode and pole
    of the automatic one kept as it stands, so that the modes not picked do not bias the picked
    ones (:func:`~armaxmodal.modes.counted.counted_modes` with ``picks``)."""
    rows, vectors = picked
    modes = work.modes.assign(picked_hz=np.nan)
    forced = []
    for k, row in rows.iterrows():
        near = [np.min(np.abs(np.log(modes.freq_hz.to_numpy() / f))) for f in (row.picked_hz, row.freq_hz)]
        at = [int(np.argmin(np.abs(np.log(modes.freq_hz.to_numpy() / f)))) for f in (row.picked_hz, row.freq_hz)]
        best = int(np.argmin(near))
        if near[best] <= PICK_REACH and not np.isfinite(modes.at[at[best], "picked_hz"]):
            modes.at[at[best], "picked_hz"] = row.picked_hz
        else:
            forced.append(k)
    extra = _armax_intervals(rows.loc[forced])
    modes = pd.concat([modes, extra], ignore_index=True)
    shapes = np.column_stack([work.shapes, *[vectors[k] for k in forced]]) if forced else work.shapes
    work = work.with_modes(modes, shapes)
    if work.refinement is None:  # no modal model to fit them with: the picks as the diagram has them
        return work.kept(np.flatnonzero(np.isfinite(modes.picked_hz.to_numpy())))
    hold, band_hz = work.refinement.hold, work.refinement.band_hz
    return counted_modes(diagram, work, band_hz, hold, nas, clustering, band, picked=True, n_jobs=n_jobs)


def _automatic(diagram, band, nas, min_support, clustering, merge_mac, n_modes, n_jobs, bar):
    """The supported clusters, split modes merged, the ``n_modes`` best supported when given:
    ``(modes by frequency, shape vectors)``."""
    modes, vectors = clustered_modes(diagram, band, nas, min_support, *clustering, n_jobs, bar)
    if modes.empty:
        return modes, vectors
    keep = merge_duplicates(modes, vectors, merge_mac, diagram.recording.duration)
    modes, vectors = modes.loc[keep].reset_index(drop=True), [vectors[i] for i in keep]
    order = modes.sort_values(["support", "count", "energy"], ascending=False).index
    if n_modes is not None:
        order = order[:n_modes]
    order = modes.loc[order].sort_values("freq_hz").index
    return modes.loc[order].reset_index(drop=True), [vectors[i] for i in order]


def _filled_samples_scale(recording, preparation) -> tuple[float, list[QualityWarning]]:
    """The factor every interval is widened by for samples the reader filled in (``gap_filled``,
    ``dropped_packet``): an interpolated sample carries no information, so a record of ``N``
    samples with ``k`` filled holds ``N - k`` observations, and a standard deviation the fit
    computed from ``N`` is too small by ``sqrt(N / (N - k))``. Counted in the record's own
    samples, before any resampling. Returns ``(factor, notes)``; 1 and none without filled samples."""
    filled = sum(w.value or 0.0 for w in recording.meta.get("read_warnings", ())
                 if w.code in ("gap_filled", "dropped_packet"))  # fmt: skip
    if not filled:
        return 1.0, []
    # gap_filled counts one channel's samples; a filled sample of any channel is lost to the fit
    n = recording.duration * (recording.fs if preparation is None else preparation.original_fs)
    factor = float(np.sqrt(n / max(n - filled, 1.0)))
    note = QualityWarning(
        "gap_filled", (),
        f"{filled:g} filled sample(s) carry no information: every interval is widened by {factor:.6f} "
        f"(sqrt(N / (N - filled)), N = {n:.0f})", factor,
    )  # fmt: skip
    return factor, [note]


def _armax_intervals(modes: pd.DataFrame) -> pd.DataFrame:
    """The ARMAX fit's standard deviations kept beside the reported ones: the segment refits are
    ARMAX fits, and their spread is judged against these even where another estimator is reported."""
    return modes.assign(estimator="armax", freq_sd_armax=modes.freq_sd, damping_sd_armax=modes.damping_sd)


def _by_the_check(diagram, work: WorkingSelection, band, nas, clustering, limits, refine: bool) -> WorkingSelection:
    """The modal-model check drops the modes the record does not need and adds left-out clusters
    it needs; after an addition, a mode the added ones make redundant goes (a merge of two), and
    the refit is made again of all of them."""
    recording, n_before = diagram.recording, len(work.modes)
    work = modes_the_check_adds(diagram, modes_the_record_needs(recording, work, band), band, nas, clustering)
    if len(work.modes) > n_before:
        work = modes_the_record_needs(recording, work, band)
    if refine and len(work.modes) > n_before:  # the refit saw fewer modes than are reported
        work = refit_with_added(diagram, work, band, limits)
    return work


def _finished(diagram, work: WorkingSelection, band, cluster_freq: float, n_orders: int) -> ModeSelection:
    """The selection with its per-sensor tables and the notes read off the final modes."""
    from armaxmodal.modes.frf_check import unexplained_peaks

    scale, widened = _filled_samples_scale(diagram.recording, diagram.preparation)
    modes = with_intervals(work.modes, scale)  # the intervals' parts combined, once
    work = replace(work, modes=modes).warned(*(widened if len(modes) else ()))
    shapes = work.shapes
    per_sensor, weighted = per_sensor_table(diagram, modes, shapes, cluster_freq)
    freq, damping = modes.freq_hz.to_numpy(), modes.damping.to_numpy()
    # a peak a mode of the model explains is explained, picked or not (the check's poles are the model's)
    explaining = (freq, damping)
    if "picked_hz" in modes or work.check_poles is not None:
        poles = work.check.poles
        explaining = (np.abs(poles) / (2 * np.pi), -poles.real / np.abs(poles))
    peaks = unexplained_peaks(diagram.recording, *explaining, band)
    work = work.warned(
        *peaks,
        *dropped_where_peaks_remain(work.count, peaks),
        *oversampling_note(freq, diagram.recording.fs),
        *_unresolved_damping_notes(modes, n_orders),
        *work.check.warnings(),
    )
    return ModeSelection(modes, shapes, per_sensor, weighted, diagram, work.refinement, work.warnings, work.check,
                         work.count)  # fmt: skip


def verdict(check, n_modes: int, uncertain_because: list[str] = ()) -> str:
    """The closing line: whether the modes explain the record, and whether the record decides them
    (``uncertain_because``: the codes of the warnings that leave it undecided)."""
    if n_modes == 0:
        return "quality: POOR -- no stable mode found: the no_modes note says why each cluster was rejected"
    if check is not None and check.passed and uncertain_because:
        return (
            f"quality: UNCERTAIN -- the {n_modes} selected mode(s) explain the measured FRF, but the record does not "
            f"settle them: {', '.join(uncertain_because)} (see the notes)"
        )
    if check is not None and check.passed:
        return f"quality: good -- the {n_modes} selected mode(s) explain the measured FRF of every checked output"
    if check is not None and check.unconfirmed_hz and not check.failing:
        where = ", ".join(f"{f:.2f}" for f in check.unconfirmed_hz)
        return f"quality: POOR -- the record does not confirm the mode(s) at {where} Hz (no coherent H1 there)"
    if check is None or not check.failing:
        return "quality: POOR -- no output has coherent lines to check the modes against: treat them as unconfirmed"
    worst = float(np.nanmax(check.model_error))
    return (
        f"quality: POOR -- the selected modes do not explain the measured FRF of {', '.join(check.failing)} "
        f"(model error up to {100 * worst:.0f} %): treat them as unconfirmed (see the warning)"
    )


#: the columns of an empty selection (what the command line and the JSON read of a mode)
_MODE_COLUMNS = ("freq_hz", "damping", "damped_freq_hz", "freq_ci95_lo", "freq_ci95_hi", "damping_ci95_lo",
                 "damping_ci95_hi", "na", "count", "support", "freq_spread", "damping_spread", "estimator")  # fmt: skip


def _no_mode_selection(diagram: StabilisationDiagram, why: str) -> ModeSelection:
    """The selection of a diagram with no stable mode: no modes, quality ``poor``, and a
    ``no_modes`` note that says why every cluster was rejected and what to do."""
    note = QualityWarning(
        "no_modes", (), f"{why}. Widen the band, extend the order range, or check that the input excites the structure."
    )
    empty = pd.DataFrame(columns=list(_MODE_COLUMNS))
    per_sensor = pd.DataFrame(columns=["sensor", "mode", "own_modal_constant"])
    shapes = np.zeros((len(diagram.recording.sensors), 0), dtype=complex)
    return ModeSelection(empty, shapes, per_sensor, pd.DataFrame(columns=["mode"]), diagram, None, (note,), None)


def _not_separated(modes: pd.DataFrame) -> list[QualityWarning]:
    """A ``modes_not_separated`` note for each pair of neighbouring modes whose frequencies
    differ by less than :data:`~armaxmodal.modes.counted.SEPARATION_SD` standard deviations of
    the difference and that the count did not report as one (picks, or modes the count left)."""
    f = modes.freq_hz.to_numpy()
    return [QualityWarning(
        "modes_not_separated", (),
        f"modes at {f[i]:.3f} and {f[j]:.3f} Hz are {gap:.1f} standard deviations of their difference apart (under "
        f"{SEPARATION_SD:g}): the record does not separate them; they may be one mode", float(f[i]),
    ) for i, j, gap in not_separated(with_intervals(modes))]  # fmt: skip


def _unresolved_damping_notes(modes: pd.DataFrame, n_orders: int) -> list[QualityWarning]:
    """A ``damping_unresolved`` note for every mode whose damping interval reaches zero or
    whose damping estimate is not positive at some orders of the sweep, with the reason."""
    notes = []
    for m in modes.itertuples(index=False):
        crossed = int(m.orders_damping_unresolved)
        if crossed == 0 and m.damping_ci95_lo > 0:
            continue
        facts = [f"damping {m.damping:.2g}, 95 % interval [{m.damping_ci95_lo:.2g}, {m.damping_ci95_hi:.2g}]"]
        if crossed:
            facts.append(f"its estimate is not positive at {crossed} of {n_orders} orders")
        if getattr(m, "model_error_dominates", False):
            why = ("the interval is the spread of the record's thirds (model_error_dominates): the thirds disagree "
                   "about this damping; run 'armaxmodal diagnose'")  # fmt: skip
        else:
            why = "the damping is below what this record resolves: a longer record, or more excitation here, narrows it"
        notes.append(QualityWarning(
            "damping_unresolved", (),
            f"mode at {m.freq_hz:.3f} Hz ([{m.freq_ci95_lo:.4g}, {m.freq_ci95_hi:.4g}] Hz): {'; '.join(facts)}. {why}",
            float(m.freq_hz),
        ))  # fmt: skip
    return notes


def _finite_or_none(value) -> float | None:
    return float(value) if np.isfinite(value) else None
