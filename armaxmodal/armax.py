"""ARMAX models ``A(q) y = q^-nk B(q) u + C(q) e`` (thesis Eqs. 3.9-3.14).

One ``ArmaxModel`` describes one output sensor (the thesis's diagonal A, Eq. 3.11).
``B`` has ``nb`` coefficients per input on lags ``nk .. nk + nb - 1``: ``nk = 0`` with a
``b0`` term is the biproper acceleration-in/acceleration-out case, ``nk < 0`` adds
non-causal taps (band-limited sampled data).

Poles are the roots ``mu`` of ``A(z)``; residues ``R`` come from the partial fractions
``G(z) = sum_k R_k / (1 - mu_k z^-1) + polynomial`` (Eq. 3.14) and, across sensors, form the
mode-shape components (Eq. 3.17).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from armaxmodal._kernels import armax_residual, inverse_filter
from armaxmodal._validate import as_signal_matrix, as_signal_vector
from armaxmodal.exceptions import DataError
from armaxmodal.modal import discrete_modal_parameters

__all__ = ["ArmaxModel"]


@dataclass(frozen=True)
class ArmaxModel:
    """One output's ARMAX model.

    Attributes
    ----------
    a : (na + 1,) ndarray
        Monic A coefficients ``[1, a1, ..., a_na]``.
    b : (n_inputs, nb) ndarray
        B coefficients; ``b[m, j]`` multiplies ``u_m(t - nk - j)``.
    c : (nc + 1,) ndarray
        Monic C coefficients.
    nk : int
        Input delay in samples (negative: non-causal taps).
    fs : float
        Sampling rate, Hz.
    noise_variance : float
        Variance of the innovations e.
    output : str
        Sensor name.
    inputs : tuple of str
        Input names.
    """

    a: np.ndarray
    b: np.ndarray
    c: np.ndarray
    nk: int
    fs: float
    noise_variance: float = float("nan")
    output: str = "y"
    inputs: tuple[str, ...] = ("u",)

    @property
    def orders(self) -> tuple[int, int, int, int]:
        """``(na, nb, nc, nk)``."""
        return self.a.size - 1, self.b.shape[1], self.c.size - 1, self.nk

    # -- poles and residues ---------------------------------------------------------------
    def poles(self) -> np.ndarray:
        """Discrete poles (roots of A(z)), complex, shape (na,)."""
        return np.roots(self.a) if self.a.size > 1 else np.zeros(0, complex)

    def residues(self, poles: np.ndarray | None = None) -> np.ndarray:
        """Residues ``R_k`` of ``q^-nk B / A`` at each pole, shape (n_inputs, n_poles).

        ``R_k = N(1/mu_k) / prod_{i != k} (1 - mu_i / mu_k)`` with ``N(x) = x^nk B(x)``; the
        polynomial (direct) part of a biproper or non-causal model does not enter.
        """
        mu = self.poles() if poles is None else np.asarray(poles, dtype=complex)
        all_poles = self.poles()
        out = np.empty((self.b.shape[0], mu.size), dtype=complex)
        for k, m in enumerate(mu):
            x = 1.0 / m
            others = all_poles[np.argsort(np.abs(all_poles - m))[1:]]
            denom = np.prod(1.0 - others / m)
            powers = x ** (self.nk + np.arange(self.b.shape[1]))
            out[:, k] = (self.b @ powers) / denom
        return out

    def modal_constants(self, poles: np.ndarray | None = None, hold: str = "bandlimited") -> np.ndarray:
        """EPFRF modal constants ``M_in`` (Eq. 3.24) from the residues, (n_inputs, n_poles).

        The output is absolute acceleration per unit base acceleration, whose continuous
        residue is ``r = -lambda^2 M``. How a discrete residue ``R`` maps to ``r`` depends on
        how the input was sampled: ``"bandlimited"`` (anti-aliased sensors, measured data) is
        impulse invariance, ``R = r / fs``; ``"zoh"`` (input held between samples) is
        ``R = r (mu - 1) / (lambda mu)``. The factor is common to every sensor of a mode, so
        mode-shape ratios are the same either way; magnitudes (FRF synthesis) are not.
        """
        if hold not in ("bandlimited", "zoh"):
            raise ValueError(f"hold: expected 'bandlimited' or 'zoh', got {hold!r}.")
        mu = self.poles() if poles is None else np.asarray(poles, dtype=complex)
        lam = np.log(mu) * self.fs
        r = self.residues(mu) * (self.fs if hold == "bandlimited" else mu * lam / (mu - 1.0))
        return -r / lam**2

    def modal_parameters(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Poles with positive imaginary part and their (freq_hz, damping, damped_freq_hz).

        Returns ``(mu, f, xi, fd)`` sorted by frequency (Eqs. 3.15-3.16 via ``ln(mu) fs``).
        """
        mu = self.poles()
        mu = mu[mu.imag > 0]
        f, xi, fd = discrete_modal_parameters(mu, self.fs)
        order = np.argsort(f)
        return mu[order], f[order], xi[order], fd[order]

    # -- responses ------------------------------------------------------------------------
    def frf(self, freq_hz) -> np.ndarray:
        """``e^{-i w nk dt} B / A`` at the given frequencies, shape (n_freq, n_inputs)."""
        w = 2 * np.pi * np.atleast_1d(np.asarray(freq_hz, dtype=float)) / self.fs
        x = np.exp(-1j * w)
        num = self.b @ (x[None, :] ** (self.nk + np.arange(self.b.shape[1]))[:, None])
        den = np.polyval(self.a[::-1], x)
        return (num / den[None, :]).T

    def simulate(self, u) -> np.ndarray:
        """Noise-free output ``q^-nk B/A u`` from rest, shape (n_samples,).

        ``u`` is (n_samples,) for one input or (n_samples, n_inputs).
        """
        u = as_signal_matrix(u, "u")
        if u.shape[1] != self.b.shape[0]:
            raise DataError(f"u: expected {self.b.shape[0]} input column(s), got {u.shape[1]}.")
        n = u.shape[0]
        v = np.zeros(n)
        for m in range(self.b.shape[0]):
            full = np.convolve(u[:, m], self.b[m])
            idx = np.arange(n) - self.nk
            ok = (idx >= 0) & (idx < full.size)
            v[ok] += full[idx[ok]]
        a = np.asarray(self.a, dtype=float)
        return inverse_filter((v / a[0])[None, :], np.ascontiguousarray(a / a[0]))[0]  # 1/A from rest

    def prediction_errors(self, y, u) -> np.ndarray:
        """One-step prediction errors ``(A y - q^-nk B u) / C`` from zero initial conditions."""
        y = as_signal_vector(y, "y")
        u = as_signal_matrix(u, "u")
        return armax_residual(y, np.ascontiguousarray(u.T), self.a, self.b, self.nk, self.c)

    def predict(self, y, u) -> np.ndarray:
        """One-step-ahead prediction ``y - eps``."""
        y = as_signal_vector(y, "y")
        return y - self.prediction_errors(y, u)
