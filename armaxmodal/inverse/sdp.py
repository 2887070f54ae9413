"""The inner problem for a general sparsity and sign pattern: a semi-definite program
solved by Clarabel's interior-point method, Section 2.2.2-2.2.3.

M diagonal and positive, C positive semi-definite, K positive definite, couplings allowed
only where ``pattern`` says, off-diagonal terms non-positive (springs pull neighbours
together); minimise the Eq. 2.14 residual with the first mass fixed (scale) and the mass
ratios bounded (Eq. 2.18). ``thesis_t`` gives the printed form instead: minimise
``(M11 - 1)^2`` subject to every real-form residual entry within ``+-t`` -- kept for
comparison only, since with ``t`` free it has a continuum of optima.

The conic form is built here and handed to Clarabel directly: the problem is small (a few
dozen variables) and a modelling layer's canonicalisation took 10-20 times longer than the
solve. ``tests/naive.py`` states the same problem in cvxpy as the reference.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.sparse

from armaxmodal.exceptions import StructureError
from armaxmodal.inverse.inner import mass_bounds
from armaxmodal.inverse.modal_data import check_modes
from armaxmodal.inverse.result import InverseSolution
from armaxmodal.systems.structure import Structure


def _svec_rows(n: int, entries: list[tuple[int, int]], offset: int, n_var: int) -> scipy.sparse.csc_matrix:
    """Map from the variables to Clarabel's scaled upper-triangle vector of a symmetric matrix
    (column-major, off-diagonals times sqrt 2) whose free entries are ``entries``."""
    position = {}
    for col in range(n):
        for row in range(col + 1):
            position[(row, col)] = len(position)
    out = scipy.sparse.lil_matrix((n * (n + 1) // 2, n_var))
    for v, (i, j) in enumerate(entries):
        out[position[(i, j)], offset + v] = 1.0 if i == j else np.sqrt(2.0)
    return out.tocsc()


def _design(lam_s: np.ndarray, psi: np.ndarray, entries: list[tuple[int, int]]) -> np.ndarray:
    """Real design matrix D, residual = D @ [m, C entries, K entries] (real and imaginary
    parts of ``(lambda^2 M + lambda C + K) psi`` stacked over the modes)."""
    n, n_modes = psi.shape
    n_e = len(entries)
    d = np.zeros((n * n_modes, n + 2 * n_e), dtype=complex)
    for r in range(n_modes):
        rows = slice(r * n, (r + 1) * n)
        p, lr = psi[:, r], lam_s[r]
        d[rows, :n] = np.diag(lr**2 * p)
        for v, (i, j) in enumerate(entries):
            for row, col in {(i, j), (j, i)}:  # a symmetric entry acts in both rows
                d[r * n + row, n + v] += lr * p[col]
                d[r * n + row, n + n_e + v] += p[col]
    return np.vstack([d.real, d.imag])


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
    eigenvalues : (n_modes,) complex
        Continuous poles, rad/s.
    shapes : (n_dof, n_modes) complex
        Mode shapes (any scale).
    pattern : (n_dof, n_dof) bool array_like, optional
        True where two DOFs may be coupled (default: a chain, neighbours only).
    mass_ratio_bounds : sequence of (low, high), optional
        Bounds on m2..mn over m1 (Eq. 2.18).
    m1, total_mass : float, optional
        Scale: the first mass or the total mass (kg).
    names : sequence of str, optional
    thesis_t : float, optional
        Solve the printed form with this residual tolerance instead.

    Returns
    -------
    InverseSolution
        ``components`` is set when the result is a chain.

    See Also
    --------
    armaxmodal.inverse.inner_solve : The chain's inner problem, least squares on the eigen-equations.

    Examples
    --------
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> body = am.supine_human()
    >>> modes = body.modes()
    >>> solution = am.inner_solve_sdp(modes.eigenvalues, modes.shapes, total_mass=body.masses.sum())
    >>> np.round(solution.structure.masses, 2)
    array([ 6.23, 21.37, 30.01, 19.95])
    """
    import clarabel

    start = time.perf_counter()
    lam, psi = check_modes(eigenvalues, shapes)
    n = psi.shape[0]
    psi = psi / np.linalg.norm(psi, axis=0)
    w_ref = float(np.exp(np.mean(np.log(np.abs(lam)))))  # non-dimensionalise by a reference frequency
    entries = _coupled_entries(n, pattern)
    design = _design(lam / w_ref, psi, entries)
    a, b_vec, n_zero, n_nonneg = _conic_constraints(n, entries, mass_ratio_bounds, design, thesis_t)
    cones = [clarabel.NonnegativeConeT(n_nonneg), clarabel.PSDTriangleConeT(n), clarabel.PSDTriangleConeT(n)]
    if n_zero:
        cones.insert(0, clarabel.ZeroConeT(n_zero))
    n_var = design.shape[1]
    if thesis_t is None:  # minimise |D x|^2 = x^T (D^T D) x; Clarabel minimises x^T P x / 2 + q^T x
        p_mat, q = 2.0 * design.T @ design, np.zeros(n_var)
    else:  # minimise (m1 - 1)^2
        p_mat, q = np.zeros((n_var, n_var)), np.zeros(n_var)
        p_mat[0, 0], q[0] = 2.0, -2.0
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    solution = clarabel.DefaultSolver(
        scipy.sparse.triu(scipy.sparse.csc_matrix(p_mat)).tocsc(), q, a, b_vec, cones, settings
    ).solve()
    status = str(solution.status)
    if status not in ("Solved", "AlmostSolved"):
        raise StructureError(f"the semi-definite inner problem ended as {status}: no model with this pattern fits.")
    x = np.asarray(solution.x)
    s = _structure(x, entries, n, w_ref, total_mass, m1, names)
    try:
        comps = s.chain_components()
    except StructureError:
        comps = None  # another coupling pattern: the matrices are the result (see Returns)
    flags = ["solver reported an inaccurate optimum"] if status == "AlmostSolved" else []
    return InverseSolution(
        s,
        comps,
        s.modes(),
        {"eigen_residual": float(np.linalg.norm(design @ x))},
        "inner_solve_sdp" if thesis_t is None else "thesis_compat",
        int(solution.iterations),
        time.perf_counter() - start,
        True,
        flags,
    )


def _coupled_entries(n: int, pattern) -> list[tuple[int, int]]:
    """The upper-triangle entries ``(i, j)`` of C and K that may be non-zero (a chain by default)."""
    allowed = np.eye(n, dtype=bool) | (np.abs(np.subtract.outer(np.arange(n), np.arange(n))) == 1)
    if pattern is not None:
        allowed = np.asarray(pattern, dtype=bool)
        if allowed.shape != (n, n) or not np.array_equal(allowed, allowed.T):
            raise StructureError(f"pattern: expected a symmetric ({n}, {n}) boolean matrix.")
        allowed = allowed | np.eye(n, dtype=bool)
    return [(i, j) for j in range(n) for i in range(j + 1) if allowed[i, j]]


def _conic_constraints(n: int, entries, mass_ratio_bounds, design: np.ndarray, thesis_t) -> tuple:
    """``(A, b, zero rows, non-negative rows)`` of ``A x + s = b``, ``s`` in the zero cone
    (m1 = 1), the non-negative cone (masses, bounds, coupling signs, the printed form's
    tolerance) and two PSD cones (C and K, K >= 1e-9 I), rows grouped by cone."""
    n_e = len(entries)
    n_var = n + 2 * n_e
    eye = np.eye(n_var)
    zero_rows, zero_b = ([eye[0]], [1.0]) if thesis_t is None else ([], [])  # m1 = 1 fixes the scale
    nonneg_rows, nonneg_b = [], []
    nonneg_rows += [-eye[i] for i in range(n)]  # masses >= 0
    nonneg_b += [0.0] * n
    lo, hi = mass_bounds(n, mass_ratio_bounds)  # validated as for the chain solve
    for i in range(1, n):
        if lo[i] > 0:
            nonneg_rows.append(-eye[i])
            nonneg_b.append(-lo[i])
        if np.isfinite(hi[i]):
            nonneg_rows.append(eye[i])
            nonneg_b.append(hi[i])
    for v, (i, j) in enumerate(entries):
        if i != j:  # off-diagonal damping and stiffness couplings are non-positive
            nonneg_rows += [eye[n + v], eye[n + n_e + v]]
            nonneg_b += [0.0, 0.0]
    if thesis_t is not None:  # the printed form: every residual entry within +-t
        nonneg_rows += list(design) + list(-design)
        nonneg_b += [thesis_t] * (2 * design.shape[0])
    svec_c = _svec_rows(n, entries, n, n_var)
    svec_k = _svec_rows(n, entries, n + n_e, n_var)
    svec_eye = _svec_rows(n, [(i, i) for i in range(n)], 0, n) @ np.ones(n)
    a = scipy.sparse.vstack(
        [
            scipy.sparse.csc_matrix(np.array(zero_rows).reshape(-1, n_var)),
            scipy.sparse.csc_matrix(np.array(nonneg_rows)),
            -svec_c,
            -svec_k,
        ]
    ).tocsc()
    b_vec = np.r_[zero_b, nonneg_b, np.zeros(svec_c.shape[0]), -1e-9 * svec_eye]  # K >= 1e-9 I
    return a, b_vec, len(zero_b), len(nonneg_b)


def _structure(x: np.ndarray, entries, n: int, w_ref: float, total_mass, m1, names) -> Structure:
    """The structure of the solution ``x`` in physical units, at the mass scale."""
    n_e = len(entries)
    mm = x[:n]
    cc, kk = np.zeros((n, n)), np.zeros((n, n))
    for v, (i, j) in enumerate(entries):
        cc[i, j] = cc[j, i] = x[n + v] * w_ref
        kk[i, j] = kk[j, i] = x[n + n_e + v] * w_ref**2
    scale = total_mass / mm.sum() if total_mass is not None else (m1 if m1 is not None else 1.0) / mm[0]
    return Structure(np.diag(mm * scale), cc * scale, kk * scale, tuple(names or ()))
