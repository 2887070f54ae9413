"""Automatic choice of ARMAX orders and input delay by an information criterion.

Rules (documented defaults, all overridable):

* ``nc = na``: white sensor noise on the outputs makes the true C equal to A.
* ``nb = na + 1 - nk``: the causal part keeps ``na + 1`` taps (a b0 term: acceleration in,
  acceleration out is biproper) and each step of negative ``nk`` adds one non-causal tap,
  as band-limited sampled data needs.
* The criterion is BIC of the concentrated Gaussian likelihood,
  ``N sum_k log(V_k / N) + p log(N K)`` for K sensors (shared poles) or per sensor.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from functools import partial
from typing import NamedTuple

import numpy as np
import pandas as pd

from armaxmodal.estimate.fit import fit_armax, fit_resumable
from armaxmodal.estimate.pool import parallel_map
from armaxmodal.estimate.result import ArmaxFit
from armaxmodal.exceptions import OrderError
from armaxmodal.recording import Recording

__all__ = ["choose_delay", "choose_orders", "OrderChoice", "Orders", "default_nb", "default_nc", "order_criteria"]


def default_nb(na: int, nk: int) -> int:
    """``na + 1 - nk`` B coefficients (see the module docstring).

    Parameters
    ----------
    na : int
        Order of A.
    nk : int
        Input delay in samples (negative: non-causal taps of a band-limited input).

    Returns
    -------
    int
        The number of B coefficients.

    See Also
    --------
    armaxmodal.estimate.default_nc : The C polynomial's order beside it.
    armaxmodal.fit_armax : Uses both when only na is given.

    Examples
    --------
    >>> from armaxmodal.estimate import default_nb
    >>> default_nb(8, 0), default_nb(8, -2)  # a delay of -2 samples needs two taps more
    (9, 11)
    """
    return na + 1 - min(nk, 0)


def default_nc(na: int) -> int:
    """``nc = na``.

    Parameters
    ----------
    na : int
        Order of A.

    Returns
    -------
    int
        The order of C.

    See Also
    --------
    armaxmodal.estimate.default_nb : The B polynomial's order beside it.
    armaxmodal.fit_armax : Uses both when only na is given.

    Examples
    --------
    >>> from armaxmodal.estimate import default_nc
    >>> default_nc(8)
    8
    """
    return na


class Orders(NamedTuple):
    """An ARMAX model's orders (Eq. 3.9): ``na`` poles, ``nb`` input and ``nc`` noise
    coefficients, input delay ``nk`` samples. A tuple, so ``(na, nb, nc, nk)`` still unpacks."""

    na: int
    nb: int
    nc: int
    nk: int


@dataclass(frozen=True)
class OrderChoice:
    """The chosen fit and the criterion table (one row per candidate).

    See Also
    --------
    armaxmodal.choose_orders : What makes one.
    armaxmodal.estimate.information_criterion : The criterion it ranks by.

    Examples
    --------
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> choice = am.choose_orders(ride, range(4, 11, 2), range(0, -2, -1))  # 4 orders x 2 delays
    >>> tuple(choice.fit.orders), len(choice.table)  # four modes: na = 8
    ((8, 9, 8, 0), 8)
    """

    fit: ArmaxFit
    table: pd.DataFrame

    @property
    def orders(self) -> tuple[int, int, int, int]:
        return self.fit.orders


def information_criterion(fit: ArmaxFit, kind: str = "bic", unit: np.ndarray | None = None) -> float:
    """BIC (or AIC) of a fit from its per-sensor mean squared prediction errors.

    ``unit`` (per sensor, e.g. ``output_mean_squares``) divides each sensor's prediction
    error variance. Candidates whose delays differ are fitted on windows a few samples apart,
    and ``n log V`` then carries ``n log s^2`` when the data are scaled by ``s``: a record in
    cm/s^2 chose a wider delay than the same record in m/s^2. Measured in the outputs' own
    mean square, the criterion is the same in every unit.

    Parameters
    ----------
    fit : ArmaxFit
    kind : {"bic", "aic"}
    unit : (n_sensors,) ndarray, optional
        Each sensor's output mean square, dividing its prediction-error variance (default: 1,
        the criterion in the data's own units).

    Returns
    -------
    float
        The criterion, summed over sensors; smaller is better.

    See Also
    --------
    armaxmodal.choose_orders : Ranks orders by it.

    Examples
    --------
    >>> import armaxmodal as am
    >>> from armaxmodal.estimate import information_criterion
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> two = am.fit_armax(ride, 4, 5, 4, 0, shared_poles=True, warn=False)  # room for two modes
    >>> four = am.fit_armax(ride, 8, 9, 8, 0, shared_poles=True, warn=False)  # for all four
    >>> round((information_criterion(two) - information_criterion(four)) / 1000)  # BIC falls, in thousands
    23
    """
    n = fit.n_samples
    k = len(fit.models)
    na, nb, nc, _ = fit.orders
    n_in = fit.models[0].b.shape[0]
    p = na + k * (n_in * nb + nc) if fit.shared_poles else k * (na + n_in * nb + nc)
    loss = fit.loss if unit is None else fit.loss / np.asarray(unit, dtype=float)
    fit_term = n * float(np.sum(np.log(loss)))
    penalty = p * np.log(n * k) if kind == "bic" else 2.0 * p
    return fit_term + penalty


def output_mean_squares(recording: Recording) -> np.ndarray:
    """Each output's mean square over the record, the unit :func:`~armaxmodal.estimate.information_criterion`
    measures prediction errors in when candidates' windows differ (``(n_sensors,)``)."""
    ms = np.mean(np.square(recording.response), axis=0)
    return np.where(ms > 0, ms, 1.0)


def order_criteria(fits: Iterable[ArmaxFit], recording: Recording) -> dict[int, float]:
    """``{na: BIC}`` of fits of one record, one per order, each output's errors in its mean square
    (:func:`output_mean_squares`): the orders fit windows a few samples apart, where a plain BIC
    depends on the data's unit."""
    unit = output_mean_squares(recording)
    return {fit.orders[0]: information_criterion(fit, unit=unit) for fit in fits}


def fit_or_none(recording, orders, **options):
    """A fit, or None when the record cannot support the orders (candidates are skipped)."""
    try:
        return fit_armax(recording, *orders, warn=False, **options)
    except OrderError:
        return None


def choose_delay(
    recording: Recording,
    nk_values: Iterable[int],
    na_values: Iterable[int],
    *,
    max_iter: int,
    tol: float,
    n_jobs: int | None = None,
    bar=None,
) -> tuple[int, dict]:
    """The input delay of the lowest-BIC shared-pole model over the orders ``na_values``, each
    delay fitted at each order for at most ``max_iter`` iterations (the delay and the order
    interact: band-limited data trade non-causal taps for poles, so they are chosen jointly).
    Only the criterion is needed: no covariances.

    Parameters
    ----------
    recording : Recording
    nk_values, na_values : iterables of int
        The delays (samples; negative: non-causal taps) and the orders each is fitted at.
    max_iter : int
        Iterations of each candidate's fit.
    tol : float
        A fit stops when an iteration lowers its loss by less than this fraction.
    n_jobs : int, optional
        Worker threads (default: all cores).
    bar : tqdm, optional
        Counts the fits.

    Returns
    -------
    nk : int
        The delay of the lowest criterion (measured in each output's mean square).
    checkpoints : dict
        ``{Orders: checkpoint}`` of the chosen delay's fits, where they stopped: a sweep continues
        them instead of fitting those orders again.
    """
    candidates = [Orders(na, default_nb(na, nk), default_nc(na), nk) for na in na_values for nk in nk_values]
    fit = partial(_resumable_or_none, recording, max_iter=max_iter, tol=tol)
    fits = parallel_map(fit, candidates, n_jobs, bar, cost=lambda orders: orders.na)
    unit = output_mean_squares(recording)
    scores = [information_criterion(f, unit=unit) if f is not None else np.inf for f, _ in fits]
    nk = candidates[int(np.argmin(scores))].nk
    return nk, {o: ck for o, (_, ck) in zip(candidates, fits, strict=True) if o.nk == nk and ck is not None}


def _resumable_or_none(recording: Recording, orders: Orders, max_iter: int, tol: float):
    """``(fit, checkpoint)`` of a shared-pole candidate, ``(None, None)`` when the record cannot support it."""
    try:
        return fit_resumable(
            recording,
            orders,
            shared_poles=True,
            max_iter=max_iter,
            tol=tol,
            stop="decrease",
            warn=False,
            covariance=False,
        )
    except OrderError:
        return None, None


def choose_orders(
    recording: Recording,
    na_values: Iterable[int] = range(4, 21, 2),
    nk_values: Iterable[int] = range(0, -7, -1),
    *,
    shared_poles: bool = True,
    criterion: str = "bic",
    max_iter: int = 100,
    n_jobs: int | None = None,
    progress: bool = False,
) -> OrderChoice:
    """Fit every (na, nk) candidate with the default nb and nc and keep the best by BIC/AIC.

    Parameters
    ----------
    recording : Recording
    na_values, nk_values : iterables of int
        Candidates; orders the record cannot support are skipped.
    shared_poles : bool
        Choose for the shared-pole form (default) or the per-sensor form.
    criterion : {"bic", "aic"}
        Computed with each sensor's prediction errors in units of its mean square
        (:func:`~armaxmodal.estimate.information_criterion`'s ``unit``), so that the choice does not depend on
        the data's unit.
    n_jobs : int, optional
        Worker threads (default: all cores; 1 runs in this thread).
    progress : bool
        Show a progress bar.
    max_iter : int
        Cap on Gauss-Newton iterations of each candidate's fit.

    Returns
    -------
    OrderChoice

    See Also
    --------
    armaxmodal.fit_armax : Fit one model.
    armaxmodal.stabilisation_diagram : Fits over a range of orders.

    Examples
    --------
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 120.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> choice = am.choose_orders(ride, na_values=[6, 8], nk_values=[0, -1])
    >>> choice.orders[0]  # na of lowest BIC: four modes need eight poles
    8
    """
    if criterion not in ("bic", "aic"):
        raise ValueError(f"criterion: expected 'bic' or 'aic', got {criterion!r}.")
    candidates = [(na, default_nb(na, nk), default_nc(na), nk) for na in na_values for nk in nk_values]
    run = partial(fit_or_none, recording, shared_poles=shared_poles, max_iter=max_iter)
    from tqdm import tqdm

    with tqdm(total=len(candidates), desc="order search", unit="fit", disable=not progress) as bar:
        fits = parallel_map(run, candidates, n_jobs, bar, cost=lambda orders: orders[0])
    rows, best, best_value = [], None, np.inf
    unit = output_mean_squares(recording)
    for (na, nb, nc, nk), fit in zip(candidates, fits, strict=True):
        if fit is None:
            continue
        value = information_criterion(fit, criterion, unit=unit)
        rows.append(
            {"na": na, "nb": nb, "nc": nc, "nk": nk, criterion: value, "converged": bool(np.all(fit.converged))}
        )
        if value < best_value:
            best, best_value = fit, value
    if best is None:
        raise OrderError("no candidate order fits this record; give smaller na_values.")
    return OrderChoice(best, pd.DataFrame(rows).sort_values(criterion).reset_index(drop=True))
