"""Frequency responses from data and from modes.

* :func:`measured_frf` -- H1 estimate (Welch cross-spectrum over input auto-spectrum) of every
  output over the base input, with the coherence.
* :func:`modal_frf` -- the absolute-acceleration transmissibility rebuilt from modes (Eqs.
  3.25-3.26 with the continuous residue ``-lambda^2 M`` of an acceleration output).
"""

from __future__ import annotations

import numpy as np
import scipy.signal

__all__ = ["measured_frf", "modal_frf"]


def default_nperseg(recording) -> int:
    """Welch segment length of :func:`measured_frf`: about 10 s (a power of two), at most an
    eighth of the record."""
    return int(min(recording.n_samples // 8, 2 ** int(np.log2(recording.fs * 10))))


def measured_frf(recording, nperseg: int | None = None):
    """H1 estimate of each output over the input and the coherence.

    Returns ``(freq_hz, H (n_freq, n_sensors) complex, coherence (n_freq, n_sensors))``.
    """
    n = default_nperseg(recording) if nperseg is None else nperseg
    u = recording.base
    f, puu = scipy.signal.welch(u, recording.fs, nperseg=n)
    h, coh = [], []
    for y in recording.response.T:
        _, puy = scipy.signal.csd(u, y, recording.fs, nperseg=n)
        _, pyy = scipy.signal.welch(y, recording.fs, nperseg=n)
        h.append(puy / puu)
        coh.append(np.abs(puy) ** 2 / (puu * pyy))
    return f, np.array(h).T, np.array(coh).T


def h1_relative_error(coherence: np.ndarray, n_samples: int, nperseg: int) -> np.ndarray:
    """Relative random error (complex rms) of an H1 estimate: ``sqrt((1 - g^2) / (g^2 n_d))``
    (Bendat & Piersol, Random Data, Sec. 9.2.4: sqrt(1 - g^2) / (|g| sqrt(2 n_d)) for the
    magnitude and for the phase in radians), with n_d the number of Welch segments
    (50 % overlap, as :func:`measured_frf`). Shape of ``coherence``."""
    n_segments = max(1, (n_samples - nperseg) // (nperseg // 2) + 1)
    g2 = np.clip(np.asarray(coherence, dtype=float), 1e-6, 1.0 - 1e-12)
    return np.sqrt((1.0 - g2) / (g2 * n_segments))


def modal_frf(freq_hz, freqs, dampings, shapes):
    """Absolute-acceleration transmissibility synthesised from modes: ``sum r/(iw - lambda) + c.c.``
    with ``r = -lambda^2 M`` (M: EPFRF modal constants). Shape (n_freq, n_sensors)."""
    w = 2j * np.pi * np.asarray(freq_hz)[:, None, None]
    wn = 2 * np.pi * np.asarray(freqs)
    lam = -np.asarray(dampings) * wn + 1j * wn * np.sqrt(1 - np.asarray(dampings) ** 2)
    r = -(lam**2)[None, :] * shapes  # (n_sensors, n_modes)
    out = r[None] / (w - lam[None, None]) + np.conj(r)[None] / (w - np.conj(lam)[None, None])
    return out.sum(axis=2)
