"""The inner problem for a general sparsity and sign pattern: a semi-definite program
(cvxpy with the Clarabel interior-point solver), Section 2.2.2-2.2.3.

M diagonal and positive, C positive semi-definite, K positive definite, couplings allowed
only where ``pattern`` says, off-diagonal terms non-positive (springs pull neighbours
together); minimise the Eq. 2.14 residual with the first mass fixed (scale) and the mass
ratios bounded (Eq. 2.18). ``thesis_t`` gives the printed form instead: minimise
``(M11 - 1)^2`` subject to every real-form residual entry within ``+-t`` -- kept for
comparison only, since with ``t`` free it has a continuum of optima.
"""

from __future__ import annotations

import time

import numpy as np

from ..exceptions import StructureError
from ..structure import Structure
from ._modal_data import check_modes
from .result import InverseSolution


def inner_solve_sdp(
    eigenvalues,
    shapes,
    *,
    pattern=None,
    mass_ratio_bounds=None,
    m1: float | None = 1.0,
    total_mass: float | None = None,
    names=None,
    thesis_t: float | None = None,
) -> InverseSolution:
    """Inner problem as an SDP for any coupling pattern.

    Parameters
    ----------
    eigenvalues, shapes : as :func:`inner_solve`.
    pattern : (n, n) bool array_like, optional
        True where two DOFs may be coupled (default: a chain, neighbours only).
    thesis_t : float, optional
        Solve the printed form with this residual tolerance instead.
    """
    import cvxpy as cp

    start = time.perf_counter()
    lam, psi = check_modes(eigenvalues, shapes)
    n = psi.shape[0]
    psi = psi / np.linalg.norm(psi, axis=0)
    w_ref = float(np.exp(np.mean(np.log(np.abs(lam)))))
    lam_s = lam / w_ref
    allowed = np.eye(n, dtype=bool) | (np.abs(np.subtract.outer(np.arange(n), np.arange(n))) == 1)
    if pattern is not None:
        allowed = np.asarray(pattern, dtype=bool) | np.eye(n, dtype=bool)
        if allowed.shape != (n, n) or not np.array_equal(allowed, allowed.T):
            raise StructureError(f"pattern: expected a symmetric ({n}, {n}) boolean matrix.")
    m = cp.Variable(n)
    c = cp.Variable((n, n), symmetric=True)
    k = cp.Variable((n, n), symmetric=True)
    cons = [m[0] == 1, m >= 0, c >> 0, k >> 1e-9 * np.eye(n)]
    if mass_ratio_bounds is not None:
        b = np.asarray(mass_ratio_bounds, dtype=float)
        cons += [m[1:] >= b[:, 0], m[1:] <= b[:, 1]]
    for i in range(n):
        for j in range(i + 1, n):
            cons += [c[i, j] == 0, k[i, j] == 0] if not allowed[i, j] else [c[i, j] <= 0, k[i, j] <= 0]
    parts = []
    for r in range(lam.size):
        a2, a1, a0 = lam_s[r] ** 2 * psi[:, r], lam_s[r] * psi[:, r], psi[:, r]
        parts += [
            cp.multiply(m, a2.real) + c @ a1.real + k @ a0.real,
            cp.multiply(m, a2.imag) + c @ a1.imag + k @ a0.imag,
        ]
    resid = cp.hstack(parts)
    if thesis_t is None:
        problem = cp.Problem(cp.Minimize(cp.sum_squares(resid)), cons)
    else:
        cons[0] = m[0] >= 0  # the printed form lets M11 float and pulls it to 1
        problem = cp.Problem(cp.Minimize(cp.square(m[0] - 1)), cons + [cp.abs(resid) <= thesis_t])
    problem.solve(solver=cp.CLARABEL)
    if problem.status not in ("optimal", "optimal_inaccurate"):
        raise StructureError(f"the semi-definite inner problem is {problem.status}: no model with this pattern fits.")
    mm, cc, kk = np.asarray(m.value), np.asarray(c.value) * w_ref, np.asarray(k.value) * w_ref**2
    scale = total_mass / mm.sum() if total_mass is not None else (m1 if m1 is not None else 1.0) / mm[0]
    s = Structure(np.diag(mm * scale), (cc + cc.T) / 2 * scale, (kk + kk.T) / 2 * scale, tuple(names or ()))
    try:
        comps = s.chain_components()
    except StructureError:
        comps = None
    flags = ["solver reported an inaccurate optimum"] if problem.status == "optimal_inaccurate" else []
    return InverseSolution(
        s,
        comps,
        s.modes(),
        {"eigen_residual": float(np.linalg.norm(resid.value))},
        "inner_solve_sdp" if thesis_t is None else "thesis_compat",
        0,
        time.perf_counter() - start,
        True,
        flags,
    )
