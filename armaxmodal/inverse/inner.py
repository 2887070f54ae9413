"""The convex inner problem of EVPHC, made well posed (thesis Eqs. 2.14-2.18).

Minimise the residual of the real-form eigenproblem (Eq. 2.14) over the chain's physical
values. The map R of Eq. 2.11 is unitary, so the real-form residual norm equals that of the
complex residual ``(lambda^2 M + lambda C + K) psi`` stacked over the modes: both are used
interchangeably. For a chain (Fig. 4.3) M, C and K are linear in the masses, springs and
dampers, so with non-negative values and mass-ratio bounds (Eq. 2.18) this is a bounded
linear least-squares problem -- convex, with a unique answer once the scale is fixed by
one mass -- solved exactly by scipy's BVLS. The printed form (minimise (M11 - 1)^2 subject
to ``|residual| <= t``) has a continuum of optima; it is not reproduced.
"""

from __future__ import annotations

import time

import numpy as np
import scipy.optimize

from armaxmodal.exceptions import StructureError
from armaxmodal.inverse.modal_data import check_modes
from armaxmodal.inverse.result import InverseSolution
from armaxmodal.systems.structure import Structure

# Relative residual of the eigen-equations above which the topology is flagged: a chain's own
# modes stay below 0.05 even with 20 % eigenvector noise; a non-chain's modes give about 0.2.
_POOR_FIT = 0.1


def _design(lam: np.ndarray, psi: np.ndarray) -> np.ndarray:
    """Complex design matrix A with residual = A @ [m, c, c_s, k, k_s] (scaled units)."""
    n, n_modes = psi.shape
    cols = 3 * n + 2 * (n - 1)
    rows = []
    for r in range(n_modes):
        p, lr = psi[:, r], lam[r]
        block = np.zeros((n, cols), dtype=complex)
        for i in range(n):
            block[i, i] = lr**2 * p[i]  # m_i
            block[i, n + i] = lr * p[i]  # c_i
            block[i, 2 * n - 1 + n + i] = p[i]  # k_i (after m, c, c_s)
        for s in range(n - 1):
            diff = p[s] - p[s + 1]
            block[s, 2 * n + s] += lr * diff  # c_s
            block[s + 1, 2 * n + s] -= lr * diff
            block[s, 4 * n - 1 + s] += diff  # k_s
            block[s + 1, 4 * n - 1 + s] -= diff
        rows.append(block)
    return np.vstack(rows)


def mass_bounds(n: int, mass_ratio_bounds) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = np.zeros(n), np.full(n, np.inf)
    lo[0] = hi[0] = 1.0
    if mass_ratio_bounds is not None:
        b = np.asarray(mass_ratio_bounds, dtype=float)
        if b.shape != (n - 1, 2):
            raise StructureError(
                f"mass_ratio_bounds: expected {n - 1} (low, high) pairs for m2..m{n} / m1, got {b.shape}."
            )
        if np.any(b[:, 0] > b[:, 1]) or np.any(b < 0):
            raise StructureError(
                f"mass_ratio_bounds exclude every solution (a low bound above its high one): {b.tolist()}."
            )
        lo[1:], hi[1:] = b[:, 0], b[:, 1]
    return lo, hi


def inner_solve(
    eigenvalues,
    shapes,
    *,
    mass_ratio_bounds=None,
    m1: float | None = 1.0,
    total_mass: float | None = None,
    names=None,
    reference_hz: float | None = None,
) -> InverseSolution:
    """Chain masses, springs and dampers that best satisfy the eigen-equations.

    Parameters
    ----------
    eigenvalues : (n_modes,) complex
        Continuous poles, rad/s, positive imaginary part.
    shapes : (n_dof, n_modes) complex
        Mode shapes, one column per mode (any scale and phase).
    mass_ratio_bounds : (n_dof - 1, 2) array_like, optional
        ``low <= m_j / m_1 <= high`` for j = 2..n (Eq. 2.18).
    m1 : float
        Scale: the first mass in kg (ignored when ``total_mass`` is given).
    total_mass : float, optional
        Scale the solution to this total mass, kg.
    names : sequence of str, optional
    reference_hz : float, optional
        Frequency used to non-dimensionalise (default: geometric mean of the modes).

    Returns
    -------
    InverseSolution

    See Also
    --------
    armaxmodal.inverse.inner_solve_sdp : The inner problem as an SDP, for any coupling pattern.
    armaxmodal.inverse.evphc : The inverse modal problem that calls it.

    Examples
    --------
    The supine chain recovered from its exact modes and its total mass:

    >>> import numpy as np
    >>> import armaxmodal as am
    >>> body = am.supine_human()
    >>> modes = body.modes()
    >>> solution = am.inner_solve(modes.eigenvalues, modes.shapes, total_mass=body.masses.sum())
    >>> np.round(solution.structure.masses, 2), np.round(body.masses, 2)
    (array([ 6.23, 21.37, 30.01, 19.95]), array([ 6.23, 21.37, 30.01, 19.95]))
    """
    start = time.perf_counter()
    lam, psi = check_modes(eigenvalues, shapes)
    n = psi.shape[0]
    if lam.size * 2 * n < 5 * n - 3:
        raise StructureError(f"{lam.size} mode(s) give too few equations for a {n}-mass chain; give more modes.")
    psi = psi / np.linalg.norm(psi, axis=0)  # each mode weighs the same
    w_ref = 2 * np.pi * reference_hz if reference_hz else float(np.exp(np.mean(np.log(np.abs(lam)))))
    a = _design(lam / w_ref, psi)
    a_real = np.vstack([a.real, a.imag])
    lo, hi = mass_bounds(n, mass_ratio_bounds)
    free = np.arange(1, a_real.shape[1])
    lb = np.r_[lo[1:], np.zeros(a_real.shape[1] - n)]
    ub = np.r_[hi[1:], np.full(a_real.shape[1] - n, np.inf)]
    # m1 = 1 fixes the scale; its column moves to the right-hand side.
    res = scipy.optimize.lsq_linear(a_real[:, free], -a_real[:, 0], bounds=(lb, ub), method="bvls", tol=1e-14)
    # BVLS may end a hair outside its bounds (seen: a spring of -2e-13 N/m, which the chain
    # then refuses as negative); the bounds are exact constraints, so clip to them
    x = np.r_[1.0, np.clip(res.x, lb, ub)]
    m, c, c_s = x[:n], x[n : 2 * n] * w_ref, x[2 * n : 3 * n - 1] * w_ref
    k, k_s = x[3 * n - 1 : 4 * n - 1] * w_ref**2, x[4 * n - 1 :] * w_ref**2
    scale = total_mass / m.sum() if total_mass is not None else (m1 if m1 is not None else 1.0)
    flags = []
    if res.active_mask[: n - 1].any():
        flags.append("a mass-ratio bound is active: the data pull a mass outside its bounds")
    try:
        s = Structure.from_chain(m * scale, k * scale, c * scale, k_s * scale, c_s * scale, names)
    except StructureError as exc:
        raise StructureError(
            f"the modes do not fit a chain with positive springs ({exc}); check the modes or the topology."
        ) from exc
    misfit = float(np.linalg.norm(a_real @ x) / np.linalg.norm(a_real[:, 0]))
    if misfit > _POOR_FIT:
        flags.append(
            f"the modes fit a chain poorly (relative eigen-equation residual {misfit:.2f} > {_POOR_FIT}): the "
            "structure may not be a chain, or the modes are very noisy; try inner_solve_sdp with a fuller pattern"
        )
    return InverseSolution(
        s,
        s.chain_components(),
        s.modes(),
        {"eigen_residual": misfit},
        "inner_solve",
        int(res.nit),
        time.perf_counter() - start,
        bool(res.success),
        flags,
    )
