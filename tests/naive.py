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
