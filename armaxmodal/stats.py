"""Shared statistics and thresholds: the numbers several stages use, in one place.

* ``Z95`` -- the 95 % two-sided normal quantile, for every interval and its inverse.
* ``welch_nperseg`` -- the Welch segment rule of the spectra the checks and figures use.
* The coherence levels, each named by what it admits: ``H1_COHERENCE``,
  ``QUASI_STATIC_COHERENCE``, ``MISFIT_COHERENCE``, ``SECOND_INPUT_COHERENCE``.
* ``MAX_DAMPING`` -- the damping above which a pole is no vibration mode here.
* ``damping_interval`` -- a damping ratio's 95 % interval, taken on its logarithm.
* ``effective_fraction`` -- Bartlett's share of independent lines in a correlated residual.
* ``sandwich_sd`` -- heteroscedasticity-consistent standard errors of a least-squares fit.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "H1_COHERENCE",
    "MAX_DAMPING",
    "MISFIT_COHERENCE",
    "QUASI_STATIC_COHERENCE",
    "SECOND_INPUT_COHERENCE",
    "Z95",
    "damping_interval",
    "effective_fraction",
    "sandwich_sd",
    "welch_nperseg",
]

#: the normal distribution's 97.5 % quantile (scipy.special.ndtri(0.975)), written out so that
#: no stage imports scipy.stats for it: intervals are estimate +- Z95 sd, and an interval's
#: half-width over Z95 is its standard deviation
Z95 = 1.959963984540054

#: an H1 line is trusted where the coherence is at least this (Heylen, Lammens & Sas, Sec. A.3):
#: the modal-model check, the unexplained-peak check, the inverse problem's transmissibility
#: block and the figures' shading
H1_COHERENCE = 0.8
#: quasi-static lines (below the first mode, where a base-excited structure moves with its
#: base) on which the delay, inversion and unit checks measure: nearly perfect coherence
QUASI_STATIC_COHERENCE = 0.9
#: lines on which the diagnosis judges a model's FRF misfit for a missing mode: every line the
#: input drives the output on, short of noise
MISFIT_COHERENCE = 0.5
#: a recorded channel less coherent with the base than this (averaged over the base's
#: spectrum) is a candidate second input: response sensors read 0.63-1.00 on the measured records
SECOND_INPUT_COHERENCE = 0.5

#: heavier damping is no vibration mode here: heavily damped biomechanical modes reach 0.4-0.5,
#: anti-alias filter poles lie above
MAX_DAMPING = 0.6


def damping_interval(damping, half_width):
    """A damping ratio's interval ``damping * exp(-+ half_width / damping)``, taken on ``log(damping)``.

    A damping ratio is positive, and its estimate's distribution is skewed when its deviation is
    not small against it: a symmetric interval ``damping +- half_width`` then reaches below zero
    (a lightly damped mode's [-0.063, 0.083]), which no damping ratio can take. On the logarithm,
    with the delta method's deviation ``half_width / damping``, the interval stays positive and
    agrees with the symmetric one to first order where the deviation is small. Where the
    symmetric interval would reach zero (``half_width >= damping``), this one spans more than a
    factor e either side: the record does not resolve the damping. The upper end stops at 1
    (critical damping): above it the pole pair is two real poles, not a mode.

    Parameters
    ----------
    damping : float or array_like
        Damping ratios (positive; others give NaN).
    half_width : float or array_like
        Half-widths of their symmetric intervals (``Z95 * sd`` for a 95 % interval), same shape
        or broadcastable.

    Returns
    -------
    (lo, hi) : float or ndarray
        The interval's ends; NaN where ``damping`` is not positive or ``half_width`` not finite.
    """
    damping, half_width = np.asarray(damping, float), np.asarray(half_width, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        spread = np.exp(half_width / np.where(damping > 0, damping, np.nan))
    return damping / spread, np.minimum(damping * spread, 1.0)


def welch_nperseg(n_samples: int, fs: float, seconds: float = 10.0, max_fraction: int = 8) -> int:
    """The Welch segment length of the checks' and figures' spectra.

    Parameters
    ----------
    n_samples : int
        Samples in the record.
    fs : float
        Sampling rate, Hz.
    seconds : float
        The segment covers at least this long: the next power of two of ``fs * seconds``
        samples (1,024 at 60 Hz for 10 s), for the resolution the checks need.
    max_fraction : int
        ... but at most ``n_samples // max_fraction`` samples, so that enough segments average.

    Returns
    -------
    int
        Samples per segment.
    """
    return int(min(n_samples // max_fraction, 2 ** int(np.ceil(np.log2(fs * seconds)))))


def effective_fraction(residual: np.ndarray) -> float:
    """The fraction of DFT lines that are independent, from the residual's correlation across
    lines: ``1 / (1 + 2 sum_k rho_k)`` (Bartlett's effective sample size), the sum over lags
    ``k = 1, 2, ...`` up to the first non-positive ``rho_k`` (at most a quarter of the lines: the
    window ends where the correlation does, not at a set lag).

    Parameters
    ----------
    residual : (n_lines, n_sensors) complex ndarray
        A fit's residual on consecutive lines.

    Returns
    -------
    float
        In (0, 1]; 1 when neighbouring lines are uncorrelated (white noise's DFT).

    See Also
    --------
    armaxmodal.modes.count_search.count_modes : Scales the criterion's penalty by it.

    Examples
    --------
    >>> import numpy as np
    >>> from armaxmodal.stats import effective_fraction
    >>> white = np.random.default_rng(0).standard_normal((4000, 4)) @ [[1, 0], [1j, 0], [0, 1], [0, 1j]]
    >>> round(effective_fraction(white), 1)
    1.0
    >>> round(effective_fraction(white + np.roll(white, 1, axis=0)), 1)  # neighbours correlated 0.5
    0.5
    """
    r = np.asarray(residual) - np.mean(residual, axis=0)
    power = np.sum(np.abs(r) ** 2)
    if power == 0 or r.shape[0] < 4:
        return 1.0
    total = 0.0
    for k in range(1, r.shape[0] // 4 + 1):
        # complex correlation of lines k apart, pooled over sensors; its real part is what
        # shares information between the two lines
        rho = float(np.real(np.sum(np.conj(r[:-k]) * r[k:])) / power)
        if rho <= 0:
            break
        total += rho
    return 1.0 / (1.0 + 2.0 * total)


def sandwich_sd(blocks, n_par: int) -> np.ndarray:
    """Standard errors of a least-squares fit's parameters, heteroscedasticity-consistent (White's
    HC1 sandwich). A DFT fit's residual variance is not the same on every line: input noise and
    the model-class gap grow with |H| near the resonances, so one pooled variance understated the
    spread of the refit's first mode 2-3 times on band-limited rides (scripts/mc_coverage.py: 78 %
    coverage).

    Parameters
    ----------
    blocks : iterable of ((m, p) ndarray, (m,) ndarray)
        The Jacobian's rows and the residual's, a block at a time (the sums are taken so).
    n_par : int
        Every parameter fitted, the projected-out linear ones included (the degrees of freedom).

    Returns
    -------
    (p,) ndarray
    """
    gram, meat, rows = 0.0, 0.0, 0
    for jac, resid in blocks:
        gram, meat, rows = gram + jac.T @ jac, meat + (jac * resid[:, None] ** 2).T @ jac, rows + resid.size
    bread = np.linalg.pinv(gram)
    scale = rows / max(rows - n_par, 1)
    return np.sqrt(np.clip(np.diag(bread @ meat @ bread) * scale, 0, None))
