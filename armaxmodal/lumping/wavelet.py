"""Morlet scalograms and squared wavelet coherence (thesis Eqs. 5.2-5.5), on pycwt.

The transform and the Torrence-Compo smoothing come from pycwt (a maintained implementation
of Torrence & Compo 1998 and Grinsted et al. 2004); what is added here:

* the thesis's wave number omega_0 = 5: pycwt tabulates the scale-smoothing width only for
  omega_0 = 6 (Torrence & Compo Table 2, delta j_0 = 0.60) and fails for any other; the same
  width is used for 5, one boxcar of 0.6 octave, as Grinsted et al. do for their Morlet;
* the significance level by red-noise Monte Carlo, vectorised: pycwt's
  ``wct_significance`` prints, writes a cache into the home folder and counts with a Python
  loop per sample, minutes for one level;
* the phase of Eq. 5.5 as ``angle(S(W_x^* W_y))`` -- the printed arctan(Re/Im) swaps the
  parts, which would put a zero lag at 90 degrees.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pycwt

__all__ = ["Morlet5", "Scalogram", "WaveletCoherence", "scalogram", "wavelet_coherence", "OMEGA0"]

OMEGA0 = 5.0  # thesis Eq. 5.3
VOICES_PER_OCTAVE = 12


class Morlet5(pycwt.Morlet):
    """pycwt's Morlet wavelet with omega_0 = 5 and a scale-smoothing width of 0.6 octave."""

    def __init__(self):
        super().__init__(OMEGA0)
        self.deltaj0 = 0.60
        self.name = "Morlet"


@dataclass(frozen=True)
class Scalogram:
    """A continuous wavelet transform.

    Attributes
    ----------
    freq_hz : (n_scales,) ndarray
        Fourier frequency of each scale, descending.
    time_s : (n,) ndarray
    coefficients : (n_scales, n) complex ndarray
    coi_hz : (n,) ndarray
        Cone of influence as a frequency: below it, edge effects dominate.

    See Also
    --------
    armaxmodal.lumping.scalogram : What makes one.

    Examples
    --------
    >>> import numpy as np
    >>> from armaxmodal.lumping import scalogram
    >>> t = np.arange(0.0, 20.0, 1 / 60.0)
    >>> s = scalogram(np.sin(2 * np.pi * 5.0 * t), 60.0, (1.0, 20.0))
    >>> s.coefficients.shape, round(float(s.freq_hz[0]), 1), round(float(s.freq_hz[-1]), 1)
    ((52, 1200), 20.0, 1.1)
    >>> round(float(s.coi_hz[s.time_s.size // 2]), 2)  # mid-record, edge effects reach only below 0.11 Hz
    0.11
    """

    freq_hz: np.ndarray
    time_s: np.ndarray
    coefficients: np.ndarray
    coi_hz: np.ndarray

    @property
    def power(self) -> np.ndarray:
        return np.abs(self.coefficients) ** 2

    def inside_coi(self) -> np.ndarray:
        """(n_scales, n) bool: where the transform is free of edge effects.

        Returns
        -------
        (n_scales, n) bool ndarray
        """
        return self.freq_hz[:, None] >= self.coi_hz[None, :]


@dataclass(frozen=True)
class WaveletCoherence:
    """Squared wavelet coherence of x and y (Eq. 5.4) and the phase of y behind x (Eq. 5.5).

    Attributes
    ----------
    freq_hz, time_s, coi_hz : as in :class:`Scalogram`
    r2 : (n_scales, n) ndarray
        Squared coherence, 0..1.
    phase_rad : (n_scales, n) ndarray
        Positive where y lags x.
    significance : (n_scales,) ndarray
        Red-noise level of ``r2`` at the chosen confidence (NaN when not computed).

    See Also
    --------
    armaxmodal.lumping.wavelet_coherence : What makes one.

    Examples
    --------
    A 5 Hz tone against a noisy copy of itself: coherent, and above the red-noise level:

    >>> import numpy as np
    >>> from armaxmodal.lumping import wavelet_coherence
    >>> t = np.arange(0.0, 20.0, 1 / 60.0)
    >>> x = np.sin(2 * np.pi * 5.0 * t)
    >>> wc = wavelet_coherence(x, x + 0.1 * np.random.default_rng(0).standard_normal(x.size), 60.0, (2.0, 10.0), mc=20)
    >>> k = np.argmin(np.abs(wc.freq_hz - 5.0))
    >>> middle = np.median(wc.r2[k, 300:900])  # the middle 10 s
    >>> wc.r2.shape, round(float(middle), 2), bool(middle > wc.significance[k])
    ((28, 1200), 1.0, True)
    """

    freq_hz: np.ndarray
    time_s: np.ndarray
    coi_hz: np.ndarray
    r2: np.ndarray
    phase_rad: np.ndarray
    significance: np.ndarray


def _scales(fs: float, f_lo: float, f_hi: float, n: int):
    if not 0 < f_lo < f_hi <= fs / 2:
        raise ValueError(f"wavelet band: expected 0 < lo < hi <= fs/2 = {fs / 2:g} Hz, got {f_lo:g}:{f_hi:g}.")
    flambda = Morlet5().flambda()
    s0 = 1.0 / (f_hi * flambda)  # scale whose Fourier period is 1 / f_hi
    dj = 1.0 / VOICES_PER_OCTAVE
    j = int(np.floor(np.log2(f_hi / f_lo) / dj))
    return s0, dj, j


def scalogram(x, fs: float, band: tuple[float, float]) -> Scalogram:
    """Morlet (omega_0 = 5) CWT of ``x`` over ``band`` Hz, 12 voices per octave.

    Parameters
    ----------
    x : (n,) array_like
    fs : float
        Sampling rate, Hz.
    band : (lo, hi)
        Frequencies to cover, Hz.

    Returns
    -------
    Scalogram
        The wavelet coefficients, frequencies and cone of influence.

    See Also
    --------
    armaxmodal.lumping.Scalogram : What it returns.
    armaxmodal.lumping.wavelet_coherence : Two signals' coherence.

    Examples
    --------
    >>> import numpy as np
    >>> from armaxmodal.lumping import scalogram
    >>> t = np.arange(0.0, 30.0, 1 / 60.0)
    >>> s = scalogram(np.sin(2 * np.pi * 5.0 * t), 60.0, (1.0, 20.0))  # a 5 Hz tone, 30 s at 60 Hz
    >>> power = np.mean(np.abs(s.coefficients[:, 600:1200]) ** 2, axis=1)  # its middle 10 s
    >>> round(float(s.freq_hz[np.argmax(power)]), 1)
    5.0
    """
    x = np.asarray(x, dtype=float)
    s0, dj, j = _scales(fs, band[0], band[1], x.size)
    w, _, freqs, coi, _, _ = pycwt.cwt(x - x.mean(), 1 / fs, dj, s0, j, Morlet5())
    return Scalogram(freqs, np.arange(x.size) / fs, w, 1.0 / np.maximum(coi, 1e-12))


def _smoothed(w1, w2, scales, fs, dj, wavelet):
    dt = 1 / fs
    s = scales[:, None]
    s1 = wavelet.smooth(np.abs(w1) ** 2 / s, dt, dj, scales)
    s2 = wavelet.smooth(np.abs(w2) ** 2 / s, dt, dj, scales)
    s12 = wavelet.smooth(np.conj(w1) * w2 / s, dt, dj, scales)
    return np.abs(s12) ** 2 / (s1 * s2), s12


def wavelet_coherence(
    x, y, fs: float, band: tuple[float, float], *, significance: float | None = 0.95, mc: int = 60, seed: int = 0
) -> WaveletCoherence:
    """Squared wavelet coherence and phase lag of ``y`` behind ``x`` (Eqs. 5.4-5.5).

    Parameters
    ----------
    x, y : (n,) array_like
    fs : float
        Sampling rate, Hz.
    band : (lo, hi)
        Frequencies to cover, Hz.
    significance : float or None
        Confidence of the red-noise level (AR(1) noise with each signal's lag-1
        autocorrelation, ``mc`` Monte Carlo pairs); None skips it.
    mc : int
        Monte Carlo pairs for the significance level.
    seed : int
        Seed of those pairs.

    Returns
    -------
    WaveletCoherence
        Coherence, phase, frequencies, cone of influence and significance level.

    See Also
    --------
    armaxmodal.lumping.WaveletCoherence : What it returns.
    armaxmodal.lumping.scalogram : One signal's wavelet power.

    Examples
    --------
    >>> import numpy as np
    >>> from armaxmodal.lumping import wavelet_coherence
    >>> t = np.arange(0.0, 30.0, 1 / 60.0)
    >>> x = np.sin(2 * np.pi * 5.0 * t)
    >>> y = np.roll(x, 3) + 0.1 * np.random.default_rng(0).standard_normal(x.size)  # 3 samples late: 90 degrees
    >>> wc = wavelet_coherence(x, y, 60.0, (2.0, 10.0), significance=None)
    >>> k = np.argmin(np.abs(wc.freq_hz - 5.0))
    >>> round(float(np.median(wc.r2[k, 300:1500])), 1), round(float(np.degrees(np.median(wc.phase_rad[k, 300:1500]))))
    (1.0, 90)
    """
    x, y = (np.asarray(v, dtype=float) for v in (x, y))
    if x.shape != y.shape or x.ndim != 1:
        raise ValueError(f"x and y: expected two 1-D arrays of one length, got {x.shape} and {y.shape}.")
    wavelet = Morlet5()
    s0, dj, j = _scales(fs, band[0], band[1], x.size)
    w1, scales, freqs, coi, _, _ = pycwt.cwt(x - x.mean(), 1 / fs, dj, s0, j, wavelet)
    w2, *_ = pycwt.cwt(y - y.mean(), 1 / fs, dj, s0, j, wavelet)
    r2, s12 = _smoothed(w1, w2, scales, fs, dj, wavelet)
    # y lags x by phi: W_x ~ e^{i w t}, W_y ~ e^{i (w t - phi)}, so S(W_x^* W_y) ~ e^{-i phi}
    phase = -np.angle(s12)
    level = np.full(freqs.size, np.nan)
    if significance is not None:
        level = _red_noise_level(_ar1(x), _ar1(y), fs, (s0, dj, j), significance, mc, seed)
    return WaveletCoherence(
        freqs, np.arange(x.size) / fs, 1.0 / np.maximum(coi, 1e-12), np.clip(r2, 0, 1), phase, level
    )


def _ar1(x: np.ndarray) -> float:
    x = x - x.mean()
    return float(np.clip(np.dot(x[:-1], x[1:]) / np.dot(x, x), 0.0, 0.99))


def _red_noise(n: int, alpha: float, rng) -> np.ndarray:
    from scipy.signal import lfilter

    return lfilter([1.0], [1.0, -alpha], rng.standard_normal(n))


def _red_noise_level(a1, a2, fs, grid, level, mc, seed) -> np.ndarray:
    """Per scale, the ``level`` quantile of the coherence of two independent AR(1) series,
    outside their cone of influence (the significance contour of Grinsted et al.)."""
    s0, dj, j = grid
    wavelet = Morlet5()
    rng = np.random.default_rng(seed)
    largest = s0 * 2 ** (j * dj) * fs
    n = int(np.ceil(6 * largest))
    samples = [[] for _ in range(j + 1)]
    for _ in range(mc):
        w1, scales, freqs, coi, _, _ = pycwt.cwt(_red_noise(n, a1, rng), 1 / fs, dj, s0, j, wavelet)
        w2, *_ = pycwt.cwt(_red_noise(n, a2, rng), 1 / fs, dj, s0, j, wavelet)
        r2, _ = _smoothed(w1, w2, scales, fs, dj, wavelet)
        inside = (1.0 / freqs)[:, None] <= coi[None, :]
        for k in range(j + 1):
            samples[k].append(r2[k, inside[k]])
    return np.array([np.quantile(np.concatenate(s), level) if sum(map(len, s)) else np.nan for s in samples])
