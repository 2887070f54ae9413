"""A gain change: one sensor's scale steps at an unknown time (a range switch, a mount that
loosens), while the structure, and so every other sensor, stays as it was.

A sensor that from sample ``t0`` reads ``(1 + d)`` times what reaches it leaves the one-step
residual ``d (A / C) y(t)`` from there on; its regressor is the output's predicted part through
the predictor's filter, ``z = (B / C) u`` (the filter's start at ``t0`` is short beside a
record). The least-squares ``d`` at every ``t0`` is a ratio of reverse cumulative sums,
``sum_{t >= t0} z e / sum_{t >= t0} z^2``; it is judged as
the level shift's size is (:mod:`.level_shift`): over its Newey-West spread, never below the
white-noise one, Bonferroni over the times searched from where the predictor's start-up has died
out, and the time's interval at the change point's likelihood-ratio level.

A change of the structure (``time_varying``, later in a round) changes every sensor's response at
once; a gain change scales one sensor's whole output, its response and its noise alike: a change
that another sensor shows at the same time is not named a gain change.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import lfilter
from scipy.special import ndtr
from scipy.stats import median_abs_deviation

from armaxmodal.diagnosis.finding import Finding
from armaxmodal.diagnosis.level_shift import CHANGE_POINT_LR_95, newey_west_sum, search_start
from armaxmodal.prepare.detrend import STEP_EDGE
from armaxmodal.stats import Z95

__all__ = ["SHARED_Z", "gain_change_findings", "gain_scan", "predicted_part", "remaining_gain"]

#: another sensor's relative change at a gain change's time, in its own SDs, beyond which the change
#: is the structure's: the 1 % two-sided level over the other sensors of a four-sensor record
SHARED_Z = 3.0


def gain_scan(eps: np.ndarray, z: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(lambda, d, energy)`` of a gain change at every sample: the white-noise statistic, the
    least-squares relative change and ``sum_{t >= t0} z^2``, from the one-step residual ``eps`` and
    the filtered output ``z`` (n,), counted where ``mask``."""
    e, zm = np.where(mask, eps, 0.0), np.where(mask, z, 0.0)
    sigma = float(median_abs_deviation(eps[mask], scale="normal"))
    matched = np.cumsum((zm * e)[::-1])[::-1]
    energy = np.maximum(np.cumsum((zm**2)[::-1])[::-1], 1e-300)
    return matched / (sigma * np.sqrt(energy)), matched / energy, energy


def _spread(e: np.ndarray, z: np.ndarray, at: int, d: float, sigma: float, energy: float) -> float:
    """The SD of the relative change at ``at``: the sum's Newey-West spread under the change, never
    below the white-noise one, over ``sum z^2``."""
    return max(np.sqrt(newey_west_sum(z[at:] * (e[at:] - d * z[at:]))), sigma * np.sqrt(energy)) / energy


def predicted_part(fitted, k: int, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Output ``k``'s predicted part through its predictor's filter, ``(A / C) y - e = (B / C) u``
    (disturbance taken out), its masked residual and the residual's SD. Not ``(A / C) y`` itself:
    it holds the residual, whose sum of squares then reads as a gain (1.207 for a planted 1.2,
    its interval 1.206-1.209)."""
    model = fitted.fit.models[k]
    y = fitted.signals.y[:, k] - fitted.disturbance()[:, k]
    eps = fitted.one_step_errors()[:, k]
    z = np.where(mask, lfilter(model.a, model.c, y) - eps, 0.0)
    sigma = float(median_abs_deviation(eps[mask], scale="normal"))
    return z, np.where(mask, eps, 0.0), sigma


def _seen_by_others(scans: list, k: int, at: int) -> bool:
    """Does another sensor change at ``at`` too, its relative change beyond ``SHARED_Z`` of its own
    SD? A change of the structure moves every sensor's response at once (a ride whose springs
    stiffen 12 % half way was named a gain change on its chest); a sensor's gain moves its own."""
    for j, (z, e, sigma, _, d, energy) in enumerate(scans):
        if j != k and abs(d[at]) > SHARED_Z * _spread(e, z, at, d[at], sigma, energy[at]):
            return True
    return False


def remaining_gain(fitted, name: str, first: int) -> tuple[float, float]:
    """``(d, sd)``: the relative gain change still in channel ``name``'s residual at recorded
    sample ``first`` under ``fitted``."""
    from armaxmodal.diagnosis.model import counted

    k = fitted.signals.sensors.index(name)
    at = first - int(round(dict(fitted.spec.shifts).get(name, 0.0)))
    z, e, sigma = predicted_part(fitted, k, counted(fitted))
    _, d, energy = gain_scan(e, z, counted(fitted))
    return float(d[at]), float(_spread(e, z, at, d[at], sigma, energy[at]))


def gain_change_findings(fitted, eps: np.ndarray, mask: np.ndarray, n_tests: int, table: dict) -> list[Finding]:
    """A ``gain_change`` finding for each sensor, with its time and relative change and their 95 %
    intervals; ``table["gain_p"]`` gets every sensor's corrected p."""
    s = fitted.signals
    edge = max(int(STEP_EDGE * s.n), 1)
    shifts = dict(fitted.spec.shifts)
    out, table["gain_p"] = [], []
    lo = max(search_start(model, mask, edge) for model in fitted.fit.models)
    settled = mask & (np.arange(s.n) >= lo)
    scans = [(*predicted_part(fitted, k, settled),) for k in range(len(s.sensors))]
    scans = [(z, e, sigma, *gain_scan(e, z, settled)) for z, e, sigma in scans]
    for k, name in enumerate(s.sensors):
        z, e, sigma, lam, d, energy = scans[k]
        at = lo + int(np.argmax(np.abs(lam[lo : s.n - edge])))
        sd = _spread(e, z, at, d[at], sigma, energy[at])
        p = min(1.0, 2 * (s.n - edge - lo) * float(ndtr(-abs(d[at] / sd))) * n_tests)
        table["gain_p"].append(p)
        if _seen_by_others(scans, k, at):
            continue  # the structure changed, not one sensor's gain
        widening = (sd * np.sqrt(energy[at]) / sigma) ** 2
        inside = np.flatnonzero(lam[lo : s.n - edge] ** 2 >= lam[at] ** 2 - CHANGE_POINT_LR_95 * widening) + lo
        lag = shifts.get(name, 0.0)  # the residual is in the channel's shifted frame
        first = int(round(at + lag))
        out.append(
            Finding(
                "gain_change",
                (name,),
                "gain_z",
                float(abs(d[at] / sd)),
                p,
                {
                    "sample": first,
                    "time_s": first / s.fs,
                    "time_ci95_s": [round(inside.min() + lag) / s.fs, round(inside.max() + lag) / s.fs],
                    "factor": float(1 + d[at]),
                    "factor_ci95": [float(1 + d[at] - Z95 * sd), float(1 + d[at] + Z95 * sd)],
                },
            )
        )
    return out
