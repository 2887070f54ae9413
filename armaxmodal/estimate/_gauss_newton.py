"""The Gauss-Newton machinery of the prediction-error fits: regressor layout, the normal
equations with their exact gradient (regressors filtered through 1/C; output error: the
simulated output through 1/A), the block-arrow system of the shared-pole form solved by its
Schur complement, and the Levenberg-Marquardt loop every fit runs.

Kept apart from :mod:`armaxmodal.estimate.fit` (starts, parameter handling, the public wrapper) so
that its tests -- finite differences against every gradient and Gauss-Newton matrix, the
Schur solve against the dense one (``tests/test_guards.py``, ``tests/test_fit.py``) -- and a
mutation run can cover it on their own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.linalg

from armaxmodal._kernels import inverse_filter_into, lagged_cross, lagged_gram
from armaxmodal.exceptions import OrderError

# A crawl: CRAWL_STEPS Gauss-Newton steps in a row (Levenberg-Marquardt damping at its
# floor) each raising 2 log-likelihood by less than CRAWL_LOGLIK, i.e. moving the parameters
# by about sqrt(0.01) = 0.1 standard error. An over-parameterised ARMAX model (near pole-zero
# cancellations) has normal equations conditioned beyond 1e10: the undamped step promises a
# gain along directions the data do not determine, and the floor-damped steps, each
# delivering exactly its prediction, crawl there. On the bench chain (20,000 x 5, na = 10)
# 84 steps of 0.004 each moved the modes by 0.001 Hz (under 0.01 standard error) and ended
# at the iteration cap; a fit recovering from a large damping instead has growing steps.
CRAWL_LOGLIK = 0.01
CRAWL_STEPS = 3
_LM_FLOOR = 1e-10


def columns(na, nb, nc, nk, n_in):
    """Regressor columns as (signal, lag, sign) over the rows of :func:`signals`."""
    sig = [0] * na + [1 + m for m in range(n_in) for _ in range(nb)] + [n_in + 1] * nc
    lag = list(range(1, na + 1)) + [nk + j for _ in range(n_in) for j in range(nb)] + list(range(1, nc + 1))
    sign = [-1.0] * na + [1.0] * (n_in * nb) + [1.0] * nc
    return np.array(sig, np.int64), np.array(lag, np.int64), np.array(sign)


def signals(y, uT, e):
    """Rows [y, u_1 .. u_m, e] for the lagged-regressor kernels."""
    return np.ascontiguousarray(np.vstack([y[None, :], uT, e[None, :]]))


def _damped(g_mat, damping):
    """Levenberg-Marquardt damping scaled by the diagonal, plus a tiny ridge for round-off.

    Non-finite normal equations mean the fit has broken down numerically (orders far above
    what the record supports): an :class:`OrderError` here, not a traceback from LAPACK."""
    if not np.all(np.isfinite(g_mat)):
        raise OrderError(
            "the fit's normal equations became non-finite: the model orders are far above what this record "
            "supports (or the data are degenerate). Lower the orders."
        )
    d = g_mat.diagonal().copy()
    d[d <= 0] = 1.0
    out = g_mat.copy()
    out.flat[:: g_mat.shape[0] + 1] += damping * d + 1e-13 * d  # no second full matrix for the diagonal
    return out


# LAPACK's Cholesky factor and solve, called directly. These are the routines scipy's
# cho_factor and cho_solve call, with the same arguments, so the numbers are the same; their
# argument checks and copies took a third of a one-sensor fit (about 34 solves of a 21 x 21
# system per fit, 70 us of wrapper around 5 us of LAPACK each).
_POTRF, _POTRS = scipy.linalg.get_lapack_funcs(("potrf", "potrs"), (np.zeros((1, 1)),))


def cholesky(lhs: np.ndarray) -> np.ndarray:
    """Upper Cholesky factor of a finite symmetric matrix (float64); LinAlgError when it is
    not positive definite."""
    factor, info = _POTRF(lhs, lower=False, overwrite_a=False, clean=False)
    if info != 0:
        raise np.linalg.LinAlgError(f"the matrix is not positive definite (LAPACK potrf info {info})")
    return factor


def cho_solve(factor: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Solve with an upper Cholesky factor from :func:`cholesky`."""
    x, info = _POTRS(factor, rhs, lower=False, overwrite_b=False)
    if info != 0:
        raise ValueError(f"illegal argument {-info} of LAPACK potrs")
    return x


def solve(g_mat, g_vec, damping=0.0):
    lhs = _damped(g_mat, damping)
    try:
        return cho_solve(cholesky(lhs), g_vec)
    except np.linalg.LinAlgError:
        return np.linalg.lstsq(lhs, g_vec, rcond=None)[0]


def inverse(g_mat):
    try:
        return cho_solve(cholesky(g_mat), np.eye(g_mat.shape[0]))
    except np.linalg.LinAlgError:
        return np.linalg.pinv(g_mat)


def workspace(n_in: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Arrays :func:`normal_equations` fills at every step: the stacked signals and their
    filtered copies, ``(n_in + 2, n)`` each. A fit keeps one pair for all its steps: fresh
    record-length arrays at every step cost fresh pages on records of millions of samples."""
    return np.empty((n_in + 2, n)), np.empty((n_in + 2, n))


def normal_equations(y, uT, eps, c, cols, t0, t1, oe=False, work=None):
    """Gauss-Newton matrix and gradient; ``work`` (from :func:`workspace`) is overwritten."""
    stacked, filtered = work if work is not None else workspace(uT.shape[0], y.size)
    # Output error: d eps / d a_i is the simulated output y - eps, filtered by 1/A, lagged.
    stacked[0] = y - eps if oe else y
    stacked[1:-1] = uT
    stacked[-1] = eps
    inverse_filter_into(stacked, c, filtered)
    return lagged_gram(filtered, *cols, t0, t1), lagged_cross(filtered, *cols, eps, t0, t1)


@dataclass
class Dense:
    """Normal equations ``H step = gradient`` of a single-output fit."""

    hessian: np.ndarray
    gradient: np.ndarray

    def solve(self, damping: float = 0.0) -> np.ndarray:
        return solve(self.hessian, self.gradient, damping)

    def curvature(self, step: np.ndarray) -> float:
        """``step' H step``."""
        return float(step @ self.hessian @ step)


@dataclass
class _Arrow:
    """Block-arrow normal equations of the shared-pole fit: the A block couples to every
    sensor's (B, C) block; sensors do not couple to each other."""

    aa: np.ndarray
    ab: list
    bb: list
    ga: np.ndarray
    gb: list

    def solve(self, damping: float = 0.0) -> np.ndarray:
        """LM step by the Schur complement on the A block: K small factorisations instead
        of one of the full size (20x fewer flops at high orders)."""

        schur = _damped(self.aa, damping)
        rhs = self.ga.copy()
        parts = []
        for ab, bb, gb in zip(self.ab, self.bb, self.gb, strict=True):
            try:
                factor = cholesky(_damped(bb, damping))
                x, y = cho_solve(factor, ab.T), cho_solve(factor, gb)
            except np.linalg.LinAlgError:
                x = np.linalg.lstsq(_damped(bb, damping), ab.T, rcond=None)[0]
                y = np.linalg.lstsq(_damped(bb, damping), gb, rcond=None)[0]
            schur -= ab @ x
            rhs -= ab @ y
            parts.append((x, y))
        step_a = solve(schur, rhs)
        return np.concatenate([step_a] + [y - x @ step_a for x, y in parts])

    @property
    def gradient(self) -> np.ndarray:
        return np.concatenate([self.ga, *self.gb])

    def curvature(self, step: np.ndarray) -> float:
        """``step' H step`` without forming H."""
        na, p_k = self.aa.shape[0], self.bb[0].shape[0]
        sa = step[:na]
        total = sa @ self.aa @ sa
        for k, (ab, bb) in enumerate(zip(self.ab, self.bb, strict=True)):
            sb = step[na + k * p_k : na + (k + 1) * p_k]
            total += 2.0 * sa @ ab @ sb + sb @ bb @ sb
        return float(total)

    def full(self) -> np.ndarray:
        na, p_k = self.aa.shape[0], self.bb[0].shape[0]
        out = np.zeros((na + len(self.bb) * p_k,) * 2)
        out[:na, :na] = self.aa
        for k, (ab, bb) in enumerate(zip(self.ab, self.bb, strict=True)):
            sl = slice(na + k * p_k, na + (k + 1) * p_k)
            out[:na, sl], out[sl, :na], out[sl, sl] = ab, ab.T, bb
        return out


def shared_normal_equations(ys, uT, state, variances, cols, na, p_k, t0, t1, oe=False, work=None):
    aa, ga = np.zeros((na, na)), np.zeros(na)
    ab, bb, gb = [], [], []
    work = work if work is not None else workspace(uT.shape[0], ys[0].size)  # one pair for every sensor
    for k, (eps, _, c) in enumerate(state):
        gk, vk = normal_equations(ys[k], uT, eps, c, cols, t0, t1, oe, work)
        gk, vk = gk / variances[k], vk / variances[k]
        aa += gk[:na, :na]
        ga += vk[:na]
        ab.append(gk[:na, na:])
        bb.append(gk[na:, na:])
        gb.append(vk[na:])
    return _Arrow(aa, ab, bb, ga, gb)


@dataclass(frozen=True)
class Progress:
    """Where a Levenberg-Marquardt run stood when its iteration cap stopped it: the
    damping, its growth factor, the crawl count and the iterations done. Passed back in,
    the run continues exactly as if the cap had been higher."""

    damping: float = 1e-4
    grow: float = 2.0
    crawling: int = 0
    iterations: int = 0


def levenberg_marquardt(
    theta, state, evaluate, linearise, project, max_iter, tol, stop="expected", unit=None, progress=None
):
    """Levenberg-Marquardt on a Gauss-Newton model, shared by every fit.

    ``evaluate(theta) -> (state, objective)``; ``linearise(state)`` gives the normal
    equations: ``solve(damping)`` the damped Gauss-Newton step, ``gradient`` and
    ``curvature(step)``; ``project`` keeps the parameters admissible. The damping follows
    the gain ratio (Nielsen, 1999): where the Gauss-Newton model overshoots along a curved
    valley, as over-parameterised ARMAX models do, it grows instead of crawling at its floor.

    ``stop="expected"``: converged when the undamped Gauss-Newton step would lower the
    objective by less than ``tol`` (relative) -- the expected improvement, as MATLAB's pem.
    ``stop="decrease"``: when an accepted step lowered it by less than ``tol``; cheaper, but
    a damped step on a flat valley can stop it early (fine for placing poles in a sweep).
    Both also stop when no step at any damping lowers the objective: a minimum to numerical
    precision, or on the stability boundary kept for C. ``unit`` (the objective change that
    is one unit of 2 log-likelihood) adds the crawl rule: CRAWL_STEPS floor-damped steps in
    a row each worth less than CRAWL_LOGLIK units end the fit as converged. ``progress``
    (a :class:`Progress` this function returned at its cap, with the ``theta`` and ``state``
    it returned) continues that run; ``max_iter`` then counts its iterations too. Returns
    ``(theta, state, iterations, converged, progress)``; ``progress`` is None unless the cap
    stopped the run.
    """
    objective = evaluate(theta)[1]
    start = progress or Progress()
    lm, grow, crawling = start.damping, start.grow, start.crawling
    for it in range(start.iterations + 1, max_iter + 1):
        normal = linearise(state)
        if stop == "expected" and normal.solve(0.0) @ normal.gradient < tol * objective:
            return theta, state, it, True, None
        while lm < 1e10:
            step = normal.solve(lm)
            trial = project(theta + step)
            state_t, objective_t = evaluate(trial)
            if objective_t < objective:
                break
            lm, grow = lm * grow, grow * 2.0
        else:
            return theta, state, it, True, None
        gauss_newton = lm <= 10.0 * _LM_FLOOR
        predicted = 2.0 * step @ normal.gradient - normal.curvature(step)
        gain = (objective - objective_t) / predicted if predicted > 0 else 0.0
        lm, grow = max(lm * max(1 / 3, 1 - (2 * gain - 1) ** 3), _LM_FLOOR), 2.0
        decrease = (objective - objective_t) / objective
        small = unit is not None and gauss_newton and objective - objective_t < CRAWL_LOGLIK * unit
        crawling = crawling + 1 if small else 0
        theta, state, objective = trial, state_t, objective_t
        if (stop == "decrease" and decrease < tol) or crawling >= CRAWL_STEPS:
            return theta, state, it, True, None
    done = max(max_iter, start.iterations)
    return theta, state, done, False, Progress(lm, grow, crawling, done)
