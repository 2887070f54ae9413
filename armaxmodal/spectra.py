"""A record's spectra: Welch auto and cross spectral densities of an input and several outputs,
the coherence, the H1 estimate with its random error, the band the input excites, and the H1's
clear, coherent peaks at a resolution chosen from the modes.

Numpy only, and in the base layer, so that a :class:`~armaxmodal.Recording` carries its own
(:meth:`~armaxmodal.Recording.welch`, computed at the first call for a segment length and kept):
the preparation's checks, the sweep, the selection, the modal-model check, the diagnosis and the
figures all read the spectra computed once for the record they hold, and no stage reaches back
to an earlier one to get them."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from armaxmodal.exceptions import DataError
from armaxmodal.stats import H1_COHERENCE, welch_nperseg

__all__ = [
    "CoherentLines",
    "coherence",
    "coherent_lines",
    "coherent_peaks",
    "default_nperseg",
    "excited_band",
    "explains",
    "h1_relative_error",
    "local_polynomial_noise",
    "measured_frf",
    "peak_prominences",
    "resolving_nperseg",
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
    return f, puy / puu[:, None], coherence(puu, puy, pyy)


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


@dataclass(frozen=True)
class CoherentLines:
    """One output's coherent lines of a band: frequencies (Hz), the H1 there and its random
    error (absolute, Bendat & Piersol's from the coherence)."""

    freq_hz: np.ndarray
    h: np.ndarray
    sigma: np.ndarray


def coherent_lines(recording, nperseg: int, band=None) -> list[CoherentLines]:
    """Each output's H1 on the lines of ``band`` (Hz; default: the input's excited band) where
    its coherence is at least :data:`~armaxmodal.stats.H1_COHERENCE`, with its random error.

    Returns
    -------
    list of CoherentLines
        One per output, in the recording's sensor order (possibly with no line).
    """
    f, h, coh = measured_frf(recording, nperseg)
    lo, hi = band if band is not None else excited_band(recording)
    out = []
    for k in range(h.shape[1]):
        good = (coh[:, k] >= H1_COHERENCE) & (f > 0) & (f >= lo) & (f <= hi)
        sigma = h1_relative_error(coh[good, k], recording.n_samples, nperseg) * np.abs(h[good, k])
        out.append(CoherentLines(f[good], h[good, k], sigma))
    return out


def peak_prominences(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima of ``x`` and their prominences, as ``scipy.signal.find_peaks(x,
    prominence=0)`` gives them (a plateau's peak at its middle, rounded down).

    Written here because importing ``scipy.signal`` imports ``scipy.stats``: 0.8 s of every
    ``stabilise`` run, for a few hundred lines of one spectrum (``tests/modes/test_frf.py``
    checks it against scipy on random and plateau-rich data).

    Parameters
    ----------
    x : (n,) array

    Returns
    -------
    peaks : (m,) int array, indices of the maxima
    prominences : (m,) array, height above the higher of the two bases
    """
    x = np.asarray(x, dtype=float)
    peaks = []
    i = 1
    while i < x.size - 1:
        if x[i - 1] < x[i]:
            ahead = i + 1
            while ahead < x.size - 1 and x[ahead] == x[i]:
                ahead += 1
            if x[ahead] < x[i]:
                peaks.append((i + ahead - 1) // 2)
                i = ahead
        i += 1
    prominences = []
    for p in peaks:
        left = p
        while left > 0 and x[left - 1] <= x[p]:
            left -= 1
        right = p
        while right < x.size - 1 and x[right + 1] <= x[p]:
            right += 1
        prominences.append(x[p] - max(x[left : p + 1].min(), x[p : right + 1].min()))
    return np.array(peaks, dtype=int), np.array(prominences, dtype=float)


def resolving_nperseg(recording, freq_hz, damping, lines_per_bandwidth: int, min_segments: int) -> int:
    """Welch segment length whose line spacing puts ``lines_per_bandwidth`` lines in the half-power
    bandwidth ``2 xi f`` of the narrowest mode: a power of two, at least 256 samples, within the
    record's ``min_segments`` half-overlapping segments (whichever the record allows).

    Parameters
    ----------
    recording : Recording
    freq_hz, damping : (n_modes,) array_like
        The modes (Hz, ratio); none: the longest segment the record allows.
    lines_per_bandwidth, min_segments : int
        The resolution asked (``armaxmodal.modes.settings.Resolution``).

    Returns
    -------
    int
        Samples per segment.
    """
    bw = 2 * np.min(np.asarray(damping, float) * np.asarray(freq_hz, float)) if len(freq_hz) else 0.0
    longest = 2 * recording.n_samples // (min_segments + 1)
    want = recording.fs * lines_per_bandwidth / bw if bw > 0 else longest
    return int(np.clip(2 ** int(np.ceil(np.log2(max(want, 16)))), min(256, longest), longest))


def coherent_peaks(recording, nperseg: int, span_lines: int, band=None) -> list[tuple[float, str, float]]:
    """Clear, coherent peaks of each sensor's measured FRF: ``(freq_hz, sensor, |H1|)``.

    A clear peak: coherence at least 0.8 on it and two lines either side, a third of its
    height above both neighbouring valleys, the highest within ``span_lines`` lines either
    side (a mode spans that many lines at the resolution of :func:`resolving_nperseg` with as
    many lines per bandwidth; a noise bump is a line or two wide), and at least 5 % of the
    sensor's strongest coherent response.
    """
    f, h, coh = measured_frf(recording, nperseg)
    lo, hi = band if band is not None else excited_band(recording)
    out = []
    for k, sensor in enumerate(recording.sensors):
        mag = np.abs(h[:, k])
        ok = (coh[:, k] >= H1_COHERENCE) & (f >= lo) & (f <= hi)
        if not ok.any():
            continue
        peaks, prominences = peak_prominences(np.where(ok, mag, 0.0))
        for i, prom in zip(peaks, prominences, strict=True):
            span = slice(max(i - span_lines, 0), i + span_lines + 1)
            if prom < 0.33 * mag[i] or mag[i] < 0.05 * mag[ok].max() or mag[i] < mag[span].max():
                continue
            if ok[max(i - 2, 0) : i + 3].all():
                out.append((float(f[i]), sensor, float(mag[i])))
    return out


def explains(freq_hz: float, line_hz: float, modes_hz, damping) -> bool:
    """A mode lies within the peak's half-power bandwidth ``2 xi f`` (at least 1 % or 3 lines)."""
    return any(
        abs(freq_hz - fm) <= max(2 * fm * x, 0.01 * fm, 3 * line_hz) for fm, x in zip(modes_hz, damping, strict=True)
    )


#: the local polynomial method's window: lines either side of each line, and the polynomials'
#: degree (Pintelon, Schoukens, Vandersteen & Barbé 2010: degree 2, and at least as many lines
#: either side as unknowns, so that the noise estimate keeps 2R + 1 - 2(degree + 1) = 7 degrees of
#: freedom a line)
LPM_HALF_WIDTH, LPM_DEGREE = 6, 2


def local_polynomial_noise(
    u: np.ndarray, y: np.ndarray, half_width: int = LPM_HALF_WIDTH, degree: int = LPM_DEGREE
) -> np.ndarray:
    """The noise variance of each output's DFT line, measured without a parametric model.

    The local polynomial method (Pintelon, Schoukens, Vandersteen and Barbé, Mechanical Systems and
    Signal Processing 24, 2010, 573-595). Around each line ``k``, ``Y(k+r) = G(r) U(k+r) + T(r) + V(k+r)`` for
    ``r = -R..R``, with ``G`` (the FRF) and ``T`` (the leakage of a finite record) polynomials of
    ``degree`` in ``r``, fitted by least squares; the residual's power over its degrees of freedom is
    the variance at ``k``. Windows at the band's ends are shifted inwards. No package for Python
    implements it (MATLAB's frequency-domain toolboxes do); it is a batched least squares.

    Parameters
    ----------
    u : (n_lines,) complex ndarray
        The input's DFT lines, equally spaced.
    y : (n_lines, n_outputs) complex ndarray
        The outputs' DFT lines (a model's residual will do: what it holds beyond the noise is
        then smooth only where the model is right).
    half_width : int
        ``R``, lines either side.
    degree : int
        Degree of the local polynomials.

    Returns
    -------
    (n_lines, n_outputs) ndarray
        ``E |V(k)|^2`` of each line, in the units of ``y`` squared.

    Raises
    ------
    ValueError
        Arrays of other shapes, or fewer lines than a window holds.

    See Also
    --------
    armaxmodal.modes.mode_count.model_adequacy : Compares a model's residual with it.

    Examples
    --------
    >>> import numpy as np
    >>> from armaxmodal.spectra import local_polynomial_noise
    >>> rng = np.random.default_rng(0)
    >>> u = rng.standard_normal(4000) + 1j * rng.standard_normal(4000)
    >>> g = 1.0 / (1.0 + 1j * np.linspace(0.0, 3.0, 4000))  # a smooth FRF
    >>> noise = 0.1 * (rng.standard_normal(4000) + 1j * rng.standard_normal(4000))  # E|V|^2 = 0.02
    >>> var = local_polynomial_noise(u, (g * u + noise)[:, None])
    >>> round(float(var.mean()), 3)
    0.02
    """
    u, y = np.asarray(u, complex), np.asarray(y, complex)
    if u.ndim != 1 or y.ndim != 2 or y.shape[0] != u.size:
        raise ValueError(
            f"local_polynomial_noise: expected u of shape (n_lines,) and y of shape (n_lines, n_outputs), "
            f"got {u.shape} and {y.shape}: give one output per column, on the input's lines."
        )
    n, width, unknowns = u.size, 2 * half_width + 1, 2 * (degree + 1)
    if n < width or width <= unknowns:
        raise ValueError(
            f"local_polynomial_noise: {n} lines, window of {width} for {unknowns} unknowns: "
            "give more lines or a wider window."
        )
    centres = np.clip(np.arange(n), half_width, n - 1 - half_width)
    rows = centres[:, None] + np.arange(-half_width, half_width + 1)[None, :]  # (n, width): each line's window
    offset = (rows - np.arange(n)[:, None]) / half_width  # scaled, so the powers stay of order one
    powers = offset[..., None] ** np.arange(degree + 1)  # (n, width, degree + 1)
    basis, _ = np.linalg.qr(np.concatenate([powers * u[rows][..., None], powers], axis=-1))
    windows = y[rows]  # (n, width, n_outputs)
    residual = windows - basis @ (np.conj(np.swapaxes(basis, 1, 2)) @ windows)
    return np.sum(np.abs(residual) ** 2, axis=1) / (width - unknowns)
