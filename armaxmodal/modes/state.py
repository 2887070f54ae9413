"""The selection as it goes, and what every stage reads: ``SelectionState``, the one frozen
object each stage of ``select_modes`` takes and returns, and
``SelectionContext``, the diagram, band, orders and settings that stay the same from stage to
stage (:mod:`armaxmodal.modes.pipeline` names the stages).

Then the fits run for the selected modes: the frequency-domain refit
(:func:`refine_modes`, which chooses the inter-sample form the data want) and the segment refits
(``segment_spread`` in :mod:`armaxmodal.modes.intervals`), run together over the worker threads, and the
refit's values applied within their limits (``refit_and_segment_fits``, ``refined_modes``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from functools import partial
from typing import TYPE_CHECKING, Any

import numpy as np
import pandas as pd

from armaxmodal._threads import single_blas_thread
from armaxmodal.estimate.dft_model import HOLDS, DftLines, ModalModel, fit_modal_model
from armaxmodal.estimate.pool import parallel_map
from armaxmodal.exceptions import OrderError
from armaxmodal.modes.count_search import count_modes
from armaxmodal.modes.intervals import segment_jobs, segment_poles
from armaxmodal.modes.settings import DEFAULTS, DftSettings, SelectionSettings
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording
from armaxmodal.spectra import excited_band

if TYPE_CHECKING:  # types only: the stages that make them import this module
    from armaxmodal.modes.diagram import StabilisationDiagram
    from armaxmodal.modes.modal_check import ModalCheck
    from armaxmodal.modes.mode_count import ModeCount
    from armaxmodal.modes.result import ModeSelection

__all__ = ["Fitters", "SelectionContext", "SelectionState", "refine_modes"]


@dataclass(frozen=True)
class SelectionState:
    """The modes selected so far and what the stages found about them.

    Attributes
    ----------
    modes : DataFrame
        One row per mode, by frequency: the columns of :attr:`armaxmodal.ModeSelection.modes`
        but the 95 % intervals, which are kept as their parts until the selection ends
        (:mod:`armaxmodal.modes.intervals`).
    shapes : (n_sensors, n_modes) complex ndarray
        The modal constants, one column per row of ``modes``.
    refinement : ModalModel or None
        The frequency-domain refit the values come from, once made.
    check : ModalCheck or None
        The modal-model check of ``modes``, once run (a stage that changes the modes runs it again).
    count : ModeCount or None
        The maximum-likelihood count, once run.
    warnings : tuple of QualityWarning
        What the stages said, in order.
    check_poles : tuple of (float, float) or None
        The poles the check fits, ``(Hz, ratio)``, where they are not the rows': the model's two
        poles of a pair the record does not separate, which one row reports, or with picks the
        picks and the model's modes not picked. None: the rows'.
    picked : (DataFrame, list of ndarray) or None
        The picks' clusters as rows and shape vectors (``picks=``), taken before any fit.
    segment_fits : dict
        The segment refits of the representative orders, ``(orders, k) -> poles``, run beside the
        refit and read by the segment stage.
    doubts : tuple of (float, float, QualityWarning)
        The modes the measured FRF's check does not need, ``(Hz, ratio, note)``: out of the
        selection, offered to the count as candidates; a note stands where the count leaves it out.
    proposals : tuple of (float, float)
        The measured H1's proposals to the count, ``(Hz, ratio)``: the diagram's clusters at its
        unexplained peaks, tried as additions after the doubts.
    counted : bool
        The modes are the count's rows (:attr:`armaxmodal.ModeSelection.counted`).
    count_lines : (DftLines, tuple of DftLines) or None
        The lines the count decided on and those of their two halves, built once by the count
        and read again by the check's confirmation (unweighted).
    result : ModeSelection or None
        The finished selection; a stage that sets it ends the pipeline (a diagram with no mode).
    """

    modes: pd.DataFrame
    shapes: np.ndarray
    refinement: ModalModel | None = None
    check: ModalCheck | None = None
    count: ModeCount | None = None
    warnings: tuple[QualityWarning, ...] = ()
    check_poles: tuple[tuple[float, float], ...] | None = None
    picked: tuple[pd.DataFrame, list] | None = field(default=None, repr=False)
    segment_fits: dict = field(default_factory=dict, repr=False)
    doubts: tuple[tuple[float, float, QualityWarning], ...] = ()
    proposals: tuple[tuple[float, float], ...] = ()
    counted: bool = False
    count_lines: tuple[DftLines, tuple[DftLines, ...]] | None = field(default=None, repr=False)
    result: ModeSelection | None = field(default=None, repr=False)

    def __post_init__(self):
        if self.shapes.shape[1] != len(self.modes):
            raise ValueError(f"{len(self.modes)} modes but {self.shapes.shape[1]} shape columns")

    @classmethod
    def empty(cls, n_sensors: int) -> SelectionState:
        """The state before any stage: no mode."""
        return cls(pd.DataFrame(), np.zeros((n_sensors, 0), dtype=complex))

    def kept(self, rows) -> SelectionState:
        """Only the modes at positions ``rows`` (in that order), renumbered from 0."""
        rows = list(rows)
        return replace(self, modes=self.modes.iloc[rows].reset_index(drop=True), shapes=self.shapes[:, rows])

    def with_modes(self, modes: pd.DataFrame, shapes: np.ndarray, **changes) -> SelectionState:
        """Other modes (and any other attribute by keyword)."""
        return replace(self, modes=modes, shapes=shapes, **changes)

    def warned(self, *warnings: QualityWarning, **changes) -> SelectionState:
        """``warnings`` appended (and any other attribute by keyword)."""
        return replace(self, warnings=self.warnings + tuple(warnings), **changes)


@single_blas_thread
def refine_modes(
    recording: Recording,
    freq_hz,
    damping,
    *,
    band_hz: tuple[float, float],
    hold: str = "auto",
    max_nfev: int = 60,
    settings: DftSettings = DEFAULTS.dft,
    decisive: float = DEFAULTS.count.decisive_bic,
) -> ModalModel:
    """Refit selected modes to the DFT of a recording, choosing the inter-sample behaviour.

    Both assumptions are fitted a few steps from the same start, with the same lines and the same number of
    parameters; the one with the lower weighted residual is the data's choice and is iterated to convergence
    (:mod:`armaxmodal.estimate.dft_model` gives the two forms). Where the few steps leave the two within
    ``decisive``, both are converged and the lower residual there chooses (a five-segment body's held
    ride: band-limited led after four steps, held by far converged, and only it gave the exact
    dampings). Each sensor is weighted by one over its noise level at the start.

    Parameters
    ----------
    recording : Recording
    freq_hz, damping : (n_modes,) array_like
        Starting modes (Hz, ratio), e.g. from :func:`armaxmodal.select_modes`.
    band_hz : (lo, hi)
        Band where the input has power (Hz); only these DFT lines are fitted.
    hold : {"auto", "bandlimited", "zoh"}
        Inter-sample assumption; "auto" fits both and keeps the lower residual.
    max_nfev : int
        Cap on residual evaluations of the chosen assumption's fit.
    settings : DftSettings
        The damping bounds and the stopping tolerance.
    decisive : float
        The difference of weighted residual sums of squares (``-2 ln L`` at unit noise) that the
        first steps must show to decide (the count's ``decisive_bic``).

    Returns
    -------
    ModalModel
        The refit, its modes in the order of ``freq_hz``; ``hold_cost``: each tried assumption's
        weighted residual sum of squares where it was decided (after the first steps, or converged).

    See Also
    --------
    armaxmodal.estimate.dft_model.fit_modal_model : The fitter it runs.

    Examples
    --------
    >>> import armaxmodal as am
    >>> body, exact = am.supine_human(), am.supine_human().modes()  # exact: 5.83, 8.31, 13.50, 16.25 Hz
    >>> ride = am.simulate_recording(body, am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03, seed=2)
    >>> from armaxmodal.modes.state import refine_modes
    >>> model = refine_modes(ride, exact.freq_hz * 1.02, exact.damping, band_hz=(0.5, 28.0))  # from 2 % off
    >>> model.hold, [round(float(f), 1) for f in model.freq_hz]  # the ride was simulated with a held input
    ('zoh', [5.8, 8.3, 13.6, 16.2])
    """
    if hold not in ("auto", *HOLDS):
        raise ValueError(f"hold: expected 'auto', 'bandlimited' or 'zoh', got {hold!r}.")
    data = DftLines.from_recording(recording, band_hz).weighted_at_start(freq_hz, damping, settings)
    fit = partial(fit_modal_model, data, max_nfev=max_nfev, settings=settings, by_frequency=False)
    fits = {
        h: fit(freq_hz, damping, h, **({"max_nfev": 4} if hold == "auto" else {})) for h in HOLDS if hold in (h, "auto")
    }
    cost = {h: float(np.sum(m.rss * data.weights**2)) for h, m in fits.items()}
    leader = min(cost, key=cost.get)
    if hold == "auto":  # a few steps tell the assumptions apart, unless within ``decisive``: then both converge
        close = abs(cost["zoh"] - cost["bandlimited"]) < decisive
        fits = {h: fit(m.freq_hz, m.damping, h) for h, m in fits.items() if close or h == leader}
        if close:  # converged, the lower residual chooses
            cost = {h: float(np.sum(m.rss * data.weights**2)) for h, m in fits.items()}
            leader = min(cost, key=cost.get)
    return replace(fits[leader], hold_cost=cost)


@dataclass(frozen=True)
class Fitters:
    """The selection's two fits, handed to the stages by the context, not imported by them: the
    frequency-domain refit (as :func:`refine_modes`) and the count (as
    :func:`~armaxmodal.modes.count_search.count_modes`). A test hands in one that fails or records."""

    refine: Callable = refine_modes
    count: Callable = count_modes


@dataclass(frozen=True)
class SelectionContext:
    """What every stage reads and none changes.

    Attributes
    ----------
    diagram : StabilisationDiagram
    settings : SelectionSettings
        Every threshold of the selection (:mod:`armaxmodal.modes.settings`).
    band : (float, float) or None
        The user's band (Hz), or the diagram's.
    nas : list of int
        The diagram's orders, sorted.
    n_modes : int or None
        The number of modes asked for (the ``fixed count`` stages).
    picks : (n_picks,) ndarray or None
        The checked picks (Hz).
    segments : int
        Disjoint segments of the segment spread (0: none).
    refine : bool
        Whether the frequency-domain refit is made (the FRF screen refits again after additions).
    n_jobs : int or None
        Worker threads.
    bar : tqdm or None
        The progress bar that counts the selection's fits.
    on_stage : callable or None
        Called with each stage's name as it is entered (the progress bar's label; a test's trace).
    fitters : Fitters
        The refit and the count the stages run.
    """

    diagram: StabilisationDiagram
    settings: SelectionSettings
    band: tuple[float, float] | None
    nas: list[int]
    n_modes: int | None = None
    picks: np.ndarray | None = None
    segments: int = 3
    refine: bool = True
    n_jobs: int | None = None
    bar: Any = field(default=None, repr=False)
    on_stage: Callable[[str], None] | None = field(default=None, repr=False)
    fitters: Fitters = field(default=Fitters(), repr=False)

    @property
    def orders(self) -> dict:
        """``{na: Orders}`` of the diagram."""
        return {o.na: o for o in self.diagram.orders}

    def update_bar(self, n: int) -> None:
        """Count ``n`` fits on the progress bar, if there is one."""
        if self.bar is not None and n:
            self.bar.update(n)


def refit_and_segment_fits(
    diagram,
    modes,
    band,
    refine: bool,
    segments: int,
    orders: dict,
    n_jobs,
    bar=None,
    settings: SelectionSettings = DEFAULTS,
    fitters: Fitters = Fitters(),
) -> dict:
    """The frequency-domain refit (key ``"refit"``) and the segment refits of every mode's
    representative orders (keys ``(orders, k)``), run together over the worker threads:
    the refit ran alone in this process before, while the workers waited. ``bar`` (tqdm)
    counts them; ``fitters.refine`` makes the refit."""
    jobs: list = [("refit", refit_band(diagram.recording, band))] if refine else []
    if segments >= 2:
        jobs += [("segment", job) for job in segment_jobs(sorted({orders[int(na)] for na in modes.na}), segments)]
    parts = diagram.recording.split(segments) if segments >= 2 else []
    task = partial(selection_job, diagram.recording, parts, modes, settings=settings, refine=fitters.refine)
    # the refit first: it is the longest job (a frequency-domain fit of every mode)
    cost = lambda job: np.inf if job[0] == "refit" else job[1][0][0]  # noqa: E731
    done = parallel_map(task, jobs, n_jobs, bar, cost=cost, min_items=2)
    return {("refit" if kind == "refit" else job): result for (kind, job), result in zip(jobs, done, strict=True)}


def refit_band(recording: Recording, band) -> tuple[float, float]:
    """Where the refit fits: the input's excited band, inside the user's band if given (modes
    outside it are not in the refit)."""
    lo, hi = excited_band(recording)
    return (lo, hi) if band is None else (max(lo, band[0]), min(hi, band[1]))


def selection_job(
    recording: Recording,
    parts: list,
    modes: pd.DataFrame,
    job,
    settings: SelectionSettings = DEFAULTS,
    refine: Callable = refine_modes,
    hold: str = "auto",
):
    """One job of :func:`refit_and_segment_fits`: a segment's refit, or the frequency-domain refit by
    ``refine`` under ``hold`` (a :class:`RefitFailure` where it cannot be made)."""
    kind, what = job
    if kind == "segment":
        return segment_poles(parts, what)
    try:
        return refine(
            recording,
            modes.freq_hz,
            modes.damping,
            band_hz=what,
            hold=hold,
            settings=settings.dft,
            decisive=settings.count.decisive_bic,
        )
    except (OrderError, np.linalg.LinAlgError) as exc:
        return RefitFailure(str(exc))  # too few lines or a degenerate basis: the ARMAX values stand, said


@dataclass(frozen=True)
class RefitFailure:
    """The frequency-domain refit could not be made; ``reason`` says why."""

    reason: str

    def notes(self, which: str = "the selected modes", uncounted: bool = True) -> list[QualityWarning]:
        """The note that says so (the ARMAX fit's values, or an earlier refit's, stand)."""
        return [
            QualityWarning(
                "refit_failed",
                (),
                f"the frequency-domain refit of {which} could not be made ({self.reason.rstrip('.')}); "
                "the values reported are the ARMAX fit's or an earlier refit's"
                + (
                    ", and the modes are not counted by the modal model, which is fitted under the inter-sample "
                    "behaviour the refit chooses"
                    if uncounted
                    else ""
                ),
            )
        ]


def refined_modes(work: SelectionState, refinement, cluster_freq, cluster_damping) -> SelectionState:
    """The frequency-domain refit (:func:`refine_modes`, or a
    :class:`RefitFailure` when it could not be made, which leaves the selection without one)
    reported for a band-limited record, and kept as the selection's ``refinement``. Two modes the
    refit brings together stay two: the count judges them (with ``n_modes`` given, the
    ``separate`` stage names them)."""
    if refinement is None or isinstance(refinement, RefitFailure):
        return replace(work, refinement=None)
    work = replace(work, refinement=refinement)
    if refinement.hold == "bandlimited":
        work = work.with_modes(*_apply_refinement(work.modes, work.shapes, refinement, cluster_freq, cluster_damping))
    return work


def _apply_refinement(modes, shapes, ref, max_freq_change, max_damping_change):
    """Report the band-limited refit of each mode unless it left the mode's neighbourhood
    (``max_freq_change`` in frequency, ``max_damping_change`` in damping; then the ARMAX value
    stays and ``estimator`` says so)."""
    modes, shapes = modes.copy(), shapes.copy()
    for i in range(len(modes)):
        df = abs(ref.freq_hz[i] / modes.at[i, "freq_hz"] - 1)
        dx = abs(ref.damping[i] / modes.at[i, "damping"] - 1)
        if df > max_freq_change or dx > max_damping_change:
            modes.at[i, "estimator"] = "armax (refit moved too far)"
            continue
        f, x = ref.freq_hz[i], ref.damping[i]
        modes.loc[i, ["freq_hz", "damping", "damped_freq_hz", "estimator"]] = [
            f,
            x,
            f * np.sqrt(1 - x**2),
            "fd-bandlimited",
        ]
        modes.loc[i, ["freq_sd", "damping_sd"]] = [ref.freq_sd[i], ref.damping_sd[i]]
        shapes[:, i] = ref.shapes[:, i]
    return modes, shapes
