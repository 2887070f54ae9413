"""Numba kernels: the only module that imports numba.

Kernels take contiguous float64 arrays and return new arrays. They do no validation:
callers in the public modules check shapes, finiteness and sizes first. Each kernel has a
slow, obvious reference in ``tests/naive.py`` that the tests compare it with.
"""

from __future__ import annotations

import numpy as np
from numba import njit

_JIT = {"cache": True, "nogil": True, "fastmath": False, "error_model": "numpy"}


@njit(**_JIT)
def _hold_recursion(phi, gam, u_pad, n_steps, stride):
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
