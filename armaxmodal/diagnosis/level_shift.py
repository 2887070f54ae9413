"""A level shift: one sensor's offset steps at an unknown time (a sensor knocked, re-zeroed or
switched in range mid-record).

A step of size ``w`` on output ``y`` at sample ``t0`` leaves the one-step residual ``w g(t - t0)``
from there on, ``g`` the step response of ``A / C`` (the level-shift pattern of Tsay 1988, as a
glitch's is the impulse response; see :mod:`.faults`). Its matched filter over every ``t0``,
``lambda(t0) = sum_j g_j e(t0 + j) / (sigma sqrt(sum_j g_j^2))``, is about N(0, 1) without a
shift (``sigma`` from the residual's median absolute deviation, robust to the shift itself); the
largest ``|lambda|`` is judged against the Bonferroni bound over the times searched. The time's
95 % interval holds the times whose ``lambda^2`` lies within 7.35 of the largest (the profile
likelihood of the change point, whose ratio's law Hansen 2000 gives). The scan starts where the
predictor's start-up has died out (1/C's impulse response holds 99.9 % of its energy), which
otherwise reads as a step near the start.

A drift is tried as a trend first: on the supine ride and the Chapter 2 system, two seeds each, a
planted drift is named ``offset_drift`` with no step tried (a rule that named a step only where it
explained more than the trend terms changed none of them, and went). A change of the structure,
later in a round, changes the dynamics and no single sensor's level.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import fftconvolve, lfilter
from scipy.special import ndtr
from scipy.stats import median_abs_deviation

from armaxmodal.diagnosis.faults import PI_ENERGY
from armaxmodal.diagnosis.finding import Finding
from armaxmodal.prepare.detrend import STEP_EDGE
from armaxmodal.stats import Z95

__all__ = [
    "CHANGE_POINT_LR_95",
    "level_shift_findings",
    "newey_west_sum",
    "remaining_step",
    "search_start",
    "step_scan",
]

#: the change point's 95 % likelihood-ratio level: its ratio is not chi-square(1) but has
#: P(LR <= x) = (1 - exp(-x / 2))^2 (Hansen 2000, threshold estimation), so -2 ln(1 - sqrt(0.95));
#: at 3.84 (with the spread then allowed below the white-noise one) a 0.1 x RMS step's interval
#: was one sample wide, the sample beside the truth
CHANGE_POINT_LR_95 = float(-2 * np.log(1 - np.sqrt(0.95)))


def step_scan(eps: np.ndarray, model, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """``(lambda, size, sigma)`` of a level shift at every sample of one channel's one-step
    residual ``eps`` (n,), counted where ``mask``: the matched-filter statistic, the
    least-squares size (the channel's units) and the residual's robust SD."""
    lam, size, sigma, _, _ = _scan(eps, model, mask)
    return lam, size, sigma


def _scan(eps: np.ndarray, model, mask: np.ndarray):
    """:func:`step_scan`, with the masked residual and the step pattern ``g``."""
    n = eps.size
    g = lfilter(model.a, model.c, np.ones(n))
    e = np.where(mask, eps, 0.0)
    sigma = float(median_abs_deviation(eps[mask], scale="normal"))
    matched = fftconvolve(e, g[::-1], mode="full")[n - 1 :]  # sum_j g_j e(t0 + j), t0 = 0..n-1
    energy = np.cumsum(g**2)[::-1]  # sum of g_j^2 over j < n - t0
    return matched / (sigma * np.sqrt(energy)), matched / energy, sigma, e, g


def newey_west_sum(w: np.ndarray) -> float:
    """Newey-West variance of ``sum w`` (Bartlett weights, ``4 n^(1/3)`` lags, as the disturbances'
    covariance in ``model._disturbance_ls``): a coloured or heteroscedastic residual (an
    earthquake's strong phase) spreads a matched filter's sum more than the white-noise
    ``sigma^2 sum g^2`` says, and a white-noise bound named a step in most measured records."""
    lag = int(4 * w.size ** (1 / 3))
    var = float(w @ w)
    for j in range(1, min(lag, w.size - 1) + 1):
        var += 2 * (1 - j / (lag + 1)) * float(w[j:] @ w[:-j])
    return max(var, 1e-300)


def _robust_variance(e: np.ndarray, g: np.ndarray, at: int, size: float) -> float:
    """:func:`newey_west_sum` of the matched filter's sum ``sum_j g_j e(at + j)`` under the step
    (the residual with it taken out)."""
    return newey_west_sum(g[: e.size - at] * (e[at:] - size * g[: e.size - at]))


def remaining_step(fitted, name: str, first: int) -> tuple[float, float]:
    """``(size, sd)`` of the step still in channel ``name``'s residual at recorded sample ``first``
    under ``fitted`` (a model fitted with the step in the data carries part of it in its noise
    model, so the first size falls short: 0.791 for a planted 0.8)."""
    from armaxmodal.diagnosis.model import counted

    k = fitted.signals.sensors.index(name)
    at = first - int(round(dict(fitted.spec.shifts).get(name, 0.0)))
    _, size, sigma, e, g = _scan(fitted.one_step_errors()[:, k], fitted.fit.models[k], counted(fitted))
    energy = float(g[: e.size - at] @ g[: e.size - at])
    spread = max(float(np.sqrt(_robust_variance(e, g, at, size[at]))), sigma * np.sqrt(energy))  # as in the test
    return float(size[at]), spread / energy


def search_start(model, mask: np.ndarray, edge: int) -> int:
    """The first sample a change is searched at: past ``edge`` and past the predictor's start from
    unknown initial values, which lasts until 1/C's impulse response holds ``PI_ENERGY`` of its
    energy (as the glitch test cuts its filter) and otherwise reads as a change near the start."""
    h = lfilter([1.0], model.c, np.r_[1.0, np.zeros(mask.size - 1)])
    start_up = int(np.searchsorted(np.cumsum(h**2) / np.sum(h**2), PI_ENERGY)) + 1
    return max(edge, int(np.argmax(mask)) + start_up)


def level_shift_findings(fitted, eps: np.ndarray, mask: np.ndarray, n_tests: int, table: dict) -> list[Finding]:
    """A ``level_shift`` finding for each sensor whose residual holds a step, with its time and
    size and their 95 % intervals (seconds from the record's start, the channel's units);
    ``table["step_p"]`` gets every sensor's corrected p."""
    s = fitted.signals
    edge = max(int(STEP_EDGE * s.n), 1)
    shifts = dict(fitted.spec.shifts)
    out, table["step_p"] = [], []
    for k, (name, model) in enumerate(zip(s.sensors, fitted.fit.models, strict=True)):
        lo = search_start(model, mask, edge)
        searched, settled = slice(lo, s.n - edge), mask & (np.arange(s.n) >= lo)
        lam, size, sigma, e, g = _scan(eps[:, k], model, settled)
        at = lo + int(np.argmax(np.abs(lam[searched])))
        energy = float(g[: s.n - at] @ g[: s.n - at])
        # the size's SD, from the residual as it is, never below the white-noise SD (a Newey-West
        # estimate can fall under it by chance: 0.42 of it on a 100 Hz ride, which put the truth
        # two samples outside a step's time interval)
        sd = max(np.sqrt(_robust_variance(e, g, at, size[at])), sigma * np.sqrt(energy)) / energy
        z = size[at] / sd
        p = min(1.0, 2 * (s.n - edge - lo) * float(ndtr(-abs(z))) * n_tests)
        table["step_p"].append(p)
        # the profile's chi-square, widened as the residual's colour widens the size's SD
        widening = (sd * np.sqrt(energy) / sigma) ** 2
        inside = np.flatnonzero(lam[searched] ** 2 >= lam[at] ** 2 - CHANGE_POINT_LR_95 * widening) + lo
        lag = shifts.get(name, 0.0)  # the residual is in the channel's shifted frame
        first = int(round(at + lag))
        half = Z95 * sd
        out.append(
            Finding(
                "level_shift",
                (name,),
                "step_z",
                float(abs(z)),
                p,
                {
                    "sample": first,
                    "time_s": first / s.fs,
                    "time_ci95_s": [round(inside.min() + lag) / s.fs, round(inside.max() + lag) / s.fs],
                    "size": float(size[at]),
                    "size_ci95": [float(size[at] - half), float(size[at] + half)],
                },
            )
        )
    return out
