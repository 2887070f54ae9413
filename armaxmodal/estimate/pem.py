"""The prediction-error loops: one sensor's model, or every sensor sharing A, by
Levenberg-Marquardt on the kernels' normal equations, weighted by each sensor's noise
variance; the covariance of the shared fit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from armaxmodal._kernels import armax_residual
from armaxmodal.estimate._gauss_newton import (
    Dense,
    Progress,
    columns,
    inverse,
    levenberg_marquardt,
    normal_equations,
    shared_normal_equations,
    workspace,
)
from armaxmodal.estimate.parameters import (
    local_parameters,
    project_shared_stable,
    project_stable,
    shared_index,
    unpack_theta,
)
from armaxmodal.estimate.starts import hannan_rissanen, output_error_start, shared_start


# -- single-output PEM ------------------------------------------------------------------------
def residual_and_loss(y, uT, theta, na, nb, nc, nk, t0, t1, oe=False):
    a, b, c = unpack_theta(theta, na, nb, nc, uT.shape[0])
    if oe:  # output error: C = A, so eps = y - (B / A) u
        c = a
    eps = armax_residual(y, uT, a, b, nk, c)
    with np.errstate(over="ignore", invalid="ignore"):  # an unstable trial step is rejected
        loss = float(eps[t0:t1] @ eps[t0:t1])
    return eps, (loss if np.isfinite(loss) else np.inf), c


def fit_single(y, uT, na, nb, nc, nk, t0, t1, max_iter, tol, oe=False, theta0=None, stop="expected"):
    n_in = uT.shape[0]
    cols = columns(na, nb, nc, nk, n_in)
    if theta0 is not None:
        theta = project_stable(theta0, na, nb, nc, n_in, oe)
    else:
        theta = hannan_rissanen(y, uT, na, nb, nc, nk, t0, t1)
    if oe and theta0 is None:
        try:
            theta = project_stable(
                output_error_start([y], uT, theta, na, nb, nc, nk, t0, t1), na, nb, nc, n_in, oe=True
            )
        except np.linalg.LinAlgError:  # degenerate input: keep the Hannan-Rissanen start
            theta = project_stable(theta, na, nb, nc, n_in, oe=True)

    def evaluate(th):
        state = residual_and_loss(y, uT, th, na, nb, nc, nk, t0, t1, oe)
        return state, state[1]

    work = workspace(n_in, y.size)

    def linearise(state):
        return Dense(*normal_equations(y, uT, state[0], state[2], cols, t0, t1, oe, work))

    state, _ = evaluate(theta)
    unit = state[1] / (t1 - t0)  # 2 log L = -N log V: a unit is a change of V by V / N
    theta, state, it, converged, _ = levenberg_marquardt(
        theta,
        state,
        evaluate,
        linearise,
        lambda th: project_stable(th, na, nb, nc, n_in, oe),
        max_iter,
        tol,
        stop,
        unit,
    )
    eps, loss, c = state
    g_mat, _ = normal_equations(y, uT, eps, c, cols, t0, t1, oe)
    n_eff = t1 - t0
    p = theta.size
    lam = loss / max(n_eff - p, 1)
    cov = lam * inverse(g_mat)
    return theta, {
        "loss": loss / n_eff,
        "noise_variance": lam,
        "iterations": it,
        "converged": converged,
        "covariance": cov,
    }


def merge_single_info(info):
    return {
        "loss": np.array([i["loss"] for i in info]),
        "noise_variance": np.array([i["noise_variance"] for i in info]),
        "iterations": np.array([i["iterations"] for i in info]),
        "converged": np.array([i["converged"] for i in info]),
        "covariance": [i["covariance"] for i in info],
    }


@dataclass(frozen=True)
class _Checkpoint:
    """Where a shared-pole fit stopped: enough to continue it bit for bit as if its
    iteration cap had been higher (``fit_resumable(..., resume=)``). The sweep continues the delay
    choice's short fits instead of starting them again."""

    theta: np.ndarray
    variances: np.ndarray  # the noise variances weighting the next iterations
    iterations: int  # done before the Levenberg-Marquardt run in progress
    progress: Progress | None  # that run's state; None between runs
    converged: bool  # stopped by the rule: nothing is left to do


def fit_shared(y, uT, na, nb, nc, nk, t0, t1, max_iter, tol, oe=False, theta0=None, stop="expected", resume=None):
    """Joint maximum likelihood with per-sensor noise variances.

    Alternates a weighted least-squares Levenberg-Marquardt solve at fixed variances
    (a true Gauss-Newton problem, so it converges fast) with the variance update
    ``lambda_k = V_k / N``; at the fixed point this maximises the concentrated likelihood
    ``-N/2 sum_k log V_k``. Gauss-Newton on ``sum_k log V_k`` directly would drop a Hessian
    term that does not vanish at the optimum and crawl. ``resume`` (a :class:`_Checkpoint`)
    continues a fit instead of starting one. Returns ``(thetas, info, checkpoint)``; ``info``
    lacks the covariances, which :func:`shared_covariance` adds.
    """
    n_out = y.shape[1]
    n_in = uT.shape[0]
    p_k = n_in * nb + nc
    cols = columns(na, nb, nc, nk, n_in)
    ys = [np.ascontiguousarray(y[:, k]) for k in range(n_out)]
    n_eff = t1 - t0

    def evaluate(th):
        out = [
            residual_and_loss(ys[k], uT, local_parameters(th, k, na, p_k), na, nb, nc, nk, t0, t1, oe)
            for k in range(n_out)
        ]
        return out, np.array([o[1] for o in out])

    if resume is not None:
        theta, variances, total_iterations = resume.theta, resume.variances, resume.iterations
        progress, converged = resume.progress, resume.converged
        state, losses = evaluate(theta)
    else:
        if theta0 is not None:
            theta = project_shared_stable(theta0, na, nb, nc, n_in, n_out, oe)
            state, losses = evaluate(theta)
        else:
            theta, state, losses = shared_start(ys, uT, na, nb, nc, nk, t0, t1, oe, evaluate)
        variances, total_iterations, progress, converged = losses / n_eff, 0, None, False
    paused = None
    work = workspace(n_in, y.shape[0])  # the normal equations' arrays, reused at every step
    while not converged and total_iterations < max_iter:
        weights = 1.0 / variances

        def weighted(th, weights=weights):
            per_sensor, losses_t = evaluate(th)
            with np.errstate(invalid="ignore", over="ignore"):  # an unstable trial (inf loss) is rejected
                return (per_sensor, losses_t), float(weights @ losses_t)

        def linearise(st, variances=variances):
            return shared_normal_equations(ys, uT, st[0], variances, cols, na, p_k, t0, t1, oe, work)

        theta, (state, losses), used, inner_converged, progress = levenberg_marquardt(
            theta,
            (state, losses),
            weighted,
            linearise,
            lambda th: project_shared_stable(th, na, nb, nc, n_in, n_out, oe),
            max_iter - total_iterations,
            tol,
            stop,
            1.0,  # the objective sum_k V_k / lambda_k changes with 2 log L one for one
            progress,
        )
        if progress is not None:  # the cap stopped this run mid-way: continue it from here
            paused = _Checkpoint(theta, variances, total_iterations, progress, False)
            progress = None
        total_iterations += used
        new_variances = losses / n_eff
        settled = np.max(np.abs(new_variances / variances - 1.0)) < 1e-3
        variances = new_variances
        converged = inner_converged and settled
    checkpoint = paused or _Checkpoint(theta, variances, total_iterations, None, converged)
    info = {
        "loss": losses / n_eff,
        "noise_variance": losses / max(n_eff - (na / n_out + p_k), 1),
        "iterations": np.full(n_out, total_iterations),
        "converged": np.full(n_out, converged),
        "state": state,
    }
    return [local_parameters(theta, k, na, p_k) for k in range(n_out)], info, checkpoint


def shared_covariance(y, uT, na, nb, nc, nk, t0, t1, info, oe=False):
    """Add the joint and per-sensor covariances to a shared fit's ``info`` (in place)."""
    n_out, p_k = y.shape[1], uT.shape[0] * nb + nc
    ys = [np.ascontiguousarray(y[:, k]) for k in range(n_out)]
    cols = columns(na, nb, nc, nk, uT.shape[0])
    lam = info["noise_variance"]
    joint = inverse(shared_normal_equations(ys, uT, info.pop("state"), lam, cols, na, p_k, t0, t1, oe).full())
    info["covariance"] = [joint[np.ix_(shared_index(k, na, p_k), shared_index(k, na, p_k))] for k in range(n_out)]
    info["joint_covariance"] = joint
