"""What the measured FRF says: the H1 on the coherent lines of a band, at a resolution chosen from
the modes, and its clear, coherent peaks with those no selected mode accounts for (thesis Section
3.3.3's check, made quantitative).

Two checks read the measured FRF, each at its own resolution, named here so that one does not
borrow the other's: the search for clear FRF peaks no mode explains (``unexplained_peaks``, at
``PEAK_RESOLUTION``) and the modal-model check (:mod:`armaxmodal.modes.modal_check`, at
``CHECK_RESOLUTION``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from armaxmodal.modes.settings import CHECK_RESOLUTION, PEAK_RESOLUTION, Resolution
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording
from armaxmodal.spectra import coherence, excited_band, h1_relative_error
from armaxmodal.stats import H1_COHERENCE

__all__ = ["CHECK_RESOLUTION", "CoherentLines", "PEAK_RESOLUTION", "Resolution", "coherent_lines", "coherent_peaks",
           "explains", "measured_h1", "peak_support", "resolving_nperseg", "unexplained_peaks"]  # fmt: skip



def resolving_nperseg(recording: Recording, freq_hz, damping, resolution: Resolution = PEAK_RESOLUTION) -> int:
    """Welch segment length whose line spacing puts ``resolution.lines_per_bandwidth`` lines in
    the half-power bandwidth ``2 xi f`` of the narrowest mode: a power of two, at least 256
    samples, within the record's ``resolution.min_segments`` half-overlapping segments (whichever
    the record allows).

    Parameters
    ----------
    recording : Recording
    freq_hz, damping : (n_modes,) array_like
        The modes (Hz, ratio); none: the longest segment the record allows.
    resolution : Resolution

    Returns
    -------
    int
        Samples per segment.
    """
    bw = 2 * np.min(np.asarray(damping, float) * np.asarray(freq_hz, float)) if len(freq_hz) else 0.0
    longest = 2 * recording.n_samples // (resolution.min_segments + 1)
    want = recording.fs * resolution.lines_per_bandwidth / bw if bw > 0 else longest
    return int(np.clip(2 ** int(np.ceil(np.log2(max(want, 16)))), min(256, longest), longest))


def measured_h1(recording: Recording, nperseg: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every sensor's H1 over the base input and its coherence.

    Returns
    -------
    freq_hz : (n_lines,) ndarray
    h1 : (n_lines, n_sensors) complex ndarray
    coherence : (n_lines, n_sensors) ndarray
    """
    f, puu, puy, pyy = recording.welch(nperseg)
    return f, puy / puu[:, None], coherence(puu, puy, pyy)


@dataclass(frozen=True)
class CoherentLines:
    """One output's coherent lines of a band: frequencies (Hz), the H1 there and its random
    error (absolute, Bendat & Piersol's from the coherence)."""

    freq_hz: np.ndarray
    h: np.ndarray
    sigma: np.ndarray


def coherent_lines(recording: Recording, nperseg: int, band=None) -> list[CoherentLines]:
    """Each output's H1 on the lines of ``band`` (Hz; default: the input's excited band) where
    its coherence is at least :data:`~armaxmodal.stats.H1_COHERENCE`, with its random error.

    Returns
    -------
    list of CoherentLines
        One per output, in the recording's sensor order (possibly with no line).
    """
    f, h, coh = measured_h1(recording, nperseg)
    lo, hi = band if band is not None else excited_band(recording)
    out = []
    for k in range(h.shape[1]):
        good = (coh[:, k] >= H1_COHERENCE) & (f > 0) & (f >= lo) & (f <= hi)
        sigma = h1_relative_error(coh[good, k], recording.n_samples, nperseg) * np.abs(h[good, k])
        out.append(CoherentLines(f[good], h[good, k], sigma))
    return out


#: a clear peak is the highest within this many lines either side: the narrowest mode spans
#: that many at :data:`PEAK_RESOLUTION`, a noise bump a line or two
PEAK_SPAN_LINES = PEAK_RESOLUTION.lines_per_bandwidth


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


def coherent_peaks(recording: Recording, nperseg: int, band=None) -> list[tuple[float, str, float]]:
    """Clear, coherent peaks of each sensor's measured FRF: ``(freq_hz, sensor, |H1|)``.

    A clear peak: coherence at least 0.8 on it and two lines either side, a third of its
    height above both neighbouring valleys, the highest within :data:`PEAK_SPAN_LINES`
    lines either side (a mode spans that many lines at the resolution of
    :func:`resolving_nperseg`; a noise bump is a line or two wide), and at least 5 % of the
    sensor's strongest coherent response.
    """
    f, h, coh = measured_h1(recording, nperseg)
    lo, hi = band if band is not None else excited_band(recording)
    out = []
    for k, sensor in enumerate(recording.sensors):
        mag = np.abs(h[:, k])
        ok = (coh[:, k] >= H1_COHERENCE) & (f >= lo) & (f <= hi)
        if not ok.any():
            continue
        peaks, prominences = peak_prominences(np.where(ok, mag, 0.0))
        for i, prom in zip(peaks, prominences, strict=True):
            span = slice(max(i - PEAK_SPAN_LINES, 0), i + PEAK_SPAN_LINES + 1)
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


def unexplained_peaks(recording: Recording, freq_hz, damping, band=None) -> list[QualityWarning]:
    """Coherent peaks of the measured FRF (:func:`coherent_peaks`) with no selected mode
    within its half-power bandwidth: each a ``unexplained_peak`` warning."""
    n = resolving_nperseg(recording, freq_hz, damping)
    df = recording.fs / n
    peaks = coherent_peaks(recording, n, band)
    return _merged([p for p in peaks if not explains(p[0], df, freq_hz, damping)], df)


def _merged(peaks, df) -> list[QualityWarning]:
    """One warning per peak seen on several sensors (within 3 % or 3 lines of each other)."""
    groups: list[list] = []
    for p in sorted(peaks):
        if groups and p[0] - groups[-1][-1][0] <= max(0.03 * p[0], 3 * df):
            groups[-1].append(p)
        else:
            groups.append([p])
    warnings = []
    for g in groups:
        f0 = max(g, key=lambda p: p[2])[0]
        sensors = tuple(sorted({p[1] for p in g}))
        warnings.append(QualityWarning(
            "unexplained_peak", sensors,
            f"the measured FRF has a clear, coherent peak at {f0:.2f} Hz ({', '.join(sensors)}) that no "
            "selected mode explains: a mode the selection missed (widen --orders or --modes), or a disturbance "
            "(run 'armaxmodal diagnose')", f0, (f0,),
        ))  # fmt: skip
    return warnings


def peak_support(recording: Recording, freq_hz: float, damping: float, band=None) -> float | None:
    """Frequency of the clear, coherent FRF peak (:func:`coherent_peaks`) that a mode at
    ``freq_hz`` explains, or None: the data's own evidence for a mode whose poles alone are
    not conclusive (a lightly damped pole whose damping estimate crosses zero)."""
    n = resolving_nperseg(recording, [freq_hz], [max(damping, 1e-6)])
    df = recording.fs / n
    near = [p for p in coherent_peaks(recording, n, band) if explains(p[0], df, [freq_hz], [max(damping, 0.0)])]
    return max(near, key=lambda p: p[2])[0] if near else None
