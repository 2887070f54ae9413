"""The search of the count (the method page's "how many modes" gives its rules): from the diagram's selection,
every step compares the current model with its neighbours, each refitted with every pole free
(:func:`~armaxmodal.estimate.dft_model.fit_modal_model`) -- a mode removed (a merge of two close modes is a
removal), a left-out stable cluster or the residual's peak added, a mode split in two -- and the neighbour
of lowest criterion (:mod:`armaxmodal.modes.mode_count`) replaces the current model while it lowers it. Then
the chosen model is converged, carried-away starts judged, equally good models fitted, wanted additions flagged.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from functools import partial

import numpy as np
from scipy.special import chdtrc

from armaxmodal._threads import single_blas_thread
from armaxmodal.estimate.dft_model import DftLines, ModalModel, fit_modal_model
from armaxmodal.estimate.pool import parallel_map
from armaxmodal.modal import matched_poles, nearest_pole, new_poles
from armaxmodal.modes.mode_count import (
    ModeCount,
    ModelTable,
    Step,
    Wanted,
    halves_chi2,
    model_adequacy,
    residual_peak,
    split_start,
)
from armaxmodal.modes.poles import physical, reported, resolved
from armaxmodal.modes.settings import DEFAULTS, AgreementSettings, CountSettings, DftSettings
from armaxmodal.stats import Z95, effective_fraction

__all__ = ["count_modes"]


class _Search:
    """One search's fits: each candidate screened (``screen_nfev``), the best of a kind converged."""

    def __init__(
        self,
        data: DftLines,
        hold: str,
        n_effective: float,
        max_nfev: int,
        n_jobs: int | None = 1,
        settings: CountSettings = DEFAULTS.count,
        dft: DftSettings = DEFAULTS.dft,
        fitter: Callable = fit_modal_model,
        agreement: AgreementSettings = DEFAULTS.agreement,
        reach: float = DEFAULTS.cluster.freq,
    ):
        self.data, self.hold, self.n_eff, self.max_nfev, self.n_jobs = data, hold, n_effective, max_nfev, n_jobs
        self.cfg, self.dft, self.trials, self.table = settings, dft, 0, ModelTable(n_effective)
        self.fitter, self.agreement, self.reach, self.logged = fitter, agreement, reach, self.table.add

    def screened(
        self, starts: list[tuple[np.ndarray, np.ndarray]], labels: list[tuple[str, float]], intervals: bool = True
    ) -> list[ModalModel | None]:
        """Each start ``(freq_hz, damping)`` fitted for ``settings.screen_nfev`` steps, over the worker threads
        (numpy releases the interpreter in their array work); ``labels``: each start's ``(action, Hz)``;
        ``intervals=False``: fits compared by their criterion alone, without standard deviations."""
        self.trials += sum(len(f) > 0 for f, _ in starts)

        one = partial(self.fitter, self.data, settings=self.dft, intervals=intervals)
        fits = parallel_map(
            lambda start: one(*start, self.hold, self.cfg.screen_nfev) if len(start[0]) else None,
            starts,
            self.n_jobs,
            min_items=2,
        )
        return [self.logged(action, f, fit) for (action, f), fit in zip(labels, fits, strict=True)]

    def fit(
        self,
        freq_hz,
        damping,
        max_nfev: int | None = None,
        counted: bool = True,
        label: tuple[str, float] | None = ("converge", float("nan")),
    ) -> ModalModel | None:
        """One fit to convergence (or ``max_nfev``); ``counted=False`` where the caller counts it; ``label``:
        its ``(action, Hz)`` in the table (None: the caller logs it, as fits run in threads do, in their order)."""
        if len(freq_hz) == 0:
            return None
        self.trials += int(counted)
        model = self.fitter(self.data, freq_hz, damping, self.hold, max_nfev or self.max_nfev, settings=self.dft)
        return model if label is None else self.logged(*label, model)

    def bic(self, model: ModalModel | None) -> float:
        return np.inf if model is None else model.bic(self.n_eff)

    def best_of_each(self, removed: list, added: list, admissible) -> list:
        """``[best removal, best addition]``: of each kind the trial of lowest criterion, converged
        from where its screening left it (both at once, over the worker threads); an addition must
        pass ``admissible`` before and after. None where a kind has no (admissible) trial."""
        chosen = []
        for trials, test in ((removed, None), (added, admissible)):
            trials = [t for t in trials if test is None or test(t[2])]
            chosen.append(min(trials, key=lambda t: self.bic(t[2])) if trials else None)
        todo = [t for t in chosen if t is not None and t[2] is not None]
        self.trials += len(todo)
        fits = parallel_map(
            lambda t: self.fit(t[2].freq_hz, t[2].damping, counted=False, label=None), todo, self.n_jobs, min_items=2
        )
        fits = [self.logged(t[0], t[1], fit) for t, fit in zip(todo, fits, strict=True)]
        converged = {id(t): (t[0], t[1], fit) for t, fit in zip(todo, fits, strict=True)}
        out = []
        for trial, test in zip(chosen, (None, admissible), strict=True):
            done = None if trial is None else converged.get(id(trial), trial)
            out.append(done if done is None or test is None or test(done[2]) else None)
        return out

    def admissible(self, model: ModalModel | None, current: ModalModel, supported) -> bool:
        """A larger model's new poles are modes: damping resolved, and stable across the diagram's
        orders where the caller says what is (``supported``)."""
        if not resolved(model, self.data.band_hz):
            return False
        new = [i for i in new_poles(current.freq_hz, model.freq_hz) if physical(model, self.data.band_hz)[i]]
        return supported is None or all(supported(model.freq_hz[i], model.damping[i]) for i in new)

    def in_both_halves(self, trial: ModalModel, new: list[int], halves) -> bool | None:
        """Do the new poles of ``trial`` (indices ``new``) that both halves excite agree in them at ``agreement.alpha``,
        pooled (:func:`halves_chi2`; its probability ``self.p``)? None: none is excited, not asked. Into its row."""
        self.trials += 2
        fits = (self.hold, self.max_nfev, self.dft, self.fitter, self.agreement, self.reach)
        chi2 = halves_chi2(self.data, trial, halves, *fits)
        tested = [i for i in new if np.isfinite(chi2[i])]
        self.p = float(chdtrc(2 * len(tested), np.sum(chi2[tested]))) if tested else 1.0  # no new pole: agreed
        return self.table.halves(trial, self.p >= self.agreement.alpha if tested or not new else None)

    def removals(self, current: ModalModel) -> list[tuple[str, float, ModalModel | None]]:
        keep = [np.arange(current.n_modes) != m for m in range(current.n_modes)]
        fits = self.screened(
            [(current.freq_hz[k], current.damping[k]) for k in keep],  # the best is converged
            [("remove", float(f)) for f in current.freq_hz],
            intervals=False,
        )
        return [("remove", float(f), fit) for f, fit in zip(current.freq_hz, fits, strict=True)]

    def additions(self, current: ModalModel, candidates, peak_hz: float) -> list[tuple[str, float, ModalModel]]:
        """Each candidate added, and the mode nearest the residual's peak (``peak_hz``) split (one
        that hides two leaves its largest residual in its band; splitting all found no more)."""
        trials = []
        for f, x in candidates:
            if current.n_modes and np.min(np.abs(current.freq_hz / f - 1)) <= self.reach:
                continue
            trials.append(("add", float(f), np.r_[current.freq_hz, f], np.r_[current.damping, x]))
        for m in [nearest_pole(current.freq_hz, peak_hz)] if current.n_modes else []:
            trials.append(("split", float(current.freq_hz[m]), *split_start(current, m)))
        fits = self.screened([(f, x) for _, _, f, x in trials], [(action, f) for action, f, _, _ in trials])
        return [(action, f, fit) for (action, f, _, _), fit in zip(trials, fits, strict=True)]


def _margins(search: _Search, here: float, current: ModalModel, removed, best_removal, best_addition):
    """``(rise, gain, new_hz)``: each removal's rise of the criterion (the best one's converged), the
    best addition's fall, and where its new pole settled (the one farthest from the current modes)."""
    rise = np.array([search.bic(t[2]) - here for t in removed])
    if best_removal is not None:
        at = int(np.argmin(rise))
        rise[at] = min(rise[at], search.bic(best_removal[2]) - here)
    gain, new_hz = -np.inf, np.nan
    if best_addition is not None and best_addition[2] is not None:
        model = best_addition[2]
        gain = here - search.bic(model)
        dist = [np.min(np.abs(current.freq_hz / f - 1)) if current.n_modes else 1.0 for f in model.freq_hz]
        new_hz = float(model.freq_hz[int(np.argmax(dist))])
    return rise, gain, new_hz


def _without_unfounded(search: _Search, start_hz, model: ModalModel, supported, halves=()):
    """The chosen model without the starting poles the search carried beyond the clustering's reach
    of every start to where no mode is founded, refitted. A pole reported there is a new pole and
    must show what a mode has: a resolved damping, and the same values in both halves of the record
    (``_Search.in_both_halves``; where they do not both excite it, stability across the orders), judged on
    the converged model only (on the way a moved pole may stand in for a mode not yet added). Poles
    the model needs (the criterion rises by ``settings.decisive_bic`` or more without them) stay in
    it, unreported. The halves judge as they judge an addition: where no column is asked (the model
    is adequate), a pole they refuse at ``agreement.alpha`` but not at ``settings.decisive_alpha`` is
    founded, tentative; under the rule its standard deviations, from a model that misfits, are no
    judge of a near agreement, and the halves refuse at ``alpha``. The method page gives the cases
    behind these rules (a pelvis stuck for 53 samples, a bridge's start carried to 4.40 Hz, a body's
    top mode the model needs, a body's close pair at 14.40 and 15.62 Hz). Returns ``(model, left out:
    ((start Hz, Hz), ...), kept unreported: ((start Hz, Hz, rise), ...), tentative: (Hz, ...))``."""
    start_hz = np.atleast_1d(np.asarray(start_hz, float))
    shown = reported(model, search.data.band_hz)
    moved = [
        (i, j)
        for i, j in matched_poles(start_hz, model.freq_hz)
        if shown[i] and abs(np.log(model.freq_hz[i] / start_hz[j])) > search.reach
    ]
    unfounded, tentative = [], []
    for i, j in moved:
        f, x = model.freq_hz[i], model.damping[i]
        founded = x - Z95 * model.damping_sd[i] > 0
        agree = search.in_both_halves(model, [i], halves) if founded and len(halves) == 2 else None
        if agree is False and supported is None and search.p >= search.cfg.decisive_alpha:
            tentative.append(float(f))
            agree = True
        founded = founded and (agree if agree is not None else supported is None or supported(f, x))
        if not founded:
            unfounded.append((i, (float(start_hz[j]), float(f))))
    keep = np.setdiff1d(np.arange(model.n_modes), [i for i, _ in unfounded])
    if not unfounded or keep.size == 0:  # nothing else to stand on: the search's model stays
        return model, (), (), tuple(tentative)
    without = search.fit(
        model.freq_hz[keep], model.damping[keep], search.cfg.final_nfev, label=("leave out", unfounded[0][1][1])
    )
    rise = search.bic(without) - search.bic(model)
    if rise >= search.cfg.decisive_bic:  # the model needs them: they stay in it, unreported
        return model, (), tuple((*moved, float(rise)) for _, moved in unfounded), tuple(tentative)
    return without, tuple(moved for _, moved in unfounded), (), tuple(tentative)


def _equally_good(search: _Search, chosen: ModalModel, rise: np.ndarray, addition: ModalModel | None):
    """The models with one mode fewer or one more (the best addition) converged and kept where their
    criterion is within ``settings.decisive_bic`` of the chosen one's: ``[(difference, model), ...]``."""
    here, out, decisive = search.bic(chosen), [], search.cfg.decisive_bic
    starts = [(np.delete(chosen.freq_hz, m), np.delete(chosen.damping, m)) for m in np.flatnonzero(rise < decisive)]
    if addition is not None:
        starts.append((addition.freq_hz, addition.damping))
    for freq_hz, damping in starts:
        model = search.fit(freq_hz, damping, search.cfg.final_nfev, label=("alternative", float("nan")))
        if model is not None and abs(search.bic(model) - here) < decisive:
            out.append((float(search.bic(model) - here), model))
    return tuple(out)


def _wanted(
    search: _Search, current: ModalModel, addition, gain: float, new_hz: float, halves, supported=None
) -> tuple:
    """The refused addition the likelihood wants (see :attr:`ModeCount.wanted`), or ``()``. The
    likelihood ratio is ``-2 ln L`` of the current model less the addition's, on the effective
    lines; it is a chi-square of the parameters one mode adds where the record holds no more."""
    if addition is None or addition[2] is None or gain > -search.cfg.decisive_bic or len(halves) != 2:
        return ()
    return _likelihood_wants(search, current, addition[2], new_hz, gain, halves, supported)


def _likelihood_wants(
    search: _Search, current: ModalModel, model: ModalModel, new_hz: float, gain: float, halves, supported
) -> tuple:
    """A :class:`Wanted` when ``model``'s likelihood ratio over ``current`` is beyond
    ``settings.decisive_alpha`` and its new poles are the same in both halves, else ``()``;
    ``supported(Hz, ratio)``: does the diagram hold a column at its new pole (``new_hz``) to pick?"""
    dof = model.n_params - current.n_params
    ratio = current.neg2_loglik_on(search.n_eff) - model.neg2_loglik_on(search.n_eff)
    if dof <= 0 or not chdtrc(dof, ratio) < search.cfg.decisive_alpha:  # NaN below 0
        return ()
    if not search.in_both_halves(model, new_poles(current.freq_hz, model.freq_hz), halves):
        return ()
    at = nearest_pole(model.freq_hz, new_hz)
    in_diagram = supported is not None and bool(supported(model.freq_hz[at], model.damping[at]))
    return Wanted(new_hz, float(ratio), int(dof), float(-gain), in_diagram)


def _split_wanted(search: _Search, current: ModalModel, halves, supported=None) -> tuple[tuple, ModalModel | None]:
    """A split the likelihood wants (``()`` if none) and its converged model (None if none converged
    resolved): the reported mode nearest the residual's peak split (as the search's additions split one),
    converged and judged as :func:`_wanted` judges an addition; it needs no diagram column (two close
    modes stand as one column there)."""
    shown = np.flatnonzero(physical(current, search.data.band_hz))
    if len(halves) != 2 or shown.size == 0:
        return (), None
    m = int(shown[nearest_pole(current.freq_hz[shown], residual_peak(current, search.data)[0])])
    label = ("split", float(current.freq_hz[m]))
    best = search.screened([split_start(current, m)], [label], intervals=False)[0]
    if best is None:
        return (), None
    model = search.fit(best.freq_hz, best.damping, search.cfg.final_nfev, label=label)
    new = new_poles(current.freq_hz, model.freq_hz) if model is not None else []
    if not resolved(model, search.data.band_hz) or not new:
        return (), None
    gain = search.bic(current) - search.bic(model)
    return _likelihood_wants(search, current, model, float(model.freq_hz[new[0]]), gain, halves, supported), model


@single_blas_thread
def count_modes(
    data: DftLines,
    freq_hz,
    damping,
    candidates=(),
    *,
    hold: str = "bandlimited",
    max_nfev: int = 40,
    halves: tuple[DftLines, ...] = (),
    supported: Callable[[float, float], bool] | None = None,
    search: bool = True,
    n_jobs: int | None = None,
    settings: CountSettings = DEFAULTS.count,
    dft: DftSettings = DEFAULTS.dft,
    fitter: Callable = fit_modal_model,
    agreement: AgreementSettings = DEFAULTS.agreement,
    adequacy: Callable | None = None,
    reach: float = DEFAULTS.cluster.freq,
) -> ModeCount:
    """Choose the number of modes by nested tests of free refits (see the module notes).

    Parameters
    ----------
    data : DftLines
        The recording's lines, weighted.
    freq_hz, damping : (n_modes,) array_like
        The starting set (Hz, ratio).
    candidates : sequence of (freq_hz, damping)
        Left-out stable clusters of the diagram, tried as additions.
    hold : {"bandlimited", "zoh"}
        Inter-sample assumption.
    max_nfev : int
        Cap on residual evaluations per fit.
    halves : tuple of DftLines
        The lines of the record's two halves: an accepted addition's new poles must be the same
        in each that both excite (``_Search.in_both_halves``). Empty: not asked.
    supported : callable, optional
        ``supported(freq_hz, damping)``: is a pole there stable across the diagram's orders? An
        addition's new poles must be (a ghost soaking up a nonlinearity is not). None: not asked.
    search : bool
        False: the starting set is the model (picks); it is fitted and its margins measured, but
        no step is taken and no mode left out.
    n_jobs : int, optional
        Worker threads for the screening fits (default: all cores).
    settings : CountSettings
        The count's thresholds (:mod:`armaxmodal.modes.settings`).
    dft, agreement : DftSettings, AgreementSettings
        The modal model's fits (a pole at their damping floor is a line, not a mode); the halves' test's level.
    fitter : callable
        The fit, as :func:`~armaxmodal.estimate.dft_model.fit_modal_model` (a test's stands in for it).
    reach : float
        Two poles within this relative frequency are one mode (the clustering's reach,
        ``ClusterSettings.freq``): a candidate near a mode, a start the search kept near, a half's pole.
    adequacy : callable, optional
        ``adequacy(model, data) -> Adequacy``: the adequacy test (default
        :func:`~armaxmodal.modes.mode_count.model_adequacy` at ``settings.adequacy_ratio``; a test's
        stands in for it beside a scripted fitter).

    Returns
    -------
    ModeCount

    See Also
    --------
    armaxmodal.modes.mode_count.ModeCount : What it returns.
    armaxmodal.modes.mode_count.model_adequacy : Which world the count runs in.

    Examples
    --------
    Started one mode short, the count adds it:

    >>> import armaxmodal as am
    >>> body, exact = am.supine_human(), am.supine_human().modes()  # exact: 5.83, 8.31, 13.50, 16.25 Hz
    >>> ride = am.simulate_recording(body, am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03, seed=2)
    >>> from armaxmodal.estimate.dft_model import DftLines
    >>> data = DftLines.from_recording(ride, (0.5, 28.0))
    >>> count = am.modes.count_search.count_modes(data, exact.freq_hz[:3], exact.damping[:3], hold="zoh")
    >>> [step.action for step in count.steps], [round(float(f), 1) for f in sorted(count.model.freq_hz)]
    (['add'], [5.8, 8.3, 13.6, 16.2])
    """
    return _count_modes(
        data,
        freq_hz,
        damping,
        candidates,
        hold=hold,
        max_nfev=max_nfev,
        halves=halves,
        supported=supported,
        search=search,
        n_jobs=n_jobs,
        settings=settings,
        dft=dft,
        fitter=fitter,
        agreement=agreement,
        adequacy=adequacy,
        reach=reach,
    )


def _count_modes(
    data: DftLines,
    freq_hz,
    damping,
    candidates,
    *,
    supported,
    search,
    settings: CountSettings,
    adequacy: Callable | None = None,
    **options,
) -> ModeCount:
    """:func:`count_modes` itself (its parameters), under the caller's BLAS threads (the public one holds one).

    The world first (:func:`armaxmodal.modes.mode_count.model_adequacy`): the search runs with the criterion and the
    halves alone, and where its model explains the record to its noise, that model is the count's.
    Where it does not, the likelihood is no judge of what a mode is: the search runs again under the
    one stated rule (an added mode also stands in a stable diagram column, ``supported``), both
    searches' fits in the table, and ``rule_refused`` keeps what the first chose where its criterion
    is lower."""
    free = _searched(
        data, freq_hz, damping, candidates, supported=supported, rule=False, search=search, settings=settings, **options
    )
    test = (adequacy or _adequacy_at(settings.adequacy_ratio))(free.model, data)
    if test.adequate or supported is None or not search:
        return replace(free, adequacy=test)
    ruled = _searched(
        data, freq_hz, damping, candidates, supported=supported, rule=True, search=search, settings=settings, **options
    )
    n_eff = free.effective_fraction * data.n_real * data.y.shape[1]  # both searches start from one model
    fall = float(ruled.model.bic(n_eff) - free.model.bic(n_eff))
    refused = (fall, tuple(np.sort(free.model.freq_hz))) if fall > 0 else ()  # what the criterion preferred
    return replace(
        ruled, adequacy=test, rule_refused=refused, trials=free.trials + ruled.trials, models=free.models + ruled.models
    )


def _adequacy_at(level: float) -> Callable:
    """The package's adequacy test at ``level``, as :func:`count_modes` calls one: ``(model, data)``."""
    return lambda model, data: model_adequacy(model, data.u, level)


def _searched(
    data: DftLines,
    freq_hz,
    damping,
    candidates,
    *,
    hold,
    max_nfev,
    halves,
    supported,
    rule: bool,
    search,
    n_jobs,
    settings: CountSettings,
    dft,
    fitter,
    agreement,
    reach,
) -> ModeCount:
    """One search from the starting set; ``rule``: an addition is admitted only where ``supported`` says
    (which also says whether a wanted mode has a column to pick)."""
    column = supported if rule else None
    start_model = fitter(data, freq_hz, damping, hold, max_nfev, settings=dft)
    # each sensor weighted by its noise level as the fitted start leaves it (the likelihood is
    # concentrated over those levels; the weights only steer the fits)
    data = data.noise_weighted(start_model)
    start_model = fitter(data, start_model.freq_hz, start_model.damping, hold, max_nfev, settings=dft)
    fraction = effective_fraction(start_model.residual)
    searching, search = (
        search,
        _Search(
            data,
            hold,
            fraction * data.n_real * data.y.shape[1],
            max_nfev,
            n_jobs,
            settings,
            dft,
            fitter,
            agreement,
            reach,
        ),
    )
    search.logged("start", float("nan"), start_model)
    # a start the free fit carried away (a weak mode's pole to beyond the band) is tried again as an addition
    lost = [
        (f, x)
        for f, x in zip(np.atleast_1d(freq_hz), np.atleast_1d(damping), strict=True)
        if np.min(np.abs(np.log(start_model.freq_hz / f))) > reach
    ]
    current, steps, candidates, unconfirmed, unsettled = start_model, [], list(candidates) + lost, [], []

    def neighbours():
        """The current model's criterion, its removals, and the best removal and addition (an
        addition the halves do not confirm is noted and dropped)."""
        here = search.bic(current)
        removed = search.removals(current)
        peak = residual_peak(current, search.data)
        added = search.additions(current, candidates + [peak], peak[0])
        best_removal, best_addition = search.best_of_each(
            removed, added, lambda model: search.admissible(model, current, column)
        )
        if best_addition is not None and search.bic(best_addition[2]) < here and len(halves) == 2:
            new = new_poles(current.freq_hz, best_addition[2].freq_hz)
            if search.in_both_halves(best_addition[2], new, halves) is False:  # refused, or taken undecided if near
                if column is None and search.p >= settings.decisive_alpha:  # see _without_unfounded
                    unsettled.append(float(best_addition[2].freq_hz[new[0]]))
                else:
                    unconfirmed.append(best_addition[1])
                    best_addition = None
        return here, removed, best_removal, best_addition

    while True:
        here, removed, best_removal, best_addition = neighbours()
        better = [t for t in (best_removal, best_addition) if t is not None and search.bic(t[2]) < here]
        if not better or len(steps) == (settings.max_steps if searching else 0):
            break
        step = min(better, key=lambda t: search.bic(t[2]))
        new = new_poles(current.freq_hz, step[2].freq_hz)
        settled = float(step[2].freq_hz[new[0]]) if new else float("nan")
        steps.append(Step(step[0], step[1], here - search.bic(step[2]), settled))
        current = step[2]
    rise, gain, new_hz = _margins(search, here, current, removed, best_removal, best_addition)
    # the reported model is the likelihood's maximum, not where the search's cap left it (a body's
    # fifth mode stood at 23.73 Hz after the search and 24.35 Hz converged, for the exact 25.48)
    search.data = data.noise_weighted(current)  # the weights the chosen model's own levels give
    final = search.fit(current.freq_hz, current.damping, settings.final_nfev)
    if search.bic(final) < here:
        rise, gain, current = rise + here - search.bic(final), gain - (here - search.bic(final)), final
    current, carried_away, stand_ins, tentative = (
        _without_unfounded(search, freq_hz, current, column, halves) if searching else (current, (), (), ())
    )
    unsettled += [
        f
        for f in tentative  # one note a pole: the search may have taken it so already
        if not any(abs(np.log(f / u)) <= reach for u in unsettled)
    ]
    if carried_away:  # the model lost a pole: its neighbours are judged again, from where it stands
        here, removed, best_removal, best_addition = neighbours()
        rise, gain, new_hz = _margins(search, here, current, removed, best_removal, best_addition)
    close = best_addition[2] if best_addition is not None and gain > -settings.decisive_bic else None
    alternatives = _equally_good(search, current, rise, close)
    wanted = _wanted(search, current, best_addition, gain, new_hz, halves, supported) if searching else ()
    if rule and wanted and not wanted.in_diagram:  # the misfit's likelihood is no judge: the rule refuses it
        wanted = ()
    if searching and not wanted and close is None:  # one mode more is already undecided: said once
        wanted, split = _split_wanted(search, current, halves, supported)
        # as good as the chosen model: its modes are the record's too
        if wanted and abs(wanted.rise) < settings.decisive_bic:
            alternatives += ((wanted.rise, split),)
    return ModeCount(
        model=current,
        start=start_model,
        steps=tuple(steps),
        removal_rise=rise,
        best_addition=float(gain),
        best_addition_hz=new_hz,
        effective_fraction=fraction,
        trials=search.trials,
        wanted=wanted,
        unconfirmed_hz=tuple(unconfirmed),
        unsettled_hz=tuple(unsettled),
        alternatives=alternatives,
        carried_away=carried_away,
        stand_ins=stand_ins,
        models=tuple(search.table.rows),
        band_hz=data.band_hz,
        settings=settings,
        dft=dft,
        agreement=agreement,
        reach=reach,
    )
