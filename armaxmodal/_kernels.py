"""Numba kernels: the only module that imports numba.

Kernels take contiguous float64 arrays and return new arrays. They do no validation:
callers in the public modules check shapes, finiteness and sizes first. Each kernel has a
slow, obvious reference in ``tests/naive.py`` that the tests compare it with.
"""

from __future__ import annotations

import numpy as np
from numba import njit, uint64

# Samples per tile of the residual's FIR part: three tiles of doubles (24 KB) stay in L1.
_TILE = 1024

# Samples per block of the 1/C filter's time-major buffer: four signals' block (64 KB) stays
# in L2 with the record's rows streaming past it.
_FILTER_BLOCK = 2048

JIT_OPTIONS = {"cache": True, "nogil": True, "fastmath": False, "error_model": "numpy"}


@njit(**JIT_OPTIONS)
def hold_recursion(phi, gam, u_pad, n_steps, stride):
    """Run ``x[k+1] = phi x[k] + sum_m gam[:, m] u_pad[k + m]`` from ``x[0] = 0``.

    Parameters
    ----------
    phi : (ns, ns) float64
    gam : (ns, p) float64
        Input gains for the p input samples the hold polynomial uses.
    u_pad : (n_steps + p - 1,) float64
        Fine-grid input, padded so that step k reads ``u_pad[k : k + p]``.
    n_steps : int
        Number of fine steps.
    stride : int
        Keep every ``stride``-th state (including x[0]).

    Returns
    -------
    (n_steps // stride + 1, ns) float64
        States ``x[0], x[stride], x[2 stride], ...``.
    """
    ns = phi.shape[0]
    p = gam.shape[1]
    n_keep = n_steps // stride + 1
    out = np.zeros((n_keep, ns))
    x = np.zeros(ns)
    x_new = np.zeros(ns)
    for k in range(n_steps):
        for i in range(ns):
            acc = 0.0
            for j in range(ns):
                acc += phi[i, j] * x[j]
            for m in range(p):
                acc += gam[i, m] * u_pad[k + m]
            x_new[i] = acc
        for i in range(ns):
            x[i] = x_new[i]
        if (k + 1) % stride == 0:
            row = (k + 1) // stride
            for i in range(ns):
                out[row, i] = x[i]
    return out


@njit(**JIT_OPTIONS)
def divide_by_c(x, c, out):
    """``out = x / C(q)`` for one signal: ``out[t] = x[t] - sum_i c[i] out[t-i]``, zero start.

    The terms are subtracted oldest first, and the two newest outputs are kept in registers:
    then each step waits on one multiply-add for ``out[t-1]`` (and on no store and reload),
    while the older terms of the next steps run ahead. With a sum of all terms subtracted at
    the end, every step waited on the whole sum: 2.8x slower at nc = 4, 1.2x at nc = 30
    (n = 20,000). Indices are unsigned: a signed index makes numba test it for wrap-around
    at every access (1.8x at nc = 30).
    """
    n = x.size
    nc = c.size - 1
    for t in range(min(nc, n)):
        acc = x[uint64(t)]
        for i in range(t, 0, -1):
            acc -= c[uint64(i)] * out[uint64(t - i)]
        out[uint64(t)] = acc
    if n <= nc or nc == 0:
        if nc == 0:
            out[:] = x
        return
    c1 = c[uint64(1)]
    c2 = c[uint64(2)] if nc >= 2 else 0.0
    newest = out[uint64(nc - 1)]
    second = out[uint64(nc - 2)] if nc >= 2 else 0.0
    for t in range(nc, n):
        acc = x[uint64(t)]
        for i in range(nc, 2, -1):
            acc -= c[uint64(i)] * out[uint64(t - i)]
        acc -= c2 * second
        acc -= c1 * newest
        out[uint64(t)] = acc
        second = newest
        newest = acc


@njit(**JIT_OPTIONS)
def inverse_filter(x, c):
    """``x_f = x / C(q)`` with zero initial state: ``x_f[t] = x[t] - sum_i c[i] x_f[t-i]``.

    ``c`` is monic (``c[0] == 1``); shape (nc + 1,). ``x`` is (n_sig, n) and every row is
    filtered.
    """
    out = np.empty_like(x)
    inverse_filter_into(x, c, out)
    return out


@njit(**JIT_OPTIONS)
def inverse_filter_into(x, c, out):
    """:func:`inverse_filter` written into ``out`` (the shape of ``x``, not ``x`` itself): a
    fit reuses one array instead of a fresh one per step, which on records of millions of
    samples costs fresh pages every time."""
    n_sig, n = x.shape
    nc = c.size - 1
    c1 = c[1] if nc >= 1 else 0.0
    c2 = c[2] if nc >= 2 else 0.0
    # Four signals at a time, time-major: their four independent sums share each load of
    # c[i] and keep the pipeline busy (1.3-2.4x faster than one signal after another).
    # As in divide_by_c, the terms run oldest first and each signal's two newest outputs
    # stay in registers (1.1-1.5x). The time-major buffer holds one block and the nc
    # outputs before it, not the record: a whole-record buffer left the cache on long
    # records and cost fresh pages at every call (2.2x slower per sample at 4.3 million
    # samples than at 20,000; now 1.3x). Unsigned indices: no wrap-around test (1.25x).
    buf = np.empty(4 * (nc + _FILTER_BLOCK))
    for s0 in range(0, n_sig, 4):
        k = min(4, n_sig - s0)
        new0 = new1 = new2 = new3 = 0.0  # each signal's x_f[t-1]
        sec0 = sec1 = sec2 = sec3 = 0.0  # and x_f[t-2]
        buf[: 4 * nc] = 0.0  # the zero state before the record
        for b0 in range(0, n, _FILTER_BLOCK):
            b1 = min(n, b0 + _FILTER_BLOCK)
            for t in range(b0, b1):
                a0 = x[s0, t]
                a1 = x[s0 + 1, t] if k > 1 else 0.0
                a2 = x[s0 + 2, t] if k > 2 else 0.0
                a3 = x[s0 + 3, t] if k > 3 else 0.0
                here = nc + t - b0  # t's row in the buffer
                for i in range(nc, 2, -1):
                    ci = c[uint64(i)]
                    row = uint64(4 * (here - i))
                    a0 -= ci * buf[row]
                    a1 -= ci * buf[row + uint64(1)]
                    a2 -= ci * buf[row + uint64(2)]
                    a3 -= ci * buf[row + uint64(3)]
                a0 = a0 - c2 * sec0 - c1 * new0
                a1 = a1 - c2 * sec1 - c1 * new1
                a2 = a2 - c2 * sec2 - c1 * new2
                a3 = a3 - c2 * sec3 - c1 * new3
                row = uint64(4 * here)
                buf[row] = a0
                buf[row + uint64(1)] = a1
                buf[row + uint64(2)] = a2
                buf[row + uint64(3)] = a3
                sec0, sec1, sec2, sec3 = new0, new1, new2, new3
                new0, new1, new2, new3 = a0, a1, a2, a3
            m = b1 - b0
            for j in range(k):
                out[s0 + j, b0:b1] = buf[4 * nc + j : 4 * (nc + m) : 4]
            for r in range(4 * nc):  # the block's last nc outputs: the next block's history
                buf[r] = buf[4 * m + r]  # (forward copy: the source lies after the target)


@njit(**JIT_OPTIONS)
def armax_residual(y, u, a, b, nk, c):
    """One-step prediction errors ``eps = (A y - q^-nk B u) / C`` with zero padding.

    Parameters
    ----------
    y : (n,) output
    u : (n_in, n) inputs
    a : (na + 1,) monic A coefficients
    b : (n_in, nb) B coefficients; ``b[m, j]`` multiplies ``u[m, t - nk - j]``
    nk : int, input delay (negative: non-causal taps)
    c : (nc + 1,) monic C coefficients

    Returns
    -------
    (n,) prediction errors; samples outside [0, n) count as zero.
    """
    n = y.size
    n_in, nb = b.shape
    # A y - q^-nk B u one lag at a time over slices: the time loop has no recursion and no
    # index arithmetic, so it runs in vector registers (4x faster than per-sample sums).
    # Done tile by tile: every lag then reads the tile from L1 cache instead of streaming the
    # whole record through L2 once per lag (2x faster at n = 20,000); each sample still gets
    # its terms in the same order, so the result is bit-identical to one pass per lag.
    w = y.copy()
    for tile0 in range(0, n, _TILE):
        tile1 = min(n, tile0 + _TILE)
        for i in range(1, a.size):
            lo = max(tile0, i)
            ai, w_i, y_i = a[i], w[lo:tile1], y[lo - i : max(tile1 - i, lo - i)]
            for t in range(tile1 - lo):
                w_i[t] += ai * y_i[t]
        for m in range(n_in):
            for j in range(nb):
                lag = nk + j
                lo, hi = max(lag, tile0), min(tile1, n + lag)
                bj, w_j, u_j = b[m, j], w[lo:hi], u[m, lo - lag : max(hi - lag, lo - lag)]
                for t in range(hi - lo):
                    w_j[t] -= bj * u_j[t]
    divide_by_c(w, c, w)  # in place: step t reads w[t] before it writes the output there
    return w


@njit(**JIT_OPTIONS)
def lagged_value(sig, s, k):
    if k < 0 or k >= sig.shape[1]:
        return 0.0
    return sig[s, k]


@njit(**JIT_OPTIONS)
def lagged_gram(sig, col_sig, col_lag, col_sign, t0, t1):
    """Gram matrix of regressor columns that are lagged copies of a few signals.

    Column ``c`` is ``col_sign[c] * sig[col_sig[c], t - col_lag[c]]`` for t in [t0, t1)
    (zero outside the record). Within a run of columns on the same signal the lags must
    increase by one; then each entry follows from its upper-left neighbour by adding the
    sample entering at ``t0`` and removing the one leaving at ``t1`` -- O(n p) work instead
    of O(n p^2). Returns the symmetric (p, p) matrix.
    """
    p = col_sig.size
    g = np.zeros((p, p))
    for c1 in range(p):
        for c2 in range(c1, p):
            s1, s2 = col_sig[c1], col_sig[c2]
            l1, l2 = col_lag[c1], col_lag[c2]
            chained = (
                c1 > 0
                and c2 > 0
                and col_sig[c1 - 1] == s1
                and col_sig[c2 - 1] == s2
                and col_lag[c1 - 1] == l1 - 1
                and col_lag[c2 - 1] == l2 - 1
            )
            if chained:
                val = col_sign[c1 - 1] * col_sign[c2 - 1] * g[c1 - 1, c2 - 1]
                val *= col_sign[c1] * col_sign[c2]
                val += (
                    col_sign[c1]
                    * col_sign[c2]
                    * (
                        lagged_value(sig, s1, t0 - l1) * lagged_value(sig, s2, t0 - l2)
                        - lagged_value(sig, s1, t1 - l1) * lagged_value(sig, s2, t1 - l2)
                    )
                )
            else:
                lo = max(t0, l1, l2)
                hi = min(t1, sig.shape[1] + l1, sig.shape[1] + l2)
                acc = 0.0
                if hi > lo:
                    acc = np.dot(sig[s1, lo - l1 : hi - l1], sig[s2, lo - l2 : hi - l2])
                val = col_sign[c1] * col_sign[c2] * acc
            g[c1, c2] = val
            g[c2, c1] = val
    return g


@njit(**JIT_OPTIONS)
def lagged_cross(sig, col_sig, col_lag, col_sign, target, t0, t1):
    """``sum_t column_c(t) * target(t)`` for t in [t0, t1), for every column; shape (p,)."""
    p = col_sig.size
    out = np.zeros(p)
    n = sig.shape[1]
    for c in range(p):
        s, lag = col_sig[c], col_lag[c]
        lo, hi = max(t0, lag), min(t1, n + lag)
        acc = 0.0
        if hi > lo:
            acc = np.dot(sig[s, lo - lag : hi - lag], target[lo:hi])
        out[c] = col_sign[c] * acc
    return out


@njit(**JIT_OPTIONS)
def max_root_radius_below(p, radius):
    """True when every root of the monic polynomial ``p`` lies strictly inside ``radius``.

    Schur-Cohn step-down recursion on the polynomial scaled to the unit circle: the roots
    are inside iff every reflection coefficient has magnitude below one. O(n^2), no
    eigenvalue problem.
    """
    n = p.size - 1
    a = np.empty(n + 1)
    for i in range(n + 1):
        a[i] = p[i] * radius ** (-i)  # roots z of p -> z / radius
    for m in range(n, 0, -1):
        k = a[m] / a[0]
        if abs(k) >= 1.0:
            return False
        denom = 1.0 - k * k
        b = np.empty(m)
        for i in range(m):
            b[i] = (a[i] - k * a[m - i]) / denom
        a = b
    return True


@njit(**JIT_OPTIONS)
def modal_basis(s, z_inv, u, lam, dt, bandlimited, basis, slopes):
    """Fill the DFT modal model's basis and each pole's slopes, a line at a time.

    Parameters
    ----------
    s, z_inv, u : (L,) complex128
        Each line's ``i omega``, ``exp(-i omega dt)`` and input DFT.
    lam : (n,) complex128
        The upper poles (rad/s).
    dt : float
        Sample interval (s).
    bandlimited : bool
        Plant columns ``u / (s - lam)`` (True) or the held ``u / (1 - mu z^-1)`` (False).
    basis : (2 L, 4 n + 2) float64, filled
        Real parts of the lines over their imaginary parts; columns: a real pair per mode
        (``h + h'`` and ``i (h - h')`` for the pole's plant ``h`` and its conjugate's ``h'``),
        the input, a transient pair per mode (the same of ``1 / (1 - mu z^-1)``), a constant.
    slopes : (4, n, L) complex128, filled
        ``d/d lambda`` of the plant at the pole and at its conjugate, then of the transient.
    """
    n_lines, n = s.size, lam.size
    for j in range(n):
        for conj in range(2):
            p = lam[j] if conj == 0 else np.conj(lam[j])
            mu = np.exp(p * dt)
            for line in range(n_lines):
                held = _reciprocal(1.0 - mu * z_inv[line])
                held_slope = dt * mu * z_inv[line] * held * held
                if bandlimited:
                    inverse = _reciprocal(s[line] - p)
                    plant = u[line] * inverse
                    plant_slope = plant * inverse
                else:
                    plant, plant_slope = u[line] * held, u[line] * held_slope
                slopes[conj, j, line], slopes[2 + conj, j, line] = plant_slope, held_slope
                _put_pair(basis, line, n_lines, 2 * j, plant, conj)
                _put_pair(basis, line, n_lines, 2 * n + 1 + 2 * j, held, conj)
    for line in range(n_lines):
        basis[line, 2 * n], basis[n_lines + line, 2 * n] = u[line].real, u[line].imag
        basis[line, 4 * n + 1], basis[n_lines + line, 4 * n + 1] = 1.0, 0.0


@njit(**JIT_OPTIONS)
def _reciprocal(z):
    """``1 / z`` as ``conj(z) / |z|^2``: numba's complex division guards against overflow by
    scaling (Smith's method), which the basis's denominators never need (``|1 - mu z^-1|`` lies
    in ``[1 - |mu|, 2]``, ``|s - lambda|`` is at least the pole's decay rate); it took three
    quarters of the kernel's time."""
    size = z.real * z.real + z.imag * z.imag
    return complex(z.real / size, -z.imag / size)


@njit(**JIT_OPTIONS)
def _put_pair(basis, line, n_lines, col, h, conj):
    """Add ``h`` (the pole's, conj 0, or its conjugate's, conj 1) to its pair's two columns."""
    sign = 1.0 if conj == 0 else -1.0
    a = h  # column a: h + h'
    b = 1j * sign * h  # column b: i (h - h')
    if conj == 0:
        basis[line, col], basis[n_lines + line, col] = a.real, a.imag
        basis[line, col + 1], basis[n_lines + line, col + 1] = b.real, b.imag
    else:
        basis[line, col] += a.real
        basis[n_lines + line, col] += a.imag
        basis[line, col + 1] += b.real
        basis[n_lines + line, col + 1] += b.imag


@njit(**JIT_OPTIONS)
def modal_moved(slopes, alpha, beta, d_lam, out):
    """``-dA/dx coef`` of the modal model, every sensor and parameter at once.

    Parameters
    ----------
    slopes : (4, n, L) complex128
        As :func:`modal_basis` fills them.
    alpha, beta : (n, S) complex128
        Each mode's plant and transient coefficient per sensor (its pair's two real
        coefficients as one complex number).
    d_lam : (n, 2) complex128
        ``d lambda / d x`` for x = (log omega_n, xi) per mode.
    out : (2 L, S, 2 n) float64, filled
        Real parts over imaginary parts, as the basis's rows.
    """
    n, n_lines = slopes.shape[1], slopes.shape[2]
    for j in range(n):
        for line in range(n_lines):
            for k in range(alpha.shape[1]):
                own = slopes[0, j, line] * alpha[j, k] + slopes[2, j, line] * beta[j, k]
                partner = slopes[1, j, line] * np.conj(alpha[j, k]) + slopes[3, j, line] * np.conj(beta[j, k])
                for i in range(2):
                    m = -(d_lam[j, i] * own + np.conj(d_lam[j, i]) * partner)
                    out[line, k, 2 * j + i], out[n_lines + line, k, 2 * j + i] = m.real, m.imag
