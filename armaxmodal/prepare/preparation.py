"""Prepare a recording for identification: quality checks, then what a user expects done.

In this order, every step stated in the result (and in the JSON):

1. the band is validated (finite, ``0 <= lo < hi <=`` Nyquist) before any work;
2. :func:`~armaxmodal.prepare.check_quality` on the raw record;
3. outputs that duplicate another channel are left out (a copy adds no information and,
   pooled with its original, gives zero-width intervals), and so are outputs that do not
   respond to the input while another does (pooled, they bend the shared poles);
4. an output in other units than the rest whose quasi-static ratio matches a unit conversion
   (:mod:`armaxmodal.prepare.units`) is converted by that exact factor; channels found late or early
   by whole samples are aligned (a sensor with its own clock);
5. each channel's mean (default) or linear trend is removed, so gravity on an accelerometer
   and sensor offsets do not bias the modes (MATLAB's ``detrend``), and so is a level shift
   where a sensor's offset jumps mid-record (:mod:`armaxmodal.prepare.detrend`);
6. a record sampled far above its band is resampled to about ``fs = band_hi / 0.4`` with
   scipy's polyphase filter (:mod:`armaxmodal.prepare.resample`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from armaxmodal._validate import check_outputs_carry_signal
from armaxmodal.exceptions import DataError
from armaxmodal.prepare.checks import check_quality
from armaxmodal.prepare.delay import estimate_delays
from armaxmodal.prepare.detrend import DETRENDS
from armaxmodal.prepare.detrend import detrend as detrend_channels
from armaxmodal.prepare.resample import resample_to_band
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording

__all__ = ["prepare", "Preparation", "check_band"]


@dataclass(frozen=True)
class Preparation:
    """What was done to a recording before fitting.

    Attributes
    ----------
    recording : Recording
        The record to fit (aligned, detrended, resampled).
    original_fs : float
        Sampling rate of the file, Hz.
    analysis_fs : float
        Sampling rate of ``recording``, Hz.
    band : (lo, hi) or None
        The user's band, Hz.
    detrend : str
        ``"mean"``, ``"linear"`` or ``"none"``.
    dropped : tuple of str
        Outputs left out: duplicates, and outputs that do not respond to the input
        (``incoherent_output``) while another output does.
    shifts : dict
        Channel -> samples it was moved earlier at the original rate (positive: it lagged).
    warnings : tuple of QualityWarning

    See Also
    --------
    armaxmodal.prepare.prepare : What makes one.
    armaxmodal.prepare.check_quality : The checks whose notes it carries.

    Examples
    --------
    A ride logged at 240 Hz for a 0.5-25 Hz band is fitted at a lower rate:

    >>> import armaxmodal as am
    >>> from armaxmodal.prepare import prepare
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(240.0, 60.0, seed=1), 240.0,
    ...                              noise=0.03, seed=2)
    >>> prep = prepare(ride, band=(0.5, 25.0))
    >>> prep.original_fs, prep.analysis_fs, prep.recording.n_samples, prep.dropped
    (240.0, 80.0, 4780, ())
    """

    recording: Recording
    original_fs: float
    analysis_fs: float
    band: tuple[float, float] | None
    detrend: str
    dropped: tuple[str, ...]
    shifts: dict
    warnings: tuple[QualityWarning, ...]

    def to_dict(self) -> dict:
        return {
            "original_fs": self.original_fs,
            "analysis_fs": self.analysis_fs,
            "band": None if self.band is None else list(self.band),
            "detrend": self.detrend,
            "dropped_channels": list(self.dropped),
            "shifts_samples": {k: int(v) for k, v in self.shifts.items()},
        }


def check_band(band, fs: float | None = None) -> tuple[float, float] | None:
    """Return ``band`` as ``(lo, hi)`` in Hz, or raise :class:`DataError` naming the fix."""
    if band is None:
        return None
    try:
        lo, hi = (float(v) for v in band)
    except (TypeError, ValueError) as exc:
        raise DataError(f"band: expected (lo, hi) in Hz, got {band!r}.") from exc
    if not (np.isfinite(lo) and np.isfinite(hi)):
        raise DataError(f"band: expected finite frequencies in Hz, got {band!r}.")
    if lo < 0 or lo >= hi:
        raise DataError(f"band: expected 0 <= lo < hi in Hz, got {lo:g}:{hi:g}; give the lower edge first.")
    if fs is not None and hi > fs / 2:
        raise DataError(
            f"band: the upper edge {hi:g} Hz is above the Nyquist frequency {fs / 2:g} Hz of this "
            f"{fs:g} Hz record; nothing above it was recorded. Use a band below {fs / 2:g} Hz."
        )
    return lo, hi


def prepare(
    recording: Recording,
    *,
    band: tuple[float, float] | None = None,
    detrend: str = "mean",
    resample: bool = True,
    align: bool = True,
    drop_incoherent: bool = True,
) -> Preparation:
    """Check and prepare ``recording`` for identification (see the module docstring).

    Parameters
    ----------
    recording : Recording
    band : (lo, hi), optional
        Frequency band of interest, Hz; its upper edge sets the analysis rate.
    detrend : {"mean", "linear", "none"}
        Remove each channel's mean (default) or least-squares line.
    resample : bool
        Resample to a rate suited to the band when the record is sampled far above it.
    align : bool
        Move channels found late or early by whole samples into line.
    drop_incoherent : bool
        Leave out outputs that do not respond to the input while another does (the
        diagnosis keeps them: such a channel may be a second input it names).

    Returns
    -------
    Preparation

    See Also
    --------
    armaxmodal.prepare.Preparation : What it returns.
    armaxmodal.stabilisation_diagram : Prepares the record itself, then sweeps.

    Examples
    --------
    >>> import armaxmodal as am
    >>> from armaxmodal.prepare import prepare
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=1), 60.0, noise=0.03,
    ...                              seed=2)
    >>> prep = prepare(ride)  # a clean ride: nothing dropped, shifted or resampled
    >>> prep.analysis_fs, prep.detrend, prep.dropped, len(prep.warnings)
    (60.0, 'mean', (), 0)
    """
    band = check_band(band, recording.fs)
    if detrend not in DETRENDS:
        raise DataError(f"detrend: expected one of {DETRENDS}, got {detrend!r}.")
    check_outputs_carry_signal(recording.sensors, recording.response)
    found = list(recording.meta.get("read_warnings", ())) + check_quality(recording)
    dropped = tuple(w.channels[0] for w in found if w.code == "duplicate_channel")
    keep = [s for s in recording.sensors if s not in dropped]
    if not keep:
        raise DataError(
            f"every output duplicates another channel ({', '.join(dropped)}); nothing independent is left to fit."
        )
    # an output that does not respond to the input, pooled with those that do, bends the
    # shared poles to its own spectrum (a temperature channel moved the supine ride's
    # 13.7 Hz mode to 15.0 Hz): left out while a responding output remains
    incoherent = {c for w in found if w.code == "incoherent_output" for c in w.channels}
    if drop_incoherent and any(s not in incoherent for s in keep):
        dropped += tuple(s for s in keep if s in incoherent)
        keep = [s for s in keep if s not in incoherent]
        # the scale of a channel left out matters to nothing fitted (its advice would mislead)
        found = [w for w in found if not (w.code == "unit_mismatch" and w.channels[0] in dropped)]
        found = [_left_out(w) if w.code == "incoherent_output" else w for w in found]
    dropped, keep, found = _leave_out_held(found, keep, dropped, band)
    rec = recording.select(keep) if dropped else recording
    rec, found = _convert_units(rec, found)
    shifts = _whole_sample_shifts(found, rec) if align else {}
    if shifts:
        rec = _align(rec, shifts)
        found = [_note_alignment(w, shifts) for w in found]
    rec, removed = detrend_channels(rec, detrend)
    found += removed
    analysis_fs = rec.fs
    if resample:
        rec, note = resample_to_band(rec, band)
        if note is not None:
            found.append(note)
            analysis_fs = rec.fs
    meta = dict(rec.meta, preprocessing={"detrend": detrend, "analysis_fs": analysis_fs})
    rec = rec.with_meta(meta)  # keeps the spectra the steps above computed
    return Preparation(rec, recording.fs, analysis_fs, band, detrend, dropped, shifts, tuple(found))


def _leave_out_held(found: list, keep: list, dropped: tuple, band) -> tuple[tuple, list, list]:
    """Outputs held from a lower rate (``held_samples``) are left out while an output at the
    record's rate remains: their images bent the shared poles (the supine ride with head held
    at half rate lost two of its four modes). A band below 0.4 of a channel's own rate keeps it:
    the resampling's anti-alias filter removes the images."""
    top = band[1] if band is not None else np.inf
    held = {w.channels[0] for w in found if w.code == "held_samples" and top > 0.4 * w.value}
    held &= set(keep)
    if not held or all(s in held for s in keep):
        return dropped, keep, found
    notes = [
        replace(w, message=w.message.rstrip(".") + "; it was left out of the fit.")
        if w.code == "held_samples" and w.channels[0] in held
        else w
        for w in found
    ]
    return dropped + tuple(s for s in keep if s in held), [s for s in keep if s not in held], notes


def _left_out(w: QualityWarning) -> QualityWarning:
    return replace(w, message=w.message.rstrip(".") + "; they were left out of the fit.")


def _convert_units(rec: Recording, found: list[QualityWarning]) -> tuple[Recording, list[QualityWarning]]:
    """Divide each ``unit_mismatch`` output whose ratio matches a unit conversion by that
    exact factor, and say so in its warning."""
    from armaxmodal.prepare.units import unit_conversion

    response, notes = rec.response.copy(), []
    for w in found:
        match = unit_conversion(w.value) if w.code == "unit_mismatch" and w.channels[0] in rec.sensors else None
        if match is not None:
            response[:, rec.sensors.index(w.channels[0])] /= match[0]
            note = f" Divided by {match[0]:.5g} before fitting; shapes are in the others' units."
            w = replace(w, message=w.message + note)
        notes.append(w)
    return replace(rec, response=response), notes


def _whole_sample_shifts(found: list[QualityWarning], rec: Recording) -> dict:
    """Channel -> whole samples it lags (from ``sensor_delay`` warnings), zeros left out.

    A late sensor is timed against the outputs on time, not against the input: a held input
    puts about half a sample on every output, and a sensor 3 samples late then reads 3.5-3.7
    (aligning it by 4 would leave it a sample early against the others)."""
    late = [w for w in found if w.code == "sensor_delay" and w.value is not None]
    late = [w for w in late if w.channels[0] in (rec.input_name, *rec.sensors)]
    reference_s = 0.0
    if any(w.channels[0] != rec.input_name for w in late):
        flagged = {w.channels[0] for w in late}
        on_time = [e.delay_s for e in estimate_delays(rec) if e.channel not in flagged]
        reference_s = float(np.median(on_time)) if on_time else 0.0
    shifts = {}
    for w in late:
        offset = reference_s if w.channels[0] != rec.input_name else 0.0
        samples = int(round((w.value * 1e-3 - offset) * rec.fs))
        if samples != 0:
            shifts[w.channels[0]] = samples
    return shifts


def _align(rec: Recording, shifts: dict) -> Recording:
    """Take each channel ``shifts[c]`` samples later in the file (it lagged), trimming ends."""
    names = [rec.input_name, *rec.sensors]
    offsets = np.array([shifts.get(c, 0) for c in names])
    offsets -= offsets.min()
    length = rec.n_samples - int(offsets.max())
    if length < rec.n_samples // 2:
        raise DataError(f"aligning channels by {shifts} samples leaves too little record; check the time stamps.")
    data = np.column_stack([rec.base, rec.response])
    cols = [data[o : o + length, i] for i, o in enumerate(offsets)]
    return replace(rec, base=cols[0], response=np.column_stack(cols[1:]))


def _note_alignment(w: QualityWarning, shifts: dict) -> QualityWarning:
    if w.code != "sensor_delay" or w.channels[0] not in shifts:
        return w
    n = shifts[w.channels[0]]
    return replace(w, message=w.message + f" Aligned by {abs(n)} sample{'s' if abs(n) != 1 else ''}.")
