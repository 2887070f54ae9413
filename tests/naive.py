"""Slow, obvious references for the numba kernels (see ``armaxmodal/_kernels.py``)."""

from __future__ import annotations

import numpy as np


def hold_recursion(phi, gam, u_pad, n_steps, stride):
    """Plain-Python ``x[k+1] = phi x[k] + gam @ u_pad[k:k+p]``, keeping every stride-th state."""
    p = gam.shape[1]
    x = np.zeros(phi.shape[0])
    kept = [x.copy()]
    for k in range(n_steps):
        x = phi @ x + gam @ u_pad[k : k + p]
        if (k + 1) % stride == 0:
            kept.append(x.copy())
    return np.array(kept)


def armax_residual(y, u, a, b, nk, c):
    """``(A y - q^-nk B u) / C`` with scipy.signal.lfilter and zero padding."""
    import scipy.signal

    n = y.size
    w = scipy.signal.lfilter(a, [1.0], y)
    for m in range(u.shape[0]):
        for j in range(b.shape[1]):
            lag = nk + j
            shifted = np.zeros(n)
            if 0 <= lag < n:
                shifted[lag:] = u[m, : n - lag]
            elif -n < lag < 0:
                shifted[: n + lag] = u[m, -lag:]
            w -= b[m, j] * shifted
    return scipy.signal.lfilter([1.0], c, w)


def inverse_filter(x, c):
    """Each row of x filtered by 1/C with scipy.signal.lfilter."""
    import scipy.signal

    return np.array([scipy.signal.lfilter([1.0], c, row) for row in x])


def lagged_design(sig, col_sig, col_lag, col_sign, t0, t1):
    """The explicit regressor matrix whose Gram the kernel computes, shape (t1 - t0, p)."""
    n = sig.shape[1]
    out = np.zeros((t1 - t0, col_sig.size))
    for c, (s, lag, sign) in enumerate(zip(col_sig, col_lag, col_sign, strict=True)):
        for t in range(t0, t1):
            k = t - lag
            out[t - t0, c] = sign * sig[s, k] if 0 <= k < n else 0.0
    return out


def max_root_radius_below(p, radius):
    """All roots of p strictly inside ``radius``, from numpy's companion-matrix roots."""
    return bool(np.all(np.abs(np.roots(p)) < radius))


def sdp_inner_cvxpy(lam, psi, allowed, mass_ratio_bounds=None):
    """The SDP inner problem stated in cvxpy (the modelling layer does the conic form).
    Returns (m, C, K) with m1 = 1, in the units of ``lam`` (not non-dimensionalised)."""
    import cvxpy as cp

    n = psi.shape[0]
    psi = psi / np.linalg.norm(psi, axis=0)
    w_ref = float(np.exp(np.mean(np.log(np.abs(lam)))))
    lam_s = lam / w_ref
    m = cp.Variable(n)
    c = cp.Variable((n, n), symmetric=True)
    k = cp.Variable((n, n), symmetric=True)
    cons = [m[0] == 1, m >= 0, c >> 0, k >> 1e-9 * np.eye(n)]
    if mass_ratio_bounds is not None:
        b = np.asarray(mass_ratio_bounds, dtype=float)
        cons += [m[1:] >= b[:, 0], m[1:] <= b[:, 1]]
    for i in range(n):
        for j in range(i + 1, n):
            cons += [c[i, j] <= 0, k[i, j] <= 0] if allowed[i, j] else [c[i, j] == 0, k[i, j] == 0]
    parts = []
    for r in range(lam.size):
        a2, a1, a0 = lam_s[r] ** 2 * psi[:, r], lam_s[r] * psi[:, r], psi[:, r]
        parts += [
            cp.multiply(m, a2.real) + c @ a1.real + k @ a0.real,
            cp.multiply(m, a2.imag) + c @ a1.imag + k @ a0.imag,
        ]
    cp.Problem(cp.Minimize(cp.sum_squares(cp.hstack(parts))), cons).solve(solver=cp.CLARABEL)
    return np.asarray(m.value), np.asarray(c.value) * w_ref, np.asarray(k.value) * w_ref**2


def modal_basis(s, z_inv, u, lam, dt, bandlimited):
    """The DFT modal model's real basis and its pole slopes, a column at a time in numpy:
    ``(basis (2 L, 4 n + 2), slopes (4, n, L))`` as ``armaxmodal._kernels.modal_basis`` fills them."""

    def held(p, slope):
        mu = np.exp(p * dt)
        den = 1 - mu * z_inv
        return dt * mu * z_inv / den**2 if slope else 1 / den

    def plant(p, slope):
        if bandlimited:
            return u / (s - p) ** (slope + 1)
        return u * held(p, slope)

    def pair(h, h_conj):
        return [h + h_conj, 1j * (h - h_conj)]

    cols = [c for p in lam for c in pair(plant(p, 0), plant(np.conj(p), 0))] + [u]
    cols += [c for p in lam for c in pair(held(p, 0), held(np.conj(p), 0))] + [np.ones_like(s)]
    basis = np.array(cols).T
    slopes = np.array([[f(q, 1) for q in poles] for f in (plant, held) for poles in (lam, np.conj(lam))])
    return np.vstack([basis.real, basis.imag]), slopes


def modal_moved(slopes, alpha, beta, d_lam):
    """``-dA/dx coef`` per sensor and parameter, (2 L, S, 2 n), a mode and parameter at a time."""
    n, lines = slopes.shape[1], slopes.shape[2]
    out = np.empty((2 * lines, alpha.shape[1], 2 * n))
    for j in range(n):
        for i in range(2):
            g = d_lam[j, i]
            own = np.outer(slopes[0, j], alpha[j]) + np.outer(slopes[2, j], beta[j])
            partner = np.outer(slopes[1, j], np.conj(alpha[j])) + np.outer(slopes[3, j], np.conj(beta[j]))
            m = -(g * own + np.conj(g) * partner)
            out[:lines, :, 2 * j + i], out[lines:, :, 2 * j + i] = m.real, m.imag
    return out


def local_polynomial_noise(u, y, half_width: int, degree: int):
    """The local polynomial method one line at a time: each line's window (shifted inwards at the
    ends), the FRF and transient polynomials fitted by ``numpy.linalg.lstsq``, the residual's power
    over its degrees of freedom."""
    u, y = np.asarray(u, complex), np.asarray(y, complex)
    n, width = u.size, 2 * half_width + 1
    var = np.empty(y.shape)
    for k in range(n):
        centre = min(max(k, half_width), n - 1 - half_width)
        rows = np.arange(centre - half_width, centre + half_width + 1)
        r = (rows - k) / half_width
        columns = [r**p * u[rows] for p in range(degree + 1)] + [r**p + 0j for p in range(degree + 1)]
        a = np.column_stack(columns)
        for j in range(y.shape[1]):
            coef = np.linalg.lstsq(a, y[rows, j], rcond=None)[0]
            var[k, j] = np.sum(np.abs(y[rows, j] - a @ coef) ** 2) / (width - 2 * (degree + 1))
    return var
