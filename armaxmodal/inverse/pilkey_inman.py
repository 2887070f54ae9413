"""Pilkey-Inman iterative algorithm (PIA), the baseline: damping and stiffness from complex
modes when the mass matrix is known (Pilkey & Inman, 1998).

With modes normalised as ``psi^T (2 lambda M + C) psi = 1`` (Lancaster), the identities
``-M^-1 C M^-1 = sum lambda^2 psi psi^T + c.c.`` and ``-K^-1 = sum psi psi^T / lambda + c.c.``
give C and K; the normalisation needs C, so the two are iterated to a fixed point.
The result is a full, unstructured pair (C, K).
"""

from __future__ import annotations

import time

import numpy as np

from armaxmodal.exceptions import StructureError
from armaxmodal.inverse.modal_data import check_modes
from armaxmodal.inverse.result import InverseSolution
from armaxmodal.systems.structure import Structure


def pia(eigenvalues, shapes, mass, *, tol: float = 1e-4, max_iter: int = 500, names=None) -> InverseSolution:
    """Damping and stiffness matrices from all n complex modes and a known mass matrix.

    Parameters
    ----------
    eigenvalues : (n,) complex, rad/s
    shapes : (n, n) complex
    mass : (n,) or (n, n)
        Known masses, kg.
    tol : float
        Relative change of C that ends the iteration.
    max_iter : int
        Cap on iterations.
    names : sequence of str, optional
        The DOFs' names.

    Returns
    -------
    InverseSolution
        The chain's damping and stiffness with the given masses.

    See Also
    --------
    armaxmodal.inverse.evphc : The inverse modal problem by eigenvector phase correction.
    armaxmodal.inverse.model_update : Components fitted to modal data and/or transmissibility.

    Examples
    --------
    Stiffness and damping from the exact modes and the masses (Pilkey & Inman):

    >>> import numpy as np
    >>> import armaxmodal as am
    >>> body = am.supine_human()
    >>> modes = body.modes()
    >>> solution = am.pia(modes.eigenvalues, modes.shapes, body.masses)
    >>> np.round(np.diag(solution.structure.K) / 1e3, 1), np.round(np.diag(body.K) / 1e3, 1)  # kN/m
    (array([ 61.7,  76.1, 190.6,  38.2]), array([ 61.7,  76.1, 190.6,  38.2]))
    """
    start = time.perf_counter()
    m = np.diag(mass) if np.ndim(mass) == 2 else np.asarray(mass, dtype=float)
    lam, psi = check_modes(eigenvalues, shapes, m.size)
    if lam.size != m.size:
        raise StructureError(f"PIA needs all {m.size} modes of a {m.size}-DOF model, got {lam.size}.")
    mm = np.diag(m)
    c = np.zeros_like(mm)
    converged, it = False, 0
    for it in range(1, max_iter + 1):  # noqa: B007 - reported
        a = np.array([psi[:, r] @ (2 * lam[r] * mm + c) @ psi[:, r] for r in range(lam.size)])
        phi = psi / np.sqrt(a)
        s2 = 2 * np.real((phi * lam**2) @ phi.T)
        c_new = -mm @ s2 @ mm
        change = np.linalg.norm(c_new - c) / max(np.linalg.norm(c_new), 1e-300)
        c = c_new
        if change < tol:
            converged = True
            break
    a = np.array([psi[:, r] @ (2 * lam[r] * mm + c) @ psi[:, r] for r in range(lam.size)])
    phi = psi / np.sqrt(a)
    k = -np.linalg.inv(2 * np.real((phi / lam) @ phi.T))
    c, k = (c + c.T) / 2, (k + k.T) / 2
    flags = [] if converged else [f"PIA did not converge in {max_iter} iterations"]
    try:
        s = Structure(mm, c, k, tuple(names or ()))
    except StructureError as exc:
        raise StructureError(
            f"PIA returned a non-physical model ({exc}); the modal data are too noisy for it."
        ) from exc
    modes = s.modes()
    if modes.real_poles.size:
        flags.append("over-damped: the PIA model has real poles")
    return InverseSolution(s, None, modes, {}, "pia", it, time.perf_counter() - start, converged, flags)
