"""What a result says of its record: the opening keys of its JSON, and whether the record was
sampled far above the modes found (both read the modes, so they live with them)."""

from __future__ import annotations

import numpy as np

from armaxmodal.modes.settings import DEFAULTS, NoteSettings
from armaxmodal.prepare.preparation import Preparation
from armaxmodal.prepare.resample import BAND_FRACTION_OF_FS
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording

__all__ = ["oversampling_note", "record_header"]


def oversampling_note(mode_freqs: np.ndarray, fs: float, settings: NoteSettings = DEFAULTS.notes
                      ) -> list[QualityWarning]:  # fmt: skip
    """An ``oversampled`` warning when every mode found lies below
    ``settings.oversampled_fraction`` of the Nyquist frequency: the input excites far above the
    structure (so the rate was kept), the poles crowd ``z = 1`` and the swept orders resolve
    them poorly (the supine ride at 1 kHz under a 0.5-400 Hz ride gave one of its four modes;
    with the band suggested here, all four). The band suggested ends at
    ``settings.suggested_band_factor`` times the highest mode found.

    Parameters
    ----------
    mode_freqs : (n_modes,) ndarray
        Natural frequencies of the modes found, Hz.
    fs : float
        The analysis rate, Hz.
    settings : NoteSettings
        The share of Nyquist that makes a record oversampled, and the band suggested.

    Returns
    -------
    list of QualityWarning
        Empty, or one warning whose value is the highest mode's share of the Nyquist frequency.
    """
    mode_freqs = np.asarray(mode_freqs, dtype=float)
    if mode_freqs.size == 0 or mode_freqs.max() >= settings.oversampled_fraction * fs / 2:
        return []
    top = float(mode_freqs.max())
    hi = float(np.ceil(settings.suggested_band_factor * top))
    factor = int(np.floor(BAND_FRACTION_OF_FS * fs / hi))
    if factor < 2:  # the band suggested keeps the rate: no lower rate to suggest
        return []
    new_fs = fs / factor
    share = top / (fs / 2)
    return [
        QualityWarning(
            "oversampled",
            (),
            f"every mode found lies below {100 * share:.1f} % of the Nyquist frequency (the highest at "
            f"{top:.3g} Hz of {fs / 2:g} Hz): the input excites far above the structure, so the rate was kept, "
            "and at this rate the poles crowd z = 1 where ARMAX models resolve them poorly; modes may be "
            f"missed or biased. Rerun with band=(0, {hi:g}) (CLI: --band 0:{hi:g}), which resamples to "
            f"{new_fs:.4g} Hz.",
            share,
        )
    ]


def record_header(recording: Recording, preparation: Preparation | None, warnings) -> dict:
    """The opening keys of every result's JSON: the rates, what the preparation did, the
    warnings, and the channels.

    Returns
    -------
    dict
        ``fs`` (as recorded), ``analysis_fs``, ``preprocessing``, ``warnings``, ``input``, ``outputs``.
    """
    return {
        "fs": recording.fs if preparation is None else preparation.original_fs,
        "analysis_fs": recording.fs,
        "preprocessing": None if preparation is None else preparation.to_dict(),
        "warnings": [w.to_dict() for w in warnings],
        "input": recording.input_name,
        "outputs": list(recording.sensors),
    }
