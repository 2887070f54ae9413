"""Where a fit starts: Hannan-Rissanen (a long ARX model, then least squares on its residuals),
Steiglitz-McBride and a subspace estimate of the shared A, and the output-error start.
"""

from __future__ import annotations

import numpy as np

from armaxmodal._kernels import armax_residual, inverse_filter, lagged_cross, lagged_gram
from armaxmodal.estimate._gauss_newton import (
    columns,
    signals,
    solve,
)
from armaxmodal.estimate.parameters import (
    project_shared_stable,
    project_stable,
    shared_index,
    stable_a,
    stable_c,
    unpack_theta,
)


# -- initial estimate ------------------------------------------------------------------------
def _arx_residual(y, uT, n_h, nb_h, nk, t1):
    """High-order ARX by least squares; returns its residuals (innovation estimates)."""
    n_in = uT.shape[0]
    t0 = max(n_h, nk + nb_h - 1, 0)
    sig = signals(y, uT, np.zeros(y.size))
    cols = columns(n_h, nb_h, 0, nk, n_in)
    g_mat = lagged_gram(sig, *cols, t0, t1)
    g_vec = lagged_cross(sig, *cols, y, t0, t1)
    theta = solve(g_mat, g_vec)
    a, b, c = unpack_theta(theta, n_h, nb_h, 0, n_in)
    return armax_residual(y, uT, a, b, nk, c)


def _initial_columns_and_signals(y, uT, na, nb, nc, nk, t1):
    n = y.size
    n_h = int(min(max(2 * (na + nc), 20), max(na + nc + 1, (t1 - nk) // 20)))
    e_hat = _arx_residual(y, uT, n_h, nb + n_h // 2, nk, t1) if nc > 0 else np.zeros(n)
    return signals(y, uT, e_hat), columns(na, nb, nc, nk, uT.shape[0])


def hannan_rissanen(y, uT, na, nb, nc, nk, t0, t1):
    sig, cols = _initial_columns_and_signals(y, uT, na, nb, nc, nk, t1)
    theta = solve(lagged_gram(sig, *cols, t0, t1), lagged_cross(sig, *cols, y, t0, t1))
    return project_stable(theta, na, nb, nc, uT.shape[0])


def lagged_sum(uT, b, nk):
    """``sum_m sum_j b[m, j] u_m[t - nk - j]`` for t in [0, n), zero outside the record."""
    n = uT.shape[1]
    out = np.zeros(n)
    for u_m, b_m in zip(uT, b, strict=True):
        full = np.convolve(u_m, b_m)  # full[i] = sum_j b_m[j] u_m[i - j]
        lo, hi = max(nk, 0), min(n, full.size + nk)
        if hi > lo:
            out[lo:hi] += full[lo - nk : hi - nk]
    return out


def _steiglitz_mcbride(ys, uT, a0, na, nb, nk, t0, t1, iterations=6):
    """Output-error start: shared A and per-sensor B by iterated prefiltering with 1/A.

    Each pass solves ``min sum_k w_k |A (y_k / A_prev) - B_k (u / A_prev)|^2`` by linear least
    squares; at the fixed point this is the output-error estimate, the maximum-likelihood
    fit for white sensor noise. Returns ``(a, [b_k])``.
    """
    n_in = uT.shape[0]
    n_out = len(ys)
    cols = columns(na, nb, 0, nk, n_in)
    p_k = n_in * nb
    a = stable_a(a0)
    weights = np.ones(n_out)
    bs = [np.zeros(p_k)] * n_out
    zeros = np.zeros(uT.shape[1])
    for it in range(iterations):
        g_mat = np.zeros((na + n_out * p_k,) * 2)
        g_vec = np.zeros(na + n_out * p_k)
        # every output and the input through the shared 1/A in one pass (u / A once, not
        # once per sensor)
        filtered = inverse_filter(np.ascontiguousarray(np.vstack([np.vstack(ys), uT])), a)
        if it > 0:
            # reweight by each sensor's output-error residual variance under the previous
            # pass's (A, B_k): y_k - B_k (u / A), which is (A y_k - B_k u) / A without a
            # recursion per sensor
            for k, yk in enumerate(ys):
                e = yk - lagged_sum(filtered[n_out:], bs[k].reshape(n_in, -1), nk)
                weights[k] = 1.0 / max(float(np.var(e[t0:t1])), 1e-300)
        for k in range(n_out):
            sig = signals(filtered[k], filtered[n_out:], zeros)
            idx = np.concatenate([np.arange(na), na + k * p_k + np.arange(p_k)])
            g_mat[np.ix_(idx, idx)] += weights[k] * lagged_gram(sig, *cols, t0, t1)
            g_vec[idx] += weights[k] * lagged_cross(sig, *cols, sig[0], t0, t1)
        theta = solve(g_mat, g_vec)
        a_new = stable_a(np.concatenate([[1.0], theta[:na]]))
        bs = [theta[na + k * p_k : na + (k + 1) * p_k] for k in range(n_out)]
        done = np.max(np.abs(a_new - a)) < 1e-4  # a start only: PEM does the rest
        a = a_new
        if done:
            break
    return a, bs


def _subspace_a(ys, uT, na):
    """Monic A(z) of order na from PO-MOESP on all outputs at once (shared poles).

    Past inputs and outputs instrument the future outputs; the column space of the
    projected block Hankel matrix is the extended observability matrix, whose shift
    invariance gives the state matrix. Non-iterative, so it cannot crawl. The block-Hankel
    rows are lagged copies of u and y, so the LQ factor is computed as the Cholesky factor
    of their lagged Gram matrix: O(N p) time and O(p^2) memory instead of a tall QR.
    """
    n_in, n_out = uT.shape[0], len(ys)
    i = max(-(-na // n_out) + 2, 2 * -(-na // n_out), 6)
    sig = np.ascontiguousarray(np.vstack([uT, np.vstack(ys)]))
    n_sig = n_in + n_out
    # kernel column order: each signal with lags 0..2i-1
    col_sig = np.repeat(np.arange(n_sig), 2 * i).astype(np.int64)
    col_lag = np.tile(np.arange(2 * i), n_sig).astype(np.int64)
    gram = lagged_gram(sig, col_sig, col_lag, np.ones(col_sig.size), 2 * i - 1, sig.shape[1])

    def rows(signals, lags):  # Hankel block j of signal s sits at lag 2i-1-j
        return [s * 2 * i + lag for lag in lags for s in signals]

    inputs, outputs = range(n_in), range(n_in, n_sig)
    future, past = [i - 1 - j for j in range(i)], [2 * i - 1 - j for j in range(i)]
    order = rows(inputs, future) + rows(inputs, past) + rows(outputs, past) + rows(outputs, future)
    g = gram[np.ix_(order, order)] / (sig.shape[1] - 2 * i + 1)
    low = np.linalg.cholesky(g + 1e-12 * np.trace(g) / g.shape[0] * np.eye(g.shape[0]))
    mi, li = n_in * i, n_out * i
    l42 = low[2 * mi + li :, mi : 2 * mi + li]
    left, sv, _ = np.linalg.svd(l42, full_matrices=False)
    gamma = left[:, :na] * np.sqrt(sv[:na])
    a_ss = np.linalg.lstsq(gamma[:-n_out], gamma[n_out:], rcond=None)[0]
    return stable_a(np.real(np.poly(np.linalg.eigvals(a_ss))))


def output_error_start(ys, uT, theta_hr, na, nb, nc, nk, t0, t1):
    """Parameter vector [a, b_1, c_1, ...]: subspace poles refined by Steiglitz-McBride,
    with C = A where the orders allow (white sensor noise)."""
    n_in = uT.shape[0]
    p_k = n_in * nb + nc
    a, bs = _steiglitz_mcbride(ys, uT, _subspace_a(ys, uT, na), na, nb, nk, t0, t1)
    c = stable_c(a[: nc + 1] if nc <= na else np.concatenate([a, np.zeros(nc - na)]))[1:]
    parts = [a[1:]]
    for k in range(len(ys)):
        hr_c = theta_hr[na + k * p_k + n_in * nb : na + (k + 1) * p_k]
        parts += [bs[k], c if nc == na else hr_c]
    return np.concatenate(parts)


def shared_start(ys, uT, na, nb, nc, nk, t0, t1, oe, evaluate):
    """The more likely of a joint Hannan-Rissanen and a subspace/Steiglitz-McBride start:
    ``(theta, state, losses)``."""
    n_out, n_in = len(ys), uT.shape[0]
    p_k = n_in * nb + nc
    cols = columns(na, nb, nc, nk, n_in)
    # Joint Hannan-Rissanen start, each sensor weighted by its ARX innovation variance.
    p = na + n_out * p_k
    g_mat = np.zeros((p, p))
    g_vec = np.zeros(p)
    for k in range(n_out):
        sig, _ = _initial_columns_and_signals(ys[k], uT, na, nb, nc, nk, t1)
        w = 1.0 / max(float(np.var(sig[-1, t0:t1])) if nc else float(np.var(ys[k][t0:t1])), 1e-300)
        idx = shared_index(k, na, p_k)
        g_mat[np.ix_(idx, idx)] += w * lagged_gram(sig, *cols, t0, t1)
        g_vec[idx] += w * lagged_cross(sig, *cols, ys[k], t0, t1)
    theta = project_shared_stable(solve(g_mat, g_vec), na, nb, nc, n_in, n_out, oe)

    state, losses = evaluate(theta)
    # Second start: output error by Steiglitz-McBride; keep whichever is more likely. A
    # degenerate input (one sinusoid) can leave the subspace step without a Cholesky factor,
    # and at very high orders its iterations can diverge to non-finite values (ValueError
    # from the factorisation): then the first start stands alone.
    try:
        alt = project_shared_stable(
            output_error_start(ys, uT, theta, na, nb, nc, nk, t0, t1), na, nb, nc, n_in, n_out, oe
        )
    except (np.linalg.LinAlgError, ValueError):
        alt = None
    if alt is not None:
        state_alt, losses_alt = evaluate(alt)
        if np.sum(np.log(losses_alt)) < np.sum(np.log(losses)):
            theta, state, losses = alt, state_alt, losses_alt
    return theta, state, losses
