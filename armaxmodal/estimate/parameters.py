"""The parameter vector: unpacking ``theta`` into A, B and C, indexing the shared and local parts
of a shared-pole fit, and projecting A and C back inside the unit circle.
"""

from __future__ import annotations

import numpy as np

from armaxmodal._kernels import max_root_radius_below

# Largest root radius allowed for C (keeps 1/C filtering stable and well conditioned).
MAX_C_RADIUS = 0.995


def unpack_theta(theta, na, nb, nc, n_in):
    a = np.concatenate([[1.0], theta[:na]])
    b = theta[na : na + n_in * nb].reshape(n_in, nb).copy()
    c = np.concatenate([[1.0], theta[na + n_in * nb :]])
    return a, b, c


def stable_c(c):
    """Reflect roots of C outside the unit circle inside and cap their radius."""
    if c.size <= 1 or max_root_radius_below(c, MAX_C_RADIUS):
        return c
    r = np.roots(c)
    mag = np.abs(r)
    r = np.where(mag > 1, 1 / np.conj(np.where(mag > 1, r, 1.0)), r)  # no 1/0 for a root at 0
    mag = np.abs(r)
    r = np.where(mag > MAX_C_RADIUS, r * (MAX_C_RADIUS / np.maximum(mag, 1e-300)), r)
    return np.real(np.poly(r))


def project_stable(theta, na, nb, nc, n_in, oe=False):
    """Keep C (output error: A) stable inside a parameter vector [a, b, c]."""
    if oe:
        theta = theta.copy()
        theta[:na] = stable_a(np.concatenate([[1.0], theta[:na]]))[1:]
        return theta
    if nc == 0:
        return theta
    theta = theta.copy()
    start = na + n_in * nb
    theta[start:] = stable_c(np.concatenate([[1.0], theta[start:]]))[1:]
    return theta


def stable_a(a):
    """Reflect roots of A outside the unit circle inside (filtering by 1/A must be stable)."""
    if max_root_radius_below(a, 1.0):
        return a
    r = np.roots(a)
    out = np.abs(r) > 1
    r = np.where(out, 1 / np.conj(np.where(out, r, 1.0)), r)
    r = np.where(np.abs(r) >= 0.9999, r * (0.9999 / np.abs(r)), r)
    return np.real(np.poly(r))


# -- shared-pole PEM -------------------------------------------------------------------------
def shared_index(k, na, p_k):
    """Global indices of sensor k's local parameters [a, b_k, c_k]."""
    return np.concatenate([np.arange(na), na + k * p_k + np.arange(p_k)])


def local_parameters(theta, k, na, p_k):
    return theta[shared_index(k, na, p_k)]


def project_shared_stable(theta, na, nb, nc, n_in, n_out, oe=False):
    if oe:
        return project_stable(theta, na, nb, nc, n_in, oe=True)
    if nc == 0:
        return theta
    theta = theta.copy()
    p_k = n_in * nb + nc
    for k in range(n_out):
        start = na + k * p_k + n_in * nb
        theta[start : start + nc] = stable_c(np.concatenate([[1.0], theta[start : start + nc]]))[1:]
    return theta
