"""The stabilisation diagram: the order sweep (thesis Sections 3.3.2 and 3.4).

The model order is unknown: too low misses modes, too high adds spurious poles. The sweep
fits the shared-pole model (the default source of modes) and every sensor alone for
``na`` over a range, with the documented rules ``nb = na + 1 - nk`` and ``nc = na``, and one
input delay ``nk`` chosen by BIC at a middle order (:func:`~armaxmodal.modes.choose_nk`). Physical poles stay
put as the order grows; :mod:`armaxmodal.modes.poles` classes each one.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property, partial

import pandas as pd

from armaxmodal._threads import one_blas_thread
from armaxmodal.estimate.fit import fit_resumable
from armaxmodal.estimate.orders import Orders, choose_delay, default_nb, default_nc, order_criteria
from armaxmodal.estimate.pool import parallel_map
from armaxmodal.exceptions import OrderError
from armaxmodal.modes.poles import (
    SHARED,
    Tolerances,
    disturbance_lines,
    pole_rows,
    rejection_reasons,
    stability_classes,
)
from armaxmodal.modes.settings import SWEEP
from armaxmodal.prepare.preparation import Preparation, prepare
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording

__all__ = ["stabilisation_diagram", "StabilisationDiagram", "choose_nk"]

# The sweep's numbers, each explained where it is set (:class:`~armaxmodal.modes.settings.SweepSettings`),
# under the names the sweep's code and its tests use
SWEEP_TOL = SWEEP.tol
NK_SEARCH = SWEEP.nk_search
NK_EXTENSION = SWEEP.nk_extension
DELAY_CHOICE_ORDERS = SWEEP.delay_choice_orders
DELAY_CHOICE_ITERATIONS = SWEEP.delay_choice_iterations
SAMPLES_PER_PARAMETER = SWEEP.samples_per_parameter
DEFAULT_ORDERS = SWEEP.default_orders
MIN_DEFAULT_TOP = SWEEP.min_default_top


@dataclass(frozen=True)
class StabilisationDiagram:
    """Poles of every order and source.

    Attributes
    ----------
    poles : DataFrame
        One row per pole: source (``shared`` or a sensor), na, freq_hz, damping,
        damped_freq_hz, freq_sd, damping_sd, energy (residue energy), cls (stability class),
        rejected (reason, empty when kept), pole (complex), vector (complex shape over
        sensors for shared poles; the residue for a sensor's own pole).
    orders : list of Orders
    tolerances : Tolerances
    recording : Recording
        The record the sweep fitted (after :func:`~armaxmodal.prepare.prepare`).
    preparation : Preparation or None
        What was done to the record first, with the quality warnings.

    See Also
    --------
    armaxmodal.stabilisation_diagram : What makes one.
    armaxmodal.select_modes : Picks the physical modes from it.

    Examples
    --------
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> diagram = am.stabilisation_diagram(ride, range(4, 13, 2), per_sensor=False)
    >>> [order.na for order in diagram.orders]
    [4, 6, 8, 10, 12]
    >>> poles = diagram.to_frame()
    >>> int((poles.na == 8).sum())  # the order-8 fit's poles
    4
    """

    poles: pd.DataFrame
    orders: list
    tolerances: Tolerances
    recording: Recording
    fits: dict = field(repr=False, default_factory=dict)
    preparation: Preparation | None = None
    own_warnings: tuple = ()

    @property
    def warnings(self) -> list[QualityWarning]:
        """Data-quality findings of the preparation and of the sweep itself (a copy)."""
        return list(self._warnings)

    @cached_property
    def _warnings(self) -> tuple[QualityWarning, ...]:
        # computed once: the disturbance lines read the record's spectrum, and every read of a
        # selection's quality, verdict or JSON reads these (the diagram is frozen, so they hold)
        found = list(self.preparation.warnings) if self.preparation is not None else []
        found += list(self.own_warnings)
        found += _delay_warnings(self.orders[0].nk, self.recording, max(o.na for o in self.orders))
        return tuple(found + disturbance_lines(self.poles, self.tolerances.min_energy, self.recording, SHARED))

    @cached_property
    def order_bic(self) -> dict[int, float]:
        """``{na: BIC}`` of the sweep's shared fits (``estimate.orders.order_criteria``), once."""
        return order_criteria([fit for (source, _), fit in self.fits.items() if source == SHARED], self.recording)

    def to_frame(self) -> pd.DataFrame:
        """The tidy pole table without the complex columns (for CSV).

        Returns
        -------
        pandas.DataFrame
            One row per pole of every order (the pole CSV): order, frequency, damping, class and
            why a pole was rejected.
        """
        return self.poles.drop(columns=["pole", "vector"])

    def plot(self, selection=None, ax=None):
        from armaxmodal.io.report.diagram_plot import plot_stabilisation

        return plot_stabilisation(self, selection, ax=ax)


def sweep_fit(recording: Recording, job, max_iter: int, tol: float, covariance: bool = True):
    """``(fit, checkpoint)`` of a sweep job ``(source, orders[, checkpoint])``: the shared
    fit continues the checkpoint when there is one; ``(None, None)`` when the record cannot
    support the orders."""
    source, orders = job[:2]
    rec = recording if source == SHARED else recording.select([source])
    extra = job[2] if len(job) > 2 else None
    resume, start = (extra, None) if source == SHARED else (None, extra)
    try:
        return fit_resumable(
            rec,
            orders,
            shared_poles=source == SHARED,
            max_iter=max_iter,
            tol=tol,
            stop="decrease",
            warn=False,
            resume=resume,
            start=start,
            covariance=covariance,
        )
    except OrderError:
        return None, None


def _fit_and_poles(recording: Recording, job, max_iter: int, tol: float):
    """A sweep job run in a worker: the fit and its pole rows (computing the rows there
    keeps the parent's serial share small)."""
    fit = sweep_fit(recording, job, max_iter, tol)[0]
    return fit, ([] if fit is None else pole_rows(fit, job[0]))


def _job_cost(job, n_sensors: int) -> float:
    """Relative run time of a sweep fit: about linear in na and in the number of sensors."""
    source, orders = job[:2]
    return orders[0] * (n_sensors if source == SHARED else 1)


def choose_nk(recording: Recording, nk_values=NK_SEARCH, na_values=DELAY_CHOICE_ORDERS, n_jobs=None) -> int:
    """The input delay of the lowest-BIC shared-pole model over a few middle orders.

    The delay and the order interact (band-limited data trade non-causal taps for poles), so
    they are chosen jointly; one order alone can pick a delay that biases heavily damped modes.

    Parameters
    ----------
    recording : Recording
        The prepared record.
    nk_values : iterable of int
        The delays to try, in samples (negative: non-causal taps).
    na_values : iterable of int
        The orders each delay is fitted at.
    n_jobs : int, optional
        Worker processes (default: all cores).

    Returns
    -------
    int
        The delay, in samples.

    See Also
    --------
    armaxmodal.estimate.information_criterion : The criterion behind the choice.
    armaxmodal.stabilisation_diagram : Chooses the delay this way when none is given.

    Examples
    --------
    >>> import armaxmodal as am
    >>> from armaxmodal.modes import choose_nk
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)  # held between samples: no non-causal tap, by 150 BIC units or more
    >>> choose_nk(ride)
    0
    """
    return _choose_nk(recording, nk_values, na_values, n_jobs, deepest=deepest_delay(recording, max(na_values)))[0]


def _choose_nk(recording, nk_values, na_values, n_jobs, tol=SWEEP_TOL, *, deepest: int, bar=None):
    """``(nk, {(SHARED, orders): checkpoint})``: the delay :func:`~armaxmodal.estimate.orders.choose_delay`
    chooses and where its fits stopped, which the sweep continues instead of fitting those orders
    again. A delay at the most non-causal end of the delays searched is a finding acted on: the search
    goes ``NK_EXTENSION`` further, again while the choice stays at its end, down to ``deepest`` (the
    most non-causal delay at which the record supports the sweep's top order). ``bar`` (tqdm) counts
    the fits; each extension counts its own on a bar of its own, so that no total grows. 8 iterations
    settle the choice where delays differ by tens of BIC units or more (checked on every fixture, a
    lightly damped structure and the real recordings against 20 and 50); where BIC is flatter the cap
    decides between delays the record does not tell apart (docs/performance.md)."""
    nk, known = choose_delay(
        recording, nk_values, na_values, max_iter=DELAY_CHOICE_ITERATIONS, tol=tol, n_jobs=n_jobs, bar=bar
    )
    beyond = range(nk - 1, max(nk - NK_EXTENSION, deepest) - 1, -1)
    if nk == min(nk_values) and len(beyond):
        further = [nk, *beyond]
        from tqdm import tqdm

        with tqdm(
            total=len(further) * len(na_values),
            desc=f"input delay choice beyond nk = {nk}",
            unit="fit",
            disable=bar is None or bar.disable,
        ) as more:
            return _choose_nk(recording, further, na_values, n_jobs, tol, deepest=deepest, bar=more)
    return nk, {(SHARED, orders): checkpoint for orders, checkpoint in known.items()}


def deepest_delay(recording: Recording, top_na: int) -> int:
    """The most non-causal delay (samples) at which one sensor's model of order ``top_na``
    (``3 na + 1 - nk`` parameters) has :data:`SAMPLES_PER_PARAMETER` samples a parameter."""
    return 3 * top_na + 1 - recording.n_samples // SAMPLES_PER_PARAMETER


def stabilisation_diagram(
    recording: Recording,
    orders=None,
    *,
    band: tuple[float, float] | None = None,
    detrend: str = "mean",
    resample: bool = True,
    align: bool = True,
    prepared: bool = False,
    nk: int | None = None,
    per_sensor: bool = True,
    per_sensor_max_order: int = 20,
    tolerances: Tolerances | None = None,
    max_iter: int = 30,
    tol: float = SWEEP_TOL,
    n_jobs: int | None = None,
    progress: bool = False,
) -> StabilisationDiagram:
    """Sweep the model order and class every pole.

    Parameters
    ----------
    recording : Recording
    orders : iterable of int, optional
        The ``na`` values; ``nb`` and ``nc`` follow the module's rules. Orders given are
        refused when the record cannot support the highest; the default,
        ``DEFAULT_ORDERS``, is capped at what the record supports (``orders_capped``).
    band : (lo, hi), optional
        Frequency band of interest, Hz: sets the analysis rate and, in :func:`select_modes`,
        the band modes are taken from.
    detrend, resample, align
        Preparation of the record (:func:`~armaxmodal.prepare.prepare`): remove each
        channel's mean (or ``"linear"`` trend, or ``"none"``), resample a record sampled far
        above its band, align channels late by whole samples.
    prepared : bool
        The record is already prepared: fit it as it is (no checks, no warnings).
    nk : int, optional
        Input delay; by default chosen by BIC (:func:`~armaxmodal.modes.choose_nk`).
    per_sensor : bool
        Also sweep every sensor alone (the thesis's per-sensor view, Table 3.2).
    per_sensor_max_order : int
        Highest ``na`` of the single-sensor sweeps.
    tolerances : Tolerances, optional
    max_iter : int
        Levenberg-Marquardt cap per fit (a sweep needs positions, not the last digit).
    tol : float
        Relative loss decrease at which a sweep fit stops; looser than :func:`fit_armax`'s
        default for the same reason. :func:`select_modes` finishes the fits it reports.
    n_jobs : int, optional
        Worker threads (default: all cores).
    progress : bool
        Show progress bars (the delay choice's fits, then the sweep's).

    Returns
    -------
    StabilisationDiagram
        The fits of every order, their poles with stability classes, the preparation and its
        warnings.

    See Also
    --------
    armaxmodal.select_modes : Pick the physical modes from the diagram.
    armaxmodal.choose_orders : One order by an information criterion.

    Examples
    --------
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 120.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> diagram = am.stabilisation_diagram(ride, range(4, 13, 2))
    >>> sorted({order.na for order in diagram.orders})
    [4, 6, 8, 10, 12]
    """
    with one_blas_thread():  # a with block, not a decorator: mutmut skips decorated functions
        limits = tolerances or Tolerances()
        preparation = None
        if not prepared:
            preparation = prepare(recording, band=band, detrend=detrend, resample=resample, align=align)
            recording = preparation.recording
        notes: tuple = ()
        if orders is None:
            orders, notes = _default_orders(recording, preparation)
        _check_top_order(max(orders), recording, preparation)
        known: dict = {}
        from tqdm import tqdm

        if nk is None:
            first = len(NK_SEARCH) * len(DELAY_CHOICE_ORDERS)
            with tqdm(total=first, desc="input delay choice", unit="fit", disable=not progress) as bar:
                deepest = deepest_delay(recording, max(orders))
                nk, known = _choose_nk(recording, NK_SEARCH, DELAY_CHOICE_ORDERS, n_jobs, tol, deepest=deepest, bar=bar)
        sources = [SHARED] + (list(recording.sensors) if per_sensor else [])
        order_list = [Orders(na, default_nb(na, nk), default_nc(na), nk) for na in orders]
        # single sensors cannot support high orders (their bounds are wide): stop them earlier
        jobs = [(s, o) for o in order_list for s in sources if s == SHARED or o.na <= per_sensor_max_order]
        # the delay choice's fits of these orders continue from where they stopped, exactly
        # as if fitted here from the start (unless this sweep's cap is below theirs)
        if max_iter < DELAY_CHOICE_ITERATIONS:
            known = {}
        task = partial(_fit_and_poles, recording, max_iter=max_iter, tol=tol)
        cost = partial(_job_cost, n_sensors=len(recording.sensors))
        with tqdm(total=len(jobs), desc="stabilisation sweep", unit="fit", disable=not progress) as bar:
            shared = [job for job in jobs if job[0] == SHARED]
            todo = [job + ((known[job],) if job in known else ()) for job in shared]
            done = dict(zip(shared, parallel_map(task, todo, n_jobs, bar, cost=cost), strict=True))
            # each sensor's own fit starts from the shared fit of its order (its A, its B and C)
            single = [job for job in jobs if job[0] != SHARED]
            starts = [done[(SHARED, job[1])][0] for job in single]
            todo = [job + ((fit,) if fit is not None else ()) for job, fit in zip(single, starts, strict=True)]
            done.update(zip(single, parallel_map(task, todo, n_jobs, bar, cost=cost), strict=True))
        rows, kept = [], {}
        for source, o in jobs:
            fit, fit_rows = done[(source, o)]
            if fit is None:
                continue
            kept[(source, o.na)] = fit
            rows += fit_rows
        if not rows:
            raise OrderError("no order in the sweep could be fitted; use lower orders or a longer record.")
        poles = pd.DataFrame(rows)
        poles["cls"] = stability_classes(poles, limits)
        poles["rejected"] = rejection_reasons(poles, limits, recording)
        return StabilisationDiagram(poles, order_list, limits, recording, kept, preparation, notes)


def _supported_top_order(recording: Recording) -> int:
    """The highest ``na`` whose per-sensor model (``3 na + 1 - nk`` parameters at the most
    non-causal delay searched) has :data:`SAMPLES_PER_PARAMETER` samples a parameter."""
    return (recording.n_samples // SAMPLES_PER_PARAMETER - 1 + min(NK_SEARCH) - NK_EXTENSION) // 3


def _default_orders(recording: Recording, preparation: Preparation | None) -> tuple[list, tuple]:
    """``DEFAULT_ORDERS``, capped at what the record supports (the user typed none, so a
    short record is no error of theirs) with an ``orders_capped`` note; uncapped when the
    record supports them all. Below :data:`MIN_DEFAULT_TOP` the sweep is refused as usual."""
    top = _supported_top_order(recording)
    if top >= max(DEFAULT_ORDERS):
        return list(DEFAULT_ORDERS), ()
    if top < MIN_DEFAULT_TOP:
        return list(DEFAULT_ORDERS), ()  # refused by _check_top_order, with its advice
    capped = [na for na in DEFAULT_ORDERS if na <= top]
    note = QualityWarning(
        "orders_capped",
        (),
        f"the default orders 2-{max(DEFAULT_ORDERS)} were capped at na = {max(capped)}: this record "
        f"({recording.n_samples} samples at {recording.fs:g} Hz) supports at most na = {top} "
        f"({SAMPLES_PER_PARAMETER} samples a parameter); a longer record allows higher orders",
        float(max(capped)),
    )
    return capped, (note,)


def _check_top_order(na: int, recording: Recording, preparation: Preparation | None) -> None:
    """Refuse, before any fit, a sweep whose highest order the record cannot support."""
    # the first extension of the delay search must fit: the parameters at its most non-causal delay
    if deepest_delay(recording, na) <= min(NK_SEARCH) - NK_EXTENSION:
        return
    per_sensor = 3 * na + 1 - (min(NK_SEARCH) - NK_EXTENSION)
    top = max(_supported_top_order(recording), 2)
    narrow = [w for w in (preparation.warnings if preparation else ()) if w.code == "narrowband_input"]
    resampled = preparation is not None and preparation.analysis_fs != preparation.original_fs
    record = f"{recording.n_samples} samples at {recording.fs:g} Hz" + (
        f", resampled from {preparation.original_fs:g} Hz to the "
        + ("band" if preparation.band is not None else "input's band")
        if resampled
        else ""
    )
    lead = f"{narrow[0].message.rstrip('.')}; check that the input excites the structure. " if narrow else ""
    raise OrderError(
        f"{lead}Orders up to na = {na} need about {per_sensor} parameters per sensor; this record ({record}) "
        f"supports at most na = {top} ({SAMPLES_PER_PARAMETER} samples a parameter). Lower the top order, "
        f"e.g. --orders 2:{min(top, 40)}."
    )


def _delay_warnings(nk: int, recording: Recording, top_na: int) -> list[QualityWarning]:
    """``nk_at_search_edge`` where the chosen delay sits at the most non-causal delay the record
    supports for the sweep's top order: the widening search could go no further, and the outputs may
    lead the input by more. (A delay beyond the first search names no lead by itself: the F-16's
    level 3 takes nk = -8 at 40 Hz where the modal-model check's delays are 0.0 ms on every output,
    and the supine ride's damaged copies take -5 or -6 at 60 Hz.)"""
    if nk > deepest_delay(recording, top_na):
        return []
    return [
        QualityWarning(
            "nk_at_search_edge",
            (recording.input_name,),
            f"the chosen input delay nk = {nk} ({-nk} samples, {1e3 * -nk / recording.fs:.0f} ms) sits at the most "
            f"non-causal delay this record supports for orders up to na = {top_na} ({SAMPLES_PER_PARAMETER} samples "
            "a parameter): the outputs may lead the input by more (a late input or a filter delay); look at the "
            "sensor_delay check and align the channels, or sweep lower orders.",
            float(nk),
        )
    ]
