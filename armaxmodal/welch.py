"""Welch spectra: auto and cross spectral densities of an input and several outputs, and their
coherence. Numpy only, so that a :class:`~armaxmodal.recording.Recording` can carry its own
(:meth:`~armaxmodal.Recording.welch`): every stage that holds the record reads the
spectra computed for it once, instead of recomputing them."""

from __future__ import annotations

import numpy as np

from armaxmodal.exceptions import DataError

__all__ = ["coherence", "welch_segments", "welch_spectra"]


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
