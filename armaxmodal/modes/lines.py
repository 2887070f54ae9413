"""The measured H1 on the coherent lines of a band, at a resolution chosen from the modes.

Two checks read the measured FRF, each at its own resolution, named here so that one does not
borrow the other's: the search for clear FRF peaks no mode explains
(:mod:`armaxmodal.modes.frf_check`) and the modal-model check
(:mod:`armaxmodal.modes.modal_check`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from armaxmodal.modes.settings import CHECK_RESOLUTION, PEAK_RESOLUTION, Resolution
from armaxmodal.recording import Recording
from armaxmodal.spectra import coherence, excited_band, h1_relative_error
from armaxmodal.stats import H1_COHERENCE

__all__ = ["CHECK_RESOLUTION", "CoherentLines", "PEAK_RESOLUTION", "Resolution", "coherent_lines", "measured_h1",
           "resolving_nperseg"]  # fmt: skip


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
