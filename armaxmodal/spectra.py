"""A record's spectra: Welch auto and cross spectral densities of an input and several outputs,
the coherence, the H1 estimate with its random error, and the band the input excites.

Numpy only, and in the base layer, so that a :class:`~armaxmodal.Recording` carries its own
(:meth:`~armaxmodal.Recording.welch`, computed at the first call for a segment length and kept):
the preparation's checks, the sweep, the selection, the modal-model check, the diagnosis and the
figures all read the spectra computed once for the record they hold, and no stage reaches back
to an earlier one to get them."""

from __future__ import annotations

import numpy as np

from armaxmodal.exceptions import DataError
from armaxmodal.stats import welch_nperseg

__all__ = [
    "coherence",
    "default_nperseg",
    "excited_band",
    "h1_relative_error",
    "measured_frf",
    "welch_segments",
    "welch_spectra",
]


def welch_spectra(u: np.ndarray, y: np.ndarray, fs: float, nperseg: int):
    """Welch auto- and cross-spectral densities of an input and several outputs.

    The estimator and scaling of ``scipy.signal.welch`` / ``csd`` with their defaults
    (periodic Hann window, 50 % overlap, constant detrend per segment, one-sided density,
    mean over segments; tested equal to them), computed with one FFT per channel and
    segment and without importing ``scipy.signal``, whose import alone is 0.3 s of the
    4 s ``stabilise`` command.

    Parameters
    ----------
    u : (n,) ndarray
        Input.
    y : (n, k) ndarray
        Outputs.
    fs : float
        Sampling rate, Hz.
    nperseg : int
        Segment length, samples (at most n).

    Returns
    -------
    freq_hz : (nperseg // 2 + 1,) ndarray
    puu : (n_freq,) ndarray
        Input PSD, unit^2/Hz.
    puy : (n_freq, k) complex ndarray
        Cross-spectral densities ``conj(U) Y``.
    pyy : (n_freq, k) ndarray
        Output PSDs.
    """
    f, uf, yf, scale = welch_segments(u, y, fs, nperseg)
    puu = scale * np.mean(np.abs(uf) ** 2, axis=0)
    puy = scale[:, None] * np.mean(np.conj(uf)[:, :, None] * yf, axis=0)
    pyy = scale[:, None] * np.mean(np.abs(yf) ** 2, axis=0)
    return f, puu, puy, pyy


def welch_segments(u: np.ndarray, y: np.ndarray, fs: float, nperseg: int):
    """The windowed segment spectra :func:`welch_spectra` averages, for statistics that need
    them one by one (a jackknife over segments).

    Returns
    -------
    freq_hz : (n_freq,) ndarray
    uf : (n_segments, n_freq) complex ndarray
        Input segment DFTs (periodic Hann window, 50 % overlap, each segment's mean removed).
    yf : (n_segments, n_freq, k) complex ndarray
        Output segment DFTs.
    scale : (n_freq,) ndarray
        Factor turning ``|DFT|^2`` into a one-sided density, unit^2/Hz.
    """
    n = u.shape[0]
    if not 2 <= int(nperseg) <= n:
        raise DataError(f"nperseg: expected a segment length between 2 and the {n} samples, got {nperseg}.")
    nperseg = int(nperseg)
    step = nperseg - nperseg // 2
    starts = np.arange(0, n - nperseg + 1, step)
    window = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(nperseg) / nperseg)
    idx = starts[:, None] + np.arange(nperseg)[None, :]

    def segments_fft(x):  # (n_segments, n_freq[, k])
        seg = x[idx]
        seg = seg - seg.mean(axis=1, keepdims=True)
        return np.fft.rfft(seg * (window if x.ndim == 1 else window[:, None]), axis=1)

    scale = np.full(nperseg // 2 + 1, 2.0 / (fs * np.sum(window**2)))
    scale[0] /= 2
    if nperseg % 2 == 0:
        scale[-1] /= 2
    return np.fft.rfftfreq(nperseg, 1.0 / fs), segments_fft(u), segments_fft(y), scale


def coherence(puu: np.ndarray, puy: np.ndarray, pyy: np.ndarray) -> np.ndarray:
    """Magnitude-squared coherence ``|Puy|^2 / (Puu Pyy)`` of :func:`welch_spectra`'s output,
    (n_freq, K); zero where a spectrum vanishes."""
    return np.abs(puy) ** 2 / np.maximum(puu[:, None] * pyy, 1e-300)


def default_nperseg(recording) -> int:
    """Welch segment length of ``measured_frf``: about 10 s (a power of two), at most an
    eighth of the record."""
    return welch_nperseg(recording.n_samples, recording.fs)


def measured_frf(recording, nperseg: int | None = None):
    """H1 estimate of each output over the input and the coherence.

    Returns ``(freq_hz, H (n_freq, n_sensors) complex, coherence (n_freq, n_sensors))``.
    """
    n = default_nperseg(recording) if nperseg is None else nperseg
    f, puu, puy, pyy = recording.welch(n)
    return f, puy / puu[:, None], np.abs(puy) ** 2 / (puu[:, None] * pyy)


def h1_relative_error(coherence: np.ndarray, n_samples: int, nperseg: int) -> np.ndarray:
    """Relative random error (complex rms) of an H1 estimate: ``sqrt((1 - g^2) / (g^2 n_d))``
    (Bendat & Piersol, Random Data, Sec. 9.2.4: sqrt(1 - g^2) / (|g| sqrt(2 n_d)) for the
    magnitude and for the phase in radians), with n_d the number of Welch segments
    (50 % overlap, as ``measured_frf``). Shape of ``coherence``."""
    n_segments = max(1, (n_samples - nperseg) // (nperseg // 2) + 1)
    g2 = np.clip(np.asarray(coherence, dtype=float), 1e-6, 1.0 - 1e-12)
    return np.sqrt((1.0 - g2) / (g2 * n_segments))


def excited_band(recording, min_db: float = -30.0) -> tuple[float, float]:
    """Lowest and highest frequency (Hz) where the input PSD is within ``min_db`` of its peak."""
    f, pxx, _, _ = recording.welch(min(recording.n_samples, 1024))
    live = f[pxx >= pxx.max() * 10 ** (min_db / 10)]
    return float(live.min()), float(live.max())
