"""Does the modal model explain the measured FRF? The FRF rebuilt from the selected modes
against an H1 fine enough to resolve the narrowest of them, and the clear, coherent FRF
peaks no selected mode accounts for (thesis Section 3.3.3's check, made quantitative)."""

from __future__ import annotations

import numpy as np

from .frf import coherence, excited_band, modal_frf, welch_spectra
from .quality import QualityWarning
from .recording import Recording

__all__ = ["resolving_nperseg", "reconstruction_error", "unexplained_peaks", "coherent_peaks", "peak_support"]

#: lines per half-power bandwidth of the narrowest mode the comparison needs
LINES_PER_BANDWIDTH = 4
#: fewest Welch segments kept (the H1's random error grows as segments get fewer)
MIN_SEGMENTS = 4
MIN_COHERENCE = 0.8


def resolving_nperseg(recording: Recording, freq_hz, damping) -> int:
    """Welch segment length whose line spacing puts :data:`LINES_PER_BANDWIDTH` lines in the
    half-power bandwidth ``2 xi f`` of the narrowest mode, within 8 s and the record (at least
    :data:`MIN_SEGMENTS` half-overlapping segments)."""
    bw = 2 * np.min(np.asarray(damping, float) * np.asarray(freq_hz, float)) if len(freq_hz) else 0.0
    longest = 2 * recording.n_samples // (MIN_SEGMENTS + 1)
    want = recording.fs * LINES_PER_BANDWIDTH / bw if bw > 0 else longest
    return int(np.clip(2 ** int(np.ceil(np.log2(max(want, 16)))), min(256, longest), longest))


def _measured(recording: Recording, nperseg: int):
    f, puu, puy, pyy = welch_spectra(recording.base, recording.response, recording.fs, nperseg)
    return f, puy / puu[:, None], coherence(puu, puy, pyy)


def reconstruction_error(recording: Recording, freq_hz, damping, shapes, band=None) -> tuple[float, int]:
    """Relative RMS difference between the FRF rebuilt from the modes and the measured H1,
    over lines in ``band`` (default: the excited band) where every sensor's coherence is at
    least 0.8, at the resolution of :func:`resolving_nperseg`. Each sensor's rebuilt FRF gets
    a constant residual term (least squares), the usual stand-in for modes outside the band
    and a direct term. Returns ``(error, nperseg)``; the error is NaN without such lines."""
    n = resolving_nperseg(recording, freq_hz, damping)
    f, h, coh = _measured(recording, n)
    lo, hi = band if band is not None else excited_band(recording)
    good = (np.min(coh, axis=1) >= MIN_COHERENCE) & (f > 0) & (f >= lo) & (f <= hi)
    if not good.any():
        return float("nan"), n
    rebuilt = modal_frf(f[good], freq_hz, damping, shapes)
    rebuilt = rebuilt + np.mean(h[good] - rebuilt, axis=0, keepdims=True)
    return float(np.linalg.norm(rebuilt - h[good]) / np.linalg.norm(h[good])), n


def peak_prominences(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima of ``x`` and their prominences, as ``scipy.signal.find_peaks(x,
    prominence=0)`` gives them (a plateau's peak at its middle, rounded down).

    Written here because importing ``scipy.signal`` imports ``scipy.stats``: 0.8 s of every
    ``stabilise`` run, for a few hundred lines of one spectrum (``tests/test_frf_check.py``
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
    height above both neighbouring valleys, the highest within :data:`LINES_PER_BANDWIDTH`
    lines either side (a mode spans that many lines at the resolution of
    :func:`resolving_nperseg`; a noise bump is a line or two wide), and at least 5 % of the
    sensor's strongest coherent response.
    """
    f, h, coh = _measured(recording, nperseg)
    lo, hi = band if band is not None else excited_band(recording)
    out = []
    for k, sensor in enumerate(recording.sensors):
        mag = np.abs(h[:, k])
        ok = (coh[:, k] >= MIN_COHERENCE) & (f >= lo) & (f <= hi)
        if not ok.any():
            continue
        peaks, prominences = peak_prominences(np.where(ok, mag, 0.0))
        for i, prom in zip(peaks, prominences, strict=True):
            span = slice(max(i - LINES_PER_BANDWIDTH, 0), i + LINES_PER_BANDWIDTH + 1)
            if prom < 0.33 * mag[i] or mag[i] < 0.05 * mag[ok].max() or mag[i] < mag[span].max():
                continue
            if ok[max(i - 2, 0) : i + 3].all():
                out.append((float(f[i]), sensor, float(mag[i])))
    return out


def _explains(freq_hz: float, line_hz: float, modes_hz, damping) -> bool:
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
    return _merged([p for p in peaks if not _explains(p[0], df, freq_hz, damping)], df)


def peak_support(recording: Recording, freq_hz: float, damping: float, band=None) -> float | None:
    """Frequency of the clear, coherent FRF peak (:func:`coherent_peaks`) that a mode at
    ``freq_hz`` explains, or None: the data's own evidence for a mode whose poles alone are
    not conclusive (a lightly damped pole whose damping estimate crosses zero)."""
    n = resolving_nperseg(recording, [freq_hz], [max(damping, 1e-6)])
    df = recording.fs / n
    near = [p for p in coherent_peaks(recording, n, band) if _explains(p[0], df, [freq_hz], [max(damping, 0.0)])]
    return max(near, key=lambda p: p[2])[0] if near else None


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
            "(run 'armaxmodal diagnose')", f0,
        ))  # fmt: skip
    return warnings


# -- close modes: is a split of one peak what the data need? --------------------------------
#: a split is kept when the FRF with both modes fits significantly better than with one (F-test)
SPLIT_ALPHA = 0.01


def close_pairs(freq_hz, damping) -> list[tuple[int, int]]:
    """Neighbouring modes whose half-power bands overlap (``|f_i - f_j| < xi_i f_i + xi_j f_j``)."""
    f, x = np.asarray(freq_hz, float), np.asarray(damping, float)
    order = np.argsort(f)
    return [
        (int(i), int(j))
        for i, j in zip(order[:-1], order[1:], strict=True)
        if f[j] - f[i] < x[i] * f[i] + x[j] * f[j]
    ]


def _modal_basis(f: np.ndarray, freq_hz, damping) -> np.ndarray:
    """Real least-squares basis of ``sum_m r_m/(iw - l_m) + conj(r_m)/(iw - conj(l_m)) + c``
    with complex r_m and c: columns for Re r_m, Im r_m, Re c, Im c (complex valued)."""
    w = 2j * np.pi * f[:, None]
    wn = 2 * np.pi * np.asarray(freq_hz, float)
    x = np.asarray(damping, float)
    lam = -x * wn + 1j * wn * np.sqrt(np.clip(1 - x**2, 0.0, None))
    a, b = 1.0 / (w - lam), 1.0 / (w - np.conj(lam))
    ones = np.ones((f.size, 1))
    return np.hstack([a + b, 1j * (a - b), ones, 1j * ones])


def split_test(recording: Recording, freq_hz, damping, weaker: int, band=None) -> tuple[float, float]:
    """Does the measured FRF need mode ``weaker`` beside the others? ``(F, p)``.

    Each sensor's H1 (at the resolution of :func:`resolving_nperseg`, coherent lines of the
    band, every other line as overlapped segments make neighbours correlated) is fitted by
    linear least squares with the modes' poles fixed -- a complex residue per mode and
    sensor and a complex constant -- weighted by the H1's own random error. With and without
    the mode, the residual sums give ``F = ((RSS_without - RSS_with) / q) / (RSS_with / dof)``
    with q = 2 per sensor (its residue) + 2 (its pole, chosen from the same data).
    """
    from scipy.special import fdtrc  # F survival function without scipy.stats' 0.5 s import

    from .frf import h1_relative_error

    n = resolving_nperseg(recording, freq_hz, damping)
    f, h, coh = _measured(recording, n)
    lo, hi = band if band is not None else excited_band(recording)
    good = (np.min(coh, axis=1) >= MIN_COHERENCE) & (f > 0) & (f >= lo) & (f <= hi)
    idx = np.flatnonzero(good)[::2]
    sigma = h1_relative_error(coh[idx], recording.n_samples, n) * np.abs(h[idx])  # (lines, sensors)
    keep = [m for m in range(len(freq_hz)) if m != weaker]
    rss = []
    for modes in (range(len(freq_hz)), keep):
        basis = _modal_basis(f[idx], np.asarray(freq_hz)[list(modes)], np.asarray(damping)[list(modes)])
        total = 0.0
        for k in range(h.shape[1]):
            a = basis / sigma[:, k : k + 1]
            y = h[idx, k] / sigma[:, k]
            a_real, y_real = np.vstack([a.real, a.imag]), np.concatenate([y.real, y.imag])
            coef = np.linalg.lstsq(a_real, y_real, rcond=None)[0]
            total += float(np.sum((y_real - a_real @ coef) ** 2))
        rss.append(total)
    n_obs = 2 * idx.size * h.shape[1]
    q = 2 * h.shape[1] + 2
    dof = n_obs - (2 * len(freq_hz) + 2) * h.shape[1] - 2 * len(freq_hz)
    if dof <= 0 or rss[0] <= 0:
        return float("nan"), float("nan")
    stat = ((rss[1] - rss[0]) / q) / (rss[0] / dof)
    return float(stat), float(fdtrc(q, dof, stat))
