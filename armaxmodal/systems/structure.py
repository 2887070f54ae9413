"""Lumped mass-spring-damper structures under base excitation (thesis Chapter 2, Section 3.3.3).

``M u'' + C u' + K u = f`` with M diagonal, C and K symmetric. Under a base acceleration
``a_g`` the motion relative to the base obeys ``M u_r'' + C u_r' + K u_r = -M e a_g``
(Eqs. 3.18-3.22, e = ones). Acronyms: FRF, frequency response function
``H(w) = (K + iwC - w^2 M)^-1`` (Eq. 2.19); EPFRF, equivalent point FRF
``-w^2 H(w) M e`` (Eqs. 2.20-2.22).

Sign note: with the equivalent force ``-M e a_g`` the relative acceleration per unit base
acceleration is ``-EPFRF``; the thesis writes the force as ``+M e a_g`` and drops the sign.
Magnitudes agree; the absolute-acceleration transmissibility is ``1 - EPFRF``.

One module of about 430 lines on purpose: the chain's matrices and what follows from them (its
components, exact modes, receptance, EPFRF, transmissibility, state space), which every test of
the package takes as its truth.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from armaxmodal._validate import as_square_matrix
from armaxmodal.exceptions import StructureError
from armaxmodal.modal import continuous_modal_parameters

__all__ = ["Structure", "ChainComponents", "ExactModes", "QUANTITIES", "FRAMES"]

QUANTITIES = ("displacement", "velocity", "acceleration")
FRAMES = ("absolute", "relative")

# Matrices read from print or built in floating point are symmetric to round-off only.
_SYMMETRY_RTOL = 1e-9


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.array(a)
    a.setflags(write=False)
    return a


def _chain_matrix(to_base: np.ndarray, links: np.ndarray) -> np.ndarray:
    """diag(to_base) plus the Laplacian of the neighbour links (Fig. 4.3)."""
    mat = np.diag(np.asarray(to_base, dtype=float))
    for i, s in enumerate(np.asarray(links, dtype=float)):
        mat[i, i] += s
        mat[i + 1, i + 1] += s
        mat[i, i + 1] -= s
        mat[i + 1, i] -= s
    return mat


def _chain_parts(mat: np.ndarray, label: str) -> tuple[np.ndarray, np.ndarray]:
    """Inverse of :func:`_chain_matrix`; raises if ``mat`` is not tridiagonal."""
    n = mat.shape[0]
    outside = np.abs(mat - np.triu(np.tril(mat, 1), -1))
    if n > 2 and outside.max() > _SYMMETRY_RTOL * np.abs(mat).max():
        i, j = np.unravel_index(np.argmax(outside), mat.shape)
        raise StructureError(
            f"{label} is not a chain: element ({i}, {j}) = {mat[i, j]:.6g} links two "
            "non-neighbouring masses; a chain (Fig. 4.3) is tridiagonal."
        )
    links = -np.diag(mat, 1)
    to_base = np.diag(mat).copy()
    to_base[:-1] -= links
    to_base[1:] -= links
    return to_base, links


@dataclass(frozen=True)
class ChainComponents:
    """Springs and dampers of a chain (Fig. 4.3): element i ties mass i to the base, s_i ties
    masses i and i+1. Units: kg, N/m, N s/m.

    See Also
    --------
    armaxmodal.Structure : The chain they build (``Structure.from_chain``).

    Examples
    --------
    >>> import armaxmodal as am
    >>> parts = am.chapter2_system().chain_components()  # Table 2.1 of the thesis
    >>> parts.masses.tolist(), parts.k.tolist()
    ([6.0, 14.0, 22.0, 9.0], [74000.0, 28000.0, 120800.0, 2400.0])
    """

    masses: np.ndarray
    k: np.ndarray
    c: np.ndarray
    k_s: np.ndarray
    c_s: np.ndarray
    names: tuple[str, ...]

    def to_frame(self) -> pd.DataFrame:
        """One row per component: kind ('mass', 'k', 'c', 'k_s', 'c_s'), location, value, unit.

        Returns
        -------
        pandas.DataFrame
            Columns ``component`` (the kind above), ``location``, ``value`` and ``unit``.
        """
        rows = []
        units = {"masses": "kg", "k": "N/m", "c": "N*s/m", "k_s": "N/m", "c_s": "N*s/m"}
        for kind, label in (("masses", "mass"), ("k", "k"), ("c", "c")):
            for name, v in zip(self.names, getattr(self, kind), strict=True):
                rows.append((label, name, v, units[kind]))
        pairs = [f"{a}-{b}" for a, b in zip(self.names[:-1], self.names[1:], strict=True)]
        for kind in ("k_s", "c_s"):
            for name, v in zip(pairs, getattr(self, kind), strict=True):
                rows.append((kind, name, v, units[kind]))
        return pd.DataFrame(rows, columns=["component", "location", "value", "unit"])


@dataclass(frozen=True)
class ExactModes:
    """Complex modes of a structure, sorted by undamped natural frequency.

    Attributes
    ----------
    eigenvalues : (n_modes,) complex
        Continuous poles lambda (rad/s) with positive imaginary part.
    freq_hz, damping, damped_freq_hz : (n_modes,) float
        ``|lambda|/2pi``, ``-Re(lambda)/|lambda|``, ``Im(lambda)/2pi``.
    shapes : (n_dof, n_modes) complex
        Eigenvectors psi of ``(lambda^2 M + lambda C + K) psi = 0``, unit 2-norm, largest
        component real and positive.
    modal_a : (n_modes,) complex
        ``a_n = psi^T (2 lambda M + C) psi``, so that
        ``H(s) = sum_n psi psi^T / (a_n (s - lambda_n)) + c.c.``
    modal_constants : (n_dof, n_modes) complex
        EPFRF modal constants ``M_in = psi_in sum_j psi_jn m_j / a_n`` (Eq. 3.24).
    real_poles : (k,) float
        Real (over-damped) poles, rad/s; empty for an under-damped structure.
    names : tuple of str

    See Also
    --------
    armaxmodal.Structure : Whose modes they are.

    Examples
    --------
    >>> import armaxmodal as am
    >>> modes = am.chapter2_system().modes()
    >>> modes.to_frame().round(3)
       mode  freq_hz  damping  damped_freq_hz
    0     1    5.916    0.278           5.683
    1     2    9.765    0.391           8.988
    2     3   13.330    0.362          12.428
    3     4   19.398    0.349          18.177
    """

    eigenvalues: np.ndarray
    freq_hz: np.ndarray
    damping: np.ndarray
    damped_freq_hz: np.ndarray
    shapes: np.ndarray
    modal_a: np.ndarray
    modal_constants: np.ndarray
    real_poles: np.ndarray
    names: tuple[str, ...]

    def to_frame(self) -> pd.DataFrame:
        """One row per mode: frequency (Hz), damping ratio, damped frequency (Hz).

        Returns
        -------
        pandas.DataFrame
            One row per mode.
        """
        return pd.DataFrame(
            {
                "mode": np.arange(1, self.freq_hz.size + 1),
                "freq_hz": self.freq_hz,
                "damping": self.damping,
                "damped_freq_hz": self.damped_freq_hz,
            }
        )

    def to_dict(self) -> dict:
        """JSON-ready dictionary (shapes as magnitude and phase in degrees per location).

        Returns
        -------
        dict
            Strict-JSON-ready.
        """
        return {
            "modes": [
                {
                    "freq_hz": float(self.freq_hz[i]),
                    "damping": float(self.damping[i]),
                    "damped_freq_hz": float(self.damped_freq_hz[i]),
                    "shape": {
                        name: {
                            "mag": float(abs(self.shapes[j, i])),
                            "phase_deg": float(np.degrees(np.angle(self.shapes[j, i]))),
                        }
                        for j, name in enumerate(self.names)
                    },
                }
                for i in range(self.freq_hz.size)
            ]
        }


@dataclass(frozen=True)
class Structure:
    """A validated lumped structure ``M u'' + C u' + K u = f``.

    Parameters
    ----------
    M : (n, n) array_like or (n,)
        Mass matrix, diagonal and positive (kg). A vector is taken as the diagonal.
    C : (n, n) array_like
        Damping matrix, symmetric positive semi-definite (N s/m).
    K : (n, n) array_like
        Stiffness matrix, symmetric positive definite (N/m).
    names : sequence of str, optional
        One name per degree of freedom (default ``dof1..dofn``).

    See Also
    --------
    armaxmodal.simulate_recording : Simulate a record of it.
    armaxmodal.ExactModes : Its exact modes.

    Examples
    --------
    >>> import armaxmodal as am
    >>> body = am.supine_human()
    >>> body.names, body.n_dof
    (('head', 'chest', 'pelvis', 'legs'), 4)
    >>> body.modes().freq_hz.round(2).tolist()  # Table 4.3 of the thesis
    [5.83, 8.31, 13.5, 16.25]
    """

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    names: tuple[str, ...] = field(default=())

    def __post_init__(self):
        M = as_square_matrix(self.M, "M")
        n = M.shape[0]
        C = as_square_matrix(self.C, "C", n)
        K = as_square_matrix(self.K, "K", n)
        if np.any(np.abs(M - np.diag(np.diag(M))) > 0):
            raise StructureError("M must be diagonal (lumped masses, Eq. 3.21); got off-diagonal terms.")
        if np.any(np.diag(M) <= 0):
            raise StructureError(f"M must have positive masses on its diagonal; got {np.diag(M)}.")
        for label, mat in (("C", C), ("K", K)):
            asym = np.abs(mat - mat.T).max()
            if asym > _SYMMETRY_RTOL * max(np.abs(mat).max(), 1e-300):
                raise StructureError(
                    f"{label} must be symmetric; largest |{label} - {label}.T| is {asym:.3g}. "
                    "Check a transcribed element (the thesis prints one C with a 0 for -40.29)."
                )
        C = (C + C.T) / 2
        K = (K + K.T) / 2
        k_eig = np.linalg.eigvalsh(K)
        if k_eig.min() <= 1e-12 * abs(k_eig).max():
            raise StructureError(
                f"K must be positive definite; its smallest eigenvalue is {k_eig.min():.6g}. "
                "A structure on a base needs every mass tied to the base through some spring."
            )
        c_eig = np.linalg.eigvalsh(C)
        if c_eig.min() < -1e-9 * max(abs(c_eig).max(), 1e-300):
            raise StructureError(f"C must be positive semi-definite; its smallest eigenvalue is {c_eig.min():.6g}.")
        names = tuple(self.names) if self.names else tuple(f"dof{i + 1}" for i in range(n))
        if len(names) != n or len(set(names)) != n:
            raise StructureError(f"names: expected {n} distinct names, got {list(names)}.")
        object.__setattr__(self, "M", _readonly(M))
        object.__setattr__(self, "C", _readonly(C))
        object.__setattr__(self, "K", _readonly(K))
        object.__setattr__(self, "names", names)

    # -- construction -------------------------------------------------------------------
    @classmethod
    def from_chain(
        cls,
        masses: Sequence[float],
        k: Sequence[float],
        c: Sequence[float],
        k_s: Sequence[float],
        c_s: Sequence[float],
        names: Sequence[str] | None = None,
    ) -> Structure:
        """Build a chain (Fig. 4.3): mass i tied to the base by (k_i, c_i) and to mass i+1 by
        (k_si, c_si). ``masses``, ``k``, ``c`` have n entries; ``k_s``, ``c_s`` have n-1."""
        masses = np.asarray(masses, dtype=float)
        n = masses.size
        for label, v, size in (("k", k, n), ("c", c, n), ("k_s", k_s, n - 1), ("c_s", c_s, n - 1)):
            if np.size(v) != size:
                raise StructureError(f"{label}: expected {size} values for {n} masses, got {np.size(v)}.")
            if np.any(np.asarray(v, dtype=float) < 0):
                raise StructureError(f"{label}: springs and dampers must be non-negative, got {v}.")
        return cls(np.diag(masses), _chain_matrix(c, c_s), _chain_matrix(k, k_s), tuple(names or ()))

    @property
    def n_dof(self) -> int:
        return self.M.shape[0]

    @property
    def masses(self) -> np.ndarray:
        return np.diag(self.M).copy()

    def chain_components(self) -> ChainComponents:
        """Springs and dampers of the chain these matrices describe; raises
        :class:`StructureError` if C or K couple non-neighbouring masses.

        Returns
        -------
        ChainComponents
            Each mass, spring and damper of the chain by name.
        """
        k, k_s = _chain_parts(self.K, "K")
        c, c_s = _chain_parts(self.C, "C")
        return ChainComponents(self.masses, k, c, k_s, c_s, self.names)

    # -- exact modal solution -----------------------------------------------------------
    def modes(self) -> ExactModes:
        """Complex modes from the first-order (state-space) eigenproblem.

        Returns
        -------
        ExactModes
            Eigenvalues, natural frequencies, damping ratios and shapes of the fixed-base system.
        """
        n = self.n_dof
        m_inv = 1.0 / np.diag(self.M)
        a = np.block([[np.zeros((n, n)), np.eye(n)], [-m_inv[:, None] * self.K, -m_inv[:, None] * self.C]])
        lam, vec = np.linalg.eig(a)
        real = np.abs(lam.imag) <= 1e-9 * np.abs(lam)
        upper = (lam.imag > 0) & ~real
        lam_u, psi = lam[upper], vec[:n, upper]
        order = np.argsort(np.abs(lam_u))
        lam_u, psi = lam_u[order], psi[:, order]
        # Unit norm, largest component on the positive real axis.
        psi = psi / np.linalg.norm(psi, axis=0)
        big = psi[np.argmax(np.abs(psi), axis=0), np.arange(psi.shape[1])]
        psi = psi * (np.abs(big) / big)
        modal_a = np.array([psi[:, i] @ (2 * lam_u[i] * self.M + self.C) @ psi[:, i] for i in range(lam_u.size)])
        constants = psi * (psi.T @ self.masses)[None, :] / modal_a[None, :]
        freq, damping, damped = continuous_modal_parameters(lam_u)
        return ExactModes(
            eigenvalues=_readonly(lam_u),
            freq_hz=_readonly(freq),
            damping=_readonly(damping),
            damped_freq_hz=_readonly(damped),
            shapes=_readonly(psi),
            modal_a=_readonly(modal_a),
            modal_constants=_readonly(constants),
            real_poles=_readonly(np.sort(lam[real].real)),
            names=self.names,
        )

    # -- frequency responses ------------------------------------------------------------
    def frf(self, freq_hz) -> np.ndarray:
        """Receptance ``H(w) = (K + iwC - w^2 M)^-1`` (Eq. 2.19), shape (n_freq, n, n), m/N.

        Parameters
        ----------
        freq_hz : (n_freq,) array_like
            Frequencies, Hz.

        Returns
        -------
        (n_freq, n, n) complex ndarray
        """
        w = 2 * np.pi * np.atleast_1d(np.asarray(freq_hz, dtype=float))
        dyn = self.K[None] + 1j * w[:, None, None] * self.C[None] - (w**2)[:, None, None] * self.M[None]
        return np.linalg.inv(dyn)

    def epfrf(self, freq_hz) -> np.ndarray:
        """EPFRF ``-w^2 H(w) M e`` (Eqs. 2.20-2.22), shape (n_freq, n_dof), dimensionless.

        Parameters
        ----------
        freq_hz : (n_freq,) array_like
            Frequencies, Hz.

        Returns
        -------
        (n_freq, n_dof) complex ndarray
        """
        w = 2 * np.pi * np.atleast_1d(np.asarray(freq_hz, dtype=float))
        w2 = (w**2)[:, None, None]
        dyn = self.K[None] + 1j * w[:, None, None] * self.C[None] - w2 * self.M[None]
        rhs = np.broadcast_to(self.masses[None, :, None], (w.size, self.n_dof, 1))
        return -(w**2)[:, None] * np.linalg.solve(dyn, rhs)[:, :, 0]

    def transmissibility(self, freq_hz, reference: str | int | None = None) -> np.ndarray:
        """Absolute-acceleration transmissibility, shape (n_freq, n_dof).

        With ``reference=None`` each output over the base acceleration, ``1 - EPFRF``
        (-> 1 at low frequency). With a DOF name or index ``l``, ``T_kl = U_k / U_l``
        between outputs (Eqs. 3.29-3.31).

        Parameters
        ----------
        freq_hz : (n_freq,) array_like
            Frequencies, Hz.
        reference : str or int, optional
            The output to divide by (default: the base).

        Returns
        -------
        (n_freq, n_dof) complex ndarray
        """
        t_base = 1.0 - self.epfrf(freq_hz)
        if reference is None:
            return t_base
        idx = self._index(reference)
        return t_base / t_base[:, idx : idx + 1]

    def _index(self, ref: str | int) -> int:
        if isinstance(ref, str):
            if ref not in self.names:
                raise StructureError(f"unknown DOF '{ref}'; names are {list(self.names)}.")
            return self.names.index(ref)
        if not 0 <= int(ref) < self.n_dof:
            raise StructureError(f"DOF index {ref} out of range 0..{self.n_dof - 1}.")
        return int(ref)

    # -- time domain ----------------------------------------------------------------------
    def state_space(
        self, quantity: str = "acceleration", frame: str = "absolute"
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Continuous state space with the base acceleration (m/s^2) as the single input.

        States are ``[u_r, u_r']`` (relative displacement and velocity), plus the base
        displacement and velocity ``[u_g, u_g']`` when absolute displacement or velocity is
        asked for. Returns ``(A, B, C, D)`` with B of shape (n_states, 1) and D (n_dof, 1).

        Parameters
        ----------
        quantity : {"acceleration", "velocity", "displacement"}
            What C and D output (m/s^2, m/s, m).
        frame : {"absolute", "relative"}
            Inertial, or relative to the base.

        Returns
        -------
        A, B, C, D : ndarray
        """
        if quantity not in QUANTITIES:
            raise ValueError(f"quantity: expected one of {QUANTITIES}, got {quantity!r}.")
        if frame not in FRAMES:
            raise ValueError(f"frame: expected one of {FRAMES}, got {frame!r}.")
        n = self.n_dof
        m_inv = 1.0 / self.masses
        with_base = frame == "absolute" and quantity != "acceleration"
        ns = 2 * n + (2 if with_base else 0)
        a = np.zeros((ns, ns))
        b = np.zeros((ns, 1))
        a[:n, n : 2 * n] = np.eye(n)
        a[n : 2 * n, :n] = -m_inv[:, None] * self.K
        a[n : 2 * n, n : 2 * n] = -m_inv[:, None] * self.C
        b[n : 2 * n, 0] = -1.0
        if with_base:
            a[2 * n, 2 * n + 1] = 1.0
            b[2 * n + 1, 0] = 1.0
        c = np.zeros((n, ns))
        d = np.zeros((n, 1))
        if quantity == "acceleration":
            c[:, : 2 * n] = a[n : 2 * n, : 2 * n]
            d[:, 0] = -1.0 if frame == "relative" else 0.0
        else:
            col = 0 if quantity == "displacement" else n
            c[:, col : col + n] = np.eye(n)
            if with_base:
                c[:, 2 * n + (0 if quantity == "displacement" else 1)] = 1.0
        return a, b, c, d
