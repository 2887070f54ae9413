"""Sensor faults: a channel stuck on one value, and isolated glitches (additive outliers).

* **Stuck.** A live sensor does not repeat its last value for long. With ``r`` the channel's
  own rate of repeating the previous sample (outside the run tested, so a coarse quantiser on
  a slow signal is allowed its repeats), a run of ``L`` equal samples somewhere in ``n`` has
  probability at most ``n r^(L-1)``. Runs at the channel's extremes are clipping's
  (:mod:`.clipping`), not tested here.
* **Glitch.** A sample off by ``w`` (a spike, a dropped sample read as zero) leaves the
  one-step residual ``w pi`` from there on, ``pi`` the impulse response of ``A / C``. The
  additive-outlier statistic of Chang, Tiao & Chen (1988) is that pattern's matched filter,
  ``lambda(t) = sum_j pi_j e(t + j) / (sigma |pi|)``, about N(0, 1) without a glitch
  (``sigma`` from the residual's median absolute deviation, robust to the glitches
  themselves). Glitches are taken one at a time, largest first, each one's pattern removed
  before the next (so a glitch's neighbours are not counted again), while ``|lambda|``
  passes the Bonferroni bound over the samples.

A glitch is the sensor's, not the record's: it falls anywhere, whatever the base is doing.
Outliers that gather where the input is strongest are the model's error under strong motion
(a shake-table IMU's residual during an earthquake's strong phase matched the pattern 200
times), so a set of glitches whose local input level ranks high (a one-sided test of the
mean rank, ``FOLLOWS_ALPHA``) is not named, nor is a glitch a clipped input sample can reach
(the input is named instead). A glitch is also one sensor's alone: outliers that other
sensors show at the same moment (within ``SHARED_WINDOW`` samples, ``|lambda| > SHARED_LEVEL``)
more often than at random moments (binomial test, ``FOLLOWS_ALPHA``) are the structure's --
the impacts of a joint with clearance, which the F-16's wing-payload joint has -- not a fault.

Both kinds are fixed as clipping is: the samples are treated as missing, filled by the
model's one-step prediction and left out of every error.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import fftconvolve, lfilter
from scipy.special import ndtr, ndtri
from scipy.stats import median_abs_deviation

from armaxmodal.diagnosis.clipping import clipped_mask
from armaxmodal.prepare.quality import STUCK_MIN_RUN, stuck_runs  # noqa: F401  (shared with the pre-fit check

__all__ = [
    "stuck_runs",
    "glitches",
    "glitch_p",
    "follows_excitation",
    "shared_by_others",
    "outlier_scores",
    "input_rail_reach",
    "FAULT_ALPHA",
]

#: Uncorrected level at which a run or a glitch enters a fault's mask.
FAULT_ALPHA = 1e-3
#: Most glitches taken from one channel (a channel with more is broken, not glitching).
MAX_GLITCHES = 200
#: Level of the test that glitches gather where the input is strongest.
FOLLOWS_ALPHA = 0.01
#: Share of the impulse response's energy kept in the matched filter.
PI_ENERGY = 0.999
#: Another sensor's outlier within this many samples of a glitch counts as the same event.
SHARED_WINDOW = 3
#: |lambda| above which another sensor's residual counts as an outlier there.
SHARED_LEVEL = 3.0


def _matched_filter(model) -> np.ndarray:
    """``pi``: the impulse response of ``A / C``, cut where it holds PI_ENERGY of its energy."""
    pi = lfilter(model.a, model.c, np.r_[1.0, np.zeros(511)])
    keep = int(np.searchsorted(np.cumsum(pi**2) / np.sum(pi**2), PI_ENERGY)) + 1
    return pi[:keep]


def outlier_scores(eps: np.ndarray, model, mask: np.ndarray) -> np.ndarray:
    """``|lambda(t)|`` of one channel's one-step residual ``eps`` (n,), zero outside ``mask``."""
    pi = _matched_filter(model)
    e = np.where(mask, eps, 0.0)
    sigma = float(median_abs_deviation(eps[mask], scale="normal"))
    lam = fftconvolve(e, pi[::-1], mode="full")[pi.size - 1 :] / (sigma * float(np.sqrt(pi @ pi)))
    return np.where(mask, np.abs(lam), 0.0)


def shared_by_others(samples: list[int], others: np.ndarray) -> float:
    """p that ``samples`` meet another sensor's outlier no more often than random moments do:
    ``others`` (n, K-1) are the other sensors' :func:`outlier_scores`; a hit is any of them
    above ``SHARED_LEVEL`` within ``SHARED_WINDOW`` samples. One-sided binomial test against
    the hit rate over all samples; 1 for fewer than three samples or no other sensor."""
    from scipy.ndimage import maximum_filter1d
    from scipy.stats import binom

    if len(samples) < 3 or others.size == 0:
        return 1.0
    near = maximum_filter1d(others.max(axis=1), 2 * SHARED_WINDOW + 1) > SHARED_LEVEL
    rate = float(np.mean(near))
    hits = int(np.count_nonzero(near[samples]))
    return float(binom.sf(hits - 1, len(samples), rate)) if hits else 1.0


def glitches(eps: np.ndarray, model, mask: np.ndarray, alpha: float = FAULT_ALPHA):
    """Additive outliers in one channel's one-step residual ``eps`` (n,), counted where
    ``mask``: ``(samples, sizes, largest |lambda|)``; sizes in the channel's units."""
    pi = _matched_filter(model)
    e = np.where(mask, eps, 0.0)
    sigma = float(median_abs_deviation(eps[mask], scale="normal"))
    norm = float(np.sqrt(pi @ pi))
    n = int(mask.sum())
    bound = float(ndtri(1 - alpha / (2 * n)))
    found, sizes, largest = [], [], 0.0
    for _ in range(MAX_GLITCHES):
        lam = fftconvolve(e, pi[::-1], mode="full")[pi.size - 1 :] / (sigma * norm)
        lam[~mask] = 0.0
        t0 = int(np.argmax(np.abs(lam)))
        largest = max(largest, abs(float(lam[t0])))
        if abs(lam[t0]) < bound:
            break
        w = lam[t0] * sigma / norm  # least-squares size of the glitch
        stop = min(e.size, t0 + pi.size)
        e[t0:stop] -= w * pi[: stop - t0]
        found.append(t0)
        sizes.append(float(w))
    return found, sizes, largest


def glitch_p(largest: float, n: int) -> float:
    """Bonferroni p of the largest ``|lambda|`` over ``n`` samples."""
    return float(min(1.0, 2 * n * ndtr(-largest)))


def follows_excitation(samples: list[int], u: np.ndarray, fs: float) -> float:
    """p that ``samples`` sit where the input's 1 s moving RMS ranks no higher than anywhere
    else (one-sided, the mean of uniform ranks against its normal approximation); 1 for fewer
    than three samples."""
    if len(samples) < 3:
        return 1.0
    width = max(int(round(fs)), 1)
    level = np.sqrt(np.convolve(u**2, np.ones(width) / width, mode="same"))
    ranks = (np.argsort(np.argsort(level)) + 0.5) / level.size
    z = (float(np.mean(ranks[samples])) - 0.5) / np.sqrt(1 / (12 * len(samples)))
    return float(ndtr(-z))


def input_rail_reach(u: np.ndarray, model, lag: int = 0) -> np.ndarray:
    """Samples of an output (n,) bool that a clipped input sample can spoil: an input held at
    its rail while the base moved on spoils the output from ``nk`` to ``nk + nb`` samples later,
    and the predictor carries that on for the length of ``A / C``'s impulse response. Residual
    outliers there are the input's clipping (named on the input), not a fault of the sensor.
    ``lag``: the output's shift, samples (its residual is in the shifted frame)."""
    u = np.asarray(u, float).reshape(len(u), -1)[:, 0]
    rails = np.flatnonzero(clipped_mask(u))
    reach = np.zeros(u.size + 1, int)
    first = rails + model.nk - lag
    stop = first + model.b.shape[1] + _matched_filter(model).size - 1  # B's taps, then pi's
    np.add.at(reach, np.clip(first, 0, u.size), 1)
    np.add.at(reach, np.clip(stop, 0, u.size), -1)
    return np.cumsum(reach)[:-1] > 0
