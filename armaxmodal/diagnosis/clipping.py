"""Clipping: samples piled up at a channel's rail, found by a count test and fixed by
leaving them out of every error and filling them from the model.

The fix treats the rail samples as missing: each is replaced by the model's one-step
prediction from the samples before it (its innovation set to zero, the ARMAX predictor's
treatment of a missing observation), the model is refitted to the filled record, and the
fill repeated -- the expectation-maximisation idea, a few passes. Filling with the noise-free
simulated response instead leaves the predictor a past without its noise after every
clipped run: a supine ride clipped at 60 % of its peak then read as a quadratic spring.

A channel that stays within its range visits its extreme value about as often as the values
just inside it (once each for continuous data, a few times for a coarse quantiser). A sensor
or recorder that saturates piles every sample beyond its range onto one value. The test
counts the samples at each rail and compares them with the mean count of the
``NEIGHBOUR_LEVELS`` distinct values just inside it: Poisson, so the p-value is
``P(N >= k | lambda)`` (``armaxmodal.prepare.quality.rail_pileup``, which the pre-fit warning
uses too, at a stricter p: it is one test of many, this one is corrected for them).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from armaxmodal._kernels import JIT_OPTIONS
from armaxmodal.prepare.quality import NEIGHBOUR_LEVELS, rail_pileup

__all__ = ["rail_pileup", "clipped_mask", "fill_by_prediction", "IMPUTE_PASSES", "NEIGHBOUR_LEVELS"]

#: Uncorrected p below which a rail's samples are treated as clipped by the fix.
RAIL_ALPHA = 1e-3
#: Refit-and-fill passes of the fix (the filled values settle in two or three).
IMPUTE_PASSES = 3


def clipped_mask(x: np.ndarray, alpha: float = RAIL_ALPHA) -> np.ndarray:
    """Samples of ``x`` at a rail whose pile-up is significant at ``alpha``, (n,) bool."""
    mask = np.zeros(x.size, bool)
    for value, _, _, p in rail_pileup(x):
        if p < alpha:
            mask |= x == value
    return mask


def fill_by_prediction(y: np.ndarray, u: np.ndarray, model, missing: np.ndarray) -> np.ndarray:
    """``y`` with each ``missing`` sample replaced by ``model``'s one-step prediction.

    Parameters
    ----------
    y : (n,) ndarray
        One output, less any modelled disturbance.
    u : (n, n_in) ndarray
        The model's inputs.
    model : ArmaxModel
    missing : (n,) bool ndarray

    Returns
    -------
    (n,) ndarray
        The filled output; the prediction errors of the filled samples are zero.
    """
    u = np.ascontiguousarray(np.asarray(u, float).reshape(y.size, -1).T)
    return _fill(np.asarray(y, float).copy(), u, model.a, model.b, model.nk, model.c, missing.astype(np.bool_))


@njit(**JIT_OPTIONS)
def _fill(y, u, a, b, nk, c, missing):
    """The ARMAX predictor run forward, writing its prediction over each missing sample
    (innovation zero there); out-of-record regressors count as zero."""
    n = y.size
    n_in, nb = b.shape
    eps = np.zeros(n)
    for t in range(n):
        pred = 0.0
        for i in range(1, a.size):
            if t - i >= 0:
                pred -= a[i] * y[t - i]
        for m in range(n_in):
            for j in range(nb):
                lag = t - nk - j
                if 0 <= lag < n:
                    pred += b[m, j] * u[m, lag]
        for i in range(1, c.size):
            if t - i >= 0:
                pred += c[i] * eps[t - i]
        if missing[t]:
            y[t] = pred
        else:
            eps[t] = y[t] - pred
    return y
