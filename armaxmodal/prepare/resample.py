"""Resampling to the band: a record sampled far above its band is brought to about
``fs = band_hi / 0.4`` with scipy's polyphase anti-alias filter (a Kaiser-windowed FIR of zero
phase, written out in ``decimate``). High orders would otherwise be spent on the empty
spectrum above the band, and one low order no longer resolves close modes at 400 Hz that it
resolves at 50 Hz."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording

__all__ = ["BAND_FRACTION_OF_FS", "RESAMPLE_EDGE", "decimate", "oversampling_note", "resample_to_band"]

#: the band's upper edge sits at this fraction of the analysis rate (0.8 of its Nyquist),
#: well inside the anti-alias filter's pass band
BAND_FRACTION_OF_FS = 0.4
#: output samples dropped at each end after resampling (the filter's half length)
RESAMPLE_EDGE = 10


def resample_to_band(rec: Recording, band) -> tuple[Recording, QualityWarning | None]:
    """Decimate by the largest whole factor that keeps the band's upper edge at
    :data:`BAND_FRACTION_OF_FS` of the new rate; the band is the user's or the input's
    excited band (within 30 dB of its peak)."""
    from armaxmodal.spectra import excited_band

    hi = band[1] if band is not None else excited_band(rec)[1]
    factor = int(np.floor(BAND_FRACTION_OF_FS * rec.fs / max(hi, 1e-9)))
    if factor < 2:
        return rec, None
    if rec.n_samples // factor < 40 * RESAMPLE_EDGE:
        return rec, None
    data = decimate(np.column_stack([rec.base, rec.response]), factor)
    new_fs = rec.fs / factor
    out = replace(rec, fs=new_fs, base=data[:, 0], response=data[:, 1:])
    source = "the band" if band is not None else "the input's excited band"
    note = QualityWarning(
        "resampled",
        (),
        # the finding first: the terminal shows a note's first clauses
        f"resampled by 1/{factor} to {new_fs:g} Hz (anti-alias filtered) for the analysis: {source} ends at "
        f"{hi:.3g} Hz, far below the Nyquist frequency {rec.fs / 2:g} Hz.",
        new_fs,
    )
    return out, note


def decimate(data: np.ndarray, factor: int) -> np.ndarray:
    """Anti-alias filter and keep every ``factor``-th sample, minus ``RESAMPLE_EDGE`` samples
    at each end: ``scipy.signal.resample_poly(data, 1, factor, axis=0)[RESAMPLE_EDGE:-RESAMPLE_EDGE]``.

    The same filter as scipy's (``firwin(20 factor + 1, 1 / factor, window=("kaiser", 5.0))``,
    zero phase). Written here because importing ``scipy.signal`` imports ``scipy.stats``: 0.9 s
    of every run that resamples, a sixth of the F-16 record's. The samples kept are those the
    filter computes from the record alone, so scipy's edge padding never enters and the
    result equals scipy's to rounding (tested).

    Parameters
    ----------
    data : (n_samples, n_channels) ndarray
    factor : int
        Decimation factor, >= 2.

    Returns
    -------
    (ceil(n_samples / factor) - 2 RESAMPLE_EDGE, n_channels) ndarray
    """
    half = 10 * factor  # scipy's half length for this rate change
    taps = np.arange(-half, half + 1)
    h = np.sinc(taps / factor) * np.kaiser(2 * half + 1, 5.0)
    h /= h.sum()  # unit gain at 0 Hz, as firwin scales it
    n_out = -(-data.shape[0] // factor) - 2 * RESAMPLE_EDGE
    # output i + RESAMPLE_EDGE is centred on input sample (i + RESAMPLE_EDGE) factor, i.e. on
    # the 'valid' convolution's sample i factor (RESAMPLE_EDGE factor == half)
    return np.column_stack(
        [np.convolve(col, h, mode="valid")[::factor][:n_out] for col in np.asarray(data, dtype=float).T]
    )


def oversampling_note(
    mode_freqs: np.ndarray, fs: float, oversampled_fraction: float, suggested_band_factor: float
) -> list[QualityWarning]:
    """An ``oversampled`` warning when every mode found lies below ``oversampled_fraction`` of the
    Nyquist frequency: the input excites far above the structure (so the rate was kept), the poles
    crowd ``z = 1`` and the swept orders resolve them poorly (the supine ride at 1 kHz under a
    0.5-400 Hz ride gave one of its four modes; with the band suggested here, all four). The band
    suggested ends at ``suggested_band_factor`` times the highest mode found, and the rate it
    resamples to is what :func:`resample_to_band` would choose for it.

    Parameters
    ----------
    mode_freqs : (n_modes,) ndarray
        Natural frequencies of the modes found, Hz.
    fs : float
        The analysis rate, Hz.
    oversampled_fraction, suggested_band_factor : float
        The share of Nyquist that makes a record oversampled, and the band suggested
        (``armaxmodal.modes.settings.NoteSettings``, with their calibration).

    Returns
    -------
    list of QualityWarning
        Empty, or one warning whose value is the highest mode's share of the Nyquist frequency.
    """
    mode_freqs = np.asarray(mode_freqs, dtype=float)
    if mode_freqs.size == 0 or mode_freqs.max() >= oversampled_fraction * fs / 2:
        return []
    top = float(mode_freqs.max())
    hi = float(np.ceil(suggested_band_factor * top))
    factor = int(np.floor(BAND_FRACTION_OF_FS * fs / hi))
    if factor < 2:  # the band suggested keeps the rate: no lower rate to suggest
        return []
    new_fs = fs / factor
    share = top / (fs / 2)
    return [
        QualityWarning(
            "oversampled",
            (),
            f"every mode lies below {100 * share:.1f} % of Nyquist: rerun with --band 0:{hi:g}, which resamples "
            f"to {new_fs:.4g} Hz (in Python band=(0, {hi:g}); the highest mode at {top:.3g} Hz of {fs / 2:g} Hz). "
            "The input excites far above the structure, so the rate was kept, and at this rate the poles crowd "
            "z = 1 where ARMAX models resolve them poorly; modes may be missed or biased.",
            share,
        )
    ]
