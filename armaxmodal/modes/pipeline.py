"""Automatic mode selection from a stabilisation diagram (thesis Section 3.4), as named stages.

``select_modes`` runs one tuple of stages over one frozen
``SelectionState`` (:mod:`armaxmodal.modes.state`); every stage is ``stage(state, context) -> state``
and reads what does not change (the diagram, the band, the orders, the settings) from one
``SelectionContext``. Which tuple runs is the only choice the
arguments make, and each is named:

* ``AUTOMATIC`` -- the diagram's stable clusters are the candidates; the measured FRF
  screens them and proposes more; the maximum-likelihood modal model counts them;
* ``FIXED_COUNT`` -- ``n_modes`` given: the best-supported clusters, checked, not counted;
* ``PICKED`` -- ``picks`` given: the picked clusters, reported from the counted model;
* the same three without the frequency-domain refit (``refine=False``), which also leaves the
  count out, since the modal model is fitted under the hold the refit chose.

A stage that finds nothing to select sets the state's ``result`` and the pipeline ends there.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

import numpy as np
import pandas as pd

from armaxmodal._threads import one_blas_thread
from armaxmodal.exceptions import PickError
from armaxmodal.modes.clusters import check_picks, clustered_modes, merge_duplicates, picked_modes, why_no_mode
from armaxmodal.modes.counted import confirmed_where_incoherent, counted_modes
from armaxmodal.modes.diagram import StabilisationDiagram
from armaxmodal.modes.frf import modes_at_unexplained_peaks, modes_the_record_needs
from armaxmodal.modes.intervals import N_SEGMENTS, apply_segment_spread, segment_spread, with_intervals
from armaxmodal.modes.modal_check import check_modes
from armaxmodal.modes.notes import dropped_where_peaks_remain, not_separated_notes, unresolved_damping_notes
from armaxmodal.modes.result import ModeSelection, filled_samples_scale, no_mode_selection, per_sensor_table
from armaxmodal.modes.settings import DEFAULTS, SelectionSettings
from armaxmodal.modes.state import (
    Fitters,
    RefitFailure,
    SelectionContext,
    SelectionState,
    refined_modes,
    refit_and_segment_fits,
)
from armaxmodal.prepare.resample import oversampling_note

__all__ = ["AUTOMATIC", "FIXED_COUNT", "PICKED", "Stage", "select_modes", "stages_for"]

Stage = Callable[[SelectionState, SelectionContext], SelectionState]


# -- the stages ----------------------------------------------------------------------------------
def take_picks(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """Each pick takes its cluster of the diagram now, before any fit: a pick the diagram does not
    offer stops the run here (:class:`~armaxmodal.exceptions.PickError`)."""
    rows, vectors = picked_modes(ctx.diagram, ctx.picks, ctx.band, ctx.nas, ctx.settings.cluster)
    return replace(state, picked=(_armax_intervals(rows), vectors))


def candidates(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """The diagram's clusters that hold poles of ``min_support`` of the orders (and the rescued
    lightly damped ones), each from its lowest-BIC fit finished to convergence. With none, the
    picks stand alone; with no pick either, the selection ends with a ``no_modes`` note."""
    c = ctx.settings.cluster
    modes, vectors = clustered_modes(ctx.diagram, ctx.band, ctx.nas, c, ctx.n_jobs, ctx.bar)
    if modes.empty and state.picked is not None:
        modes, vectors = state.picked
    if modes.empty:  # a result, not a stop: the diagram, its poles and why each cluster failed
        why = why_no_mode(ctx.diagram, ctx.band, ctx.nas, c)
        return replace(state, result=no_mode_selection(ctx.diagram, why, ctx.settings))
    return state.with_modes(_armax_intervals(modes), np.column_stack(vectors))


def merge(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """Two candidates closer than the half-power band whose shapes agree (``merge_mac``) are one
    mode split by over-modelling: the weaker goes. The rest by frequency."""
    modes = state.modes
    keep = merge_duplicates(modes, list(state.shapes.T), ctx.settings.cluster.merge_mac, ctx.diagram.recording.duration)
    state = state.kept(keep)
    return state.kept(state.modes.sort_values("freq_hz").index)


def best_n(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """The ``n_modes`` best-supported candidates (support, then orders, then residue energy), by frequency."""
    ranked = state.modes.sort_values(["support", "count", "energy"], ascending=False).index[: ctx.n_modes]
    state = state.kept(ranked)
    return state.kept(state.modes.sort_values("freq_hz").index)


def refit(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """The frequency-domain refit under the inter-sample behaviour the data choose
    (:func:`armaxmodal.modes.state.refine_modes`), reported for a band-limited record, with the segment refits
    of every mode's representative orders run beside it over the worker threads."""
    fitted = refit_and_segment_fits(
        ctx.diagram,
        state.modes,
        ctx.band,
        True,
        ctx.segments,
        ctx.orders,
        ctx.n_jobs,
        ctx.bar,
        ctx.settings,
        ctx.fitters,
    )
    done = fitted.pop("refit")
    c = ctx.settings.cluster
    state = refined_modes(replace(state, segment_fits=fitted), done, c.freq, c.damping)
    return state.warned(*done.notes()) if isinstance(done, RefitFailure) else state


def segment_fits(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """The segment refits of every mode's representative orders alone (no frequency-domain refit)."""
    fitted = refit_and_segment_fits(
        ctx.diagram, state.modes, ctx.band, False, ctx.segments, ctx.orders, ctx.n_jobs, ctx.bar
    )
    return replace(state, segment_fits=fitted)


def screen_by_frf(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """Without a count: a mode the H1's LSFD check does not need goes, with its note
    (:func:`~armaxmodal.modes.frf.modes_the_record_needs`)."""
    return modes_the_record_needs(ctx.diagram.recording, state, ctx.band, ctx.settings)


def propose_by_frf(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """The measured H1 proposes, the count decides. A candidate its LSFD check does not need leaves
    the count's start and is offered to it as an addition (``doubts``; its ``mode_not_needed`` note
    stands only where the count does not take it back), and so is the diagram's cluster at each
    clear, coherent H1 peak no candidate explains (``proposals``)."""
    # the peaks are judged against every candidate: a doubted one's peak is offered once, as its doubt
    proposals = modes_at_unexplained_peaks(ctx.diagram, state.modes, ctx.band, ctx.nas, ctx.settings.cluster)
    doubts: list = []
    state = modes_the_record_needs(ctx.diagram.recording, state, ctx.band, ctx.settings, doubts)
    return replace(state, doubts=tuple(doubts), proposals=tuple(proposals))


def count(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """The last word on the number of modes: nested tests of the maximum-likelihood modal model with
    every pole free (:mod:`armaxmodal.modes.counted`). It needs the refit's hold and band: where the
    refit could not be made, its ``refit_failed`` note says the modes are not counted."""
    if state.refinement is None or not len(state.modes):  # nothing counts the doubts: the check's word stands
        return replace(state, doubts=()).warned(*(note for _, _, note in state.doubts)) if state.doubts else state
    hold, band_hz = state.refinement.hold, state.refinement.band_hz
    state = counted_modes(
        ctx.diagram, state, band_hz, hold, ctx.nas, ctx.settings, ctx.band, n_jobs=ctx.n_jobs, counter=ctx.fitters.count
    )
    ctx.update_bar(state.count.trials)
    return state


def add_picks(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """The picks as the modes reported: a pick is the automatic mode within the clustering's reach
    of it or of its cluster; a pick no automatic mode answers is added from its cluster. The modal
    model is then fitted with every mode and pole of the automatic one kept as it stands, so that
    the modes not picked do not bias the picked ones."""
    rows, vectors = state.picked
    modes = state.modes.assign(picked_hz=np.nan)
    reach, forced = ctx.settings.cluster.pick_reach, []
    for k, row in rows.iterrows():
        distance = [np.abs(np.log(modes.freq_hz.to_numpy() / f)) for f in (row.picked_hz, row.freq_hz)]
        best = int(np.argmin([np.min(d) for d in distance]))
        at = int(np.argmin(distance[best]))
        if distance[best][at] <= reach and not np.isfinite(modes.at[at, "picked_hz"]):
            modes.at[at, "picked_hz"] = row.picked_hz
        else:
            forced.append(k)
    modes = pd.concat([modes, rows.loc[forced]], ignore_index=True)
    shapes = np.column_stack([state.shapes, *[vectors[k] for k in forced]]) if forced else state.shapes
    state = state.with_modes(modes, shapes)
    if state.refinement is None:  # no modal model to fit them with: the picks as the diagram has them
        return state.kept(np.flatnonzero(np.isfinite(modes.picked_hz.to_numpy())))
    hold, band_hz = state.refinement.hold, state.refinement.band_hz
    return counted_modes(
        ctx.diagram, state, band_hz, hold, ctx.nas, ctx.settings, ctx.band, picked=True, n_jobs=ctx.n_jobs
    )


def separate(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """A ``modes_not_separated`` note for each neighbouring pair the record does not separate and
    that the count did not report as one: after ``spread``, so that the intervals judged are the
    reported ones, every widening included."""
    return state.warned(*not_separated_notes(state.modes))


def check(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """The modal-model check of the modes (:mod:`armaxmodal.modes.modal_check`): the LSFD fit of every
    output's H1 by the selected poles, or by the model's where they are not the rows' (``check_poles``:
    its two poles where one row reports a pair; with picks, the picks and the modes not picked). A mode
    no coherent H1 line is near, which the check cannot test, is confirmed where the counted modal
    model needs it decisively and alike in both halves of the record (``confirmed_where_incoherent``):
    the check's result is made here, once, from both."""
    f, x = state.modes.freq_hz, state.modes.damping
    if state.check_poles:
        f, x = zip(*state.check_poles, strict=True)
    checked = check_modes(ctx.diagram.recording, np.array(f), np.array(x), ctx.band, settings=ctx.settings.frf)
    confirmed, notes = confirmed_where_incoherent(state, checked.unconfirmed_hz, ctx.settings)
    if confirmed:
        checked = replace(checked, unconfirmed_hz=tuple(f for f in checked.unconfirmed_hz if f not in confirmed))
    return replace(state, check=checked).warned(*notes)


def spread(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """Each mode's spread over disjoint segments of the record widens its intervals where it exceeds
    them (``segment_spread`` in :mod:`armaxmodal.modes.intervals`), from the segment refits the refit stage ran."""
    if ctx.segments < 2:
        return state
    modes, orders = state.modes, ctx.orders
    limits = ctx.settings.agreement
    table = segment_spread(
        ctx.diagram.recording,
        modes,
        lambda i: orders[int(modes.at[i, "na"])],
        ctx.segments,
        ctx.n_jobs,
        state.segment_fits,
        ctx.settings.cluster.freq,
    )
    modes, notes = apply_segment_spread(modes, table, ctx.segments, limits.alpha)
    return replace(state, modes=modes).warned(*notes)


def finish(state: SelectionState, ctx: SelectionContext) -> SelectionState:
    """The intervals' parts combined, once; the per-sensor tables; the notes read off the final modes."""
    from armaxmodal.modes.frf import undriven_resonances, unexplained_peaks

    diagram, notes = ctx.diagram, ctx.settings.notes
    scale, widened = filled_samples_scale(diagram.recording, diagram.preparation)
    modes = with_intervals(state.modes, scale)
    state = replace(state, modes=modes).warned(*(widened if len(modes) else ()))
    per_sensor, weighted = per_sensor_table(diagram, modes, state.shapes, ctx.settings.cluster.freq)
    freq, damping = modes.freq_hz.to_numpy(), modes.damping.to_numpy()
    # a peak a mode of the model explains is explained, picked or not (the check's poles are the model's)
    explaining = (freq, damping)
    if ctx.picks is not None or state.check_poles is not None:
        poles = state.check.poles
        explaining = (np.abs(poles) / (2 * np.pi), -poles.real / np.abs(poles))
    peaks = unexplained_peaks(diagram.recording, *explaining, ctx.band)
    state = state.warned(
        *peaks,
        *undriven_resonances(diagram, explaining[0], ctx.band, ctx.nas, ctx.settings.cluster),
        *dropped_where_peaks_remain(state.count, peaks, ctx.settings.cluster.same_row_freq),
        *oversampling_note(freq, diagram.recording.fs, notes.oversampled_fraction, notes.suggested_band_factor),
        *unresolved_damping_notes(modes, len(ctx.nas)),
        *state.check.warnings(),
    )
    picks = None if ctx.picks is None else sorted(float(f) for f in ctx.picks)
    result = ModeSelection(
        modes,
        state.shapes,
        per_sensor,
        weighted,
        diagram,
        state.refinement,
        state.warnings,
        state.check,
        state.count,
        ctx.settings,
        picks,
        state.counted,
        ctx.segments,
    )
    return replace(state, result=result)


# -- the stage lists -----------------------------------------------------------------------------
#: the diagram's candidates, with those the FRF proposes, counted by the modal model
AUTOMATIC: tuple[Stage, ...] = (candidates, merge, refit, propose_by_frf, count, check, spread, separate, finish)
#: ``n_modes`` given: the best-supported candidates, refitted and checked; nothing dropped or added
FIXED_COUNT: tuple[Stage, ...] = (candidates, merge, best_n, refit, check, spread, separate, finish)
#: ``picks`` given: the picked clusters reported from the model the automatic selection counted
PICKED: tuple[Stage, ...] = (
    take_picks,
    candidates,
    merge,
    refit,
    propose_by_frf,
    count,
    add_picks,
    check,
    spread,
    separate,
    finish,
)


def stages_for(n_modes: int | None, picks, refine: bool) -> tuple[Stage, ...]:
    """The stage list of a call: :data:`AUTOMATIC`, :data:`FIXED_COUNT` or :data:`PICKED`; without
    the refit (``refine=False``) the same with ``segment_fits`` for ``refit`` and no ``count`` (the
    modal model is fitted under the hold the refit chooses), and so ``screen_by_frf``, whose drops
    stand, for ``propose_by_frf``, whose drops and proposals the count judges."""
    if picks is not None and n_modes is not None:
        raise PickError("picks and n_modes do not mix: pick the modes, or give their number, not both.")
    stages = PICKED if picks is not None else FIXED_COUNT if n_modes is not None else AUTOMATIC
    if refine:
        return stages
    swap = {refit: segment_fits, propose_by_frf: screen_by_frf}
    return tuple(swap.get(s, s) for s in stages if s is not count)


# -- the entry point -----------------------------------------------------------------------------
def select_modes(
    diagram: StabilisationDiagram,
    n_modes: int | None = None,
    band: tuple[float, float] | None = None,
    *,
    settings: SelectionSettings | None = None,
    refine: bool = True,
    segments: int = N_SEGMENTS,
    n_jobs: int | None = None,
    progress: bool = False,
    picks=None,
    on_stage: Callable[[str], None] | None = None,
    fitters: Fitters | None = None,
) -> ModeSelection:
    """Pick the physical modes from the shared-pole poles of a diagram.

    What decides which modes are reported:

    1. **candidates** -- the diagram's poles are clustered across orders (greedy, by increasing
       ``na``: a pole joins the nearest cluster within ``settings.cluster.freq`` relative frequency
       and ``settings.cluster.damping`` relative damping that has no pole of its order yet); a
       cluster holding poles of ``settings.cluster.min_support`` of the orders is a candidate,
       reported from its lowest-BIC fit. Two candidates closer than their half-power band whose
       shapes agree (MAC at least ``settings.cluster.merge_mac``) are one mode split (**merge**).
    2. **refit** -- the candidates are refitted to the recording's DFT under the inter-sample
       behaviour the data choose (band-limited or held).
    3. **propose_by_frf** -- the measured H1 proposes: a candidate its LSFD check does not need
       leaves the count's start, and the diagram's cluster at a clear, coherent H1 peak no
       candidate explains comes in, both offered to the count as additions.
    4. **count** -- the one keep-or-drop: the maximum-likelihood modal model with every pole free
       decides the number of modes by nested tests (BIC on the effective lines; an addition's new
       poles the same in both halves and stable across orders): it removes, adds or splits modes,
       and says where the record does not decide (``count_undecided``).
    5. **check**, **spread**, **separate**, **finish** -- the modal-model check (where no coherent
       H1 line is near a mode, the counted model may confirm it), the intervals widened by the
       segments' spread and the other structures and estimators, a ``modes_not_separated`` note
       (and so ``uncertain``) for neighbours the reported intervals do not separate, and the verdict.

    ``n_modes``, ``picks`` and ``refine=False`` run other named stage lists (``stages_for``).

    Parameters
    ----------
    diagram : StabilisationDiagram
    n_modes : int, optional
        Keep the ``n_modes`` best-supported modes (the modal-model check then judges them but
        neither drops nor adds any, and they are not counted).
    band : (lo, hi), optional
        Frequency band in Hz (default: the diagram's band, if it was given one).
    settings : SelectionSettings, optional
        Every threshold of the stages (:mod:`armaxmodal.modes.settings`); the result carries it.
    refine : bool
        Refit the selected modes to the recording's DFT (and count them by the modal model).
    segments : int
        Refit each mode's representative orders on this many disjoint segments and widen
        the intervals where their spread exceeds them (:mod:`armaxmodal.modes.intervals`); 0 skips.
    n_jobs : int, optional
        Worker threads for the finishing and segment fits (default: all cores; 1 inside a
        worker that has one core already, e.g. a study's).
    progress : bool
        Show a count of the fits the selection runs, labelled with the stage.
    picks : sequence of float, optional
        Frequencies (Hz) picked by hand: each takes the nearest cluster of the diagram holding
        poles of at least ``settings.cluster.min_orders`` orders within the clustering's reach (a
        :class:`~armaxmodal.exceptions.PickError` says when none does). The picks are refitted,
        checked and judged as automatic modes are, but none is dropped or added: a pick the
        record does not need is said to be (``pick_not_supported``). Not with ``n_modes``.
    on_stage : callable, optional
        Called with each stage's name as it is entered.
    fitters : Fitters, optional
        The refit and the count the stages run (default: the package's; a test hands in others).

    Returns
    -------
    ModeSelection
        The modes with their intervals and shapes, the modal-model check, the count's
        evidence, the settings and the verdict.

    See Also
    --------
    armaxmodal.stabilisation_diagram : the sweep this selects from.
    armaxmodal.modes.settings.SelectionSettings : the thresholds.

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
    >>> round(100 * float(np.max(np.abs(selection.modes.freq_hz / exact - 1))))  # the largest error, % (0.3-0.4)
    0
    """
    from tqdm import tqdm

    settings = DEFAULTS if settings is None else settings
    if not isinstance(settings, SelectionSettings):
        raise TypeError(f"settings: expected a SelectionSettings, got {type(settings).__name__}.")
    stages = stages_for(n_modes, picks, refine)
    if band is None and diagram.preparation is not None:
        band = diagram.preparation.band
    checked = None if picks is None else check_picks(picks, band, diagram.recording.fs, settings.cluster)
    with one_blas_thread(), tqdm(desc="mode selection", unit="fit", disable=not progress) as bar:
        ctx = SelectionContext(
            diagram,
            settings,
            band,
            sorted({o.na for o in diagram.orders}),
            n_modes,
            checked,
            segments,
            refine,
            n_jobs,
            bar,
            on_stage,
            fitters or Fitters(),
        )
        return run_stages(stages, SelectionState.empty(len(diagram.recording.sensors)), ctx)


def run_stages(stages: tuple[Stage, ...], state: SelectionState, ctx: SelectionContext) -> ModeSelection:
    """Run ``stages`` in order until one sets the result."""
    for stage in stages:
        if ctx.on_stage is not None:
            ctx.on_stage(stage.__name__)
        if ctx.bar is not None:
            ctx.bar.set_postfix_str(stage.__name__, refresh=False)
        state = stage(state, ctx)
        if state.result is not None:
            return state.result
    raise RuntimeError("the stage list ends without a result: its last stage must be 'finish'")


def _armax_intervals(modes: pd.DataFrame) -> pd.DataFrame:
    """The ARMAX fit's standard deviations kept beside the reported ones: the segment refits are
    ARMAX fits, and their spread is judged against these even where another estimator is reported."""
    return modes.assign(estimator="armax", freq_sd_armax=modes.freq_sd, damping_sd_armax=modes.damping_sd)
