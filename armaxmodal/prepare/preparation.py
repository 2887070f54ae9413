"""Prepare a recording for identification: quality checks, then what a user expects done.

In this order, every step stated in the result (and in the JSON):

1. the band is validated (finite, ``0 <= lo < hi <=`` Nyquist) before any work;
2. :func:`armaxmodal.prepare.checks.check_quality` on the raw record;
3. outputs that duplicate another channel are left out (a copy adds no information and,
   pooled with its original, gives zero-width intervals), and so are outputs that do not
   respond to the input while another does (pooled, they bend the shared poles);
4. an output in other units than the rest whose quasi-static ratio matches a unit conversion
   (:mod:`armaxmodal.prepare.units`) is converted by that exact factor; channels found late or early
   by whole samples are aligned (a sensor with its own clock);
5. each channel's mean (default) or linear trend is removed, so gravity on an accelerometer
   and sensor offsets do not bias the modes (MATLAB's ``detrend``), and so is a level shift
   where a sensor's offset jumps mid-record (:func:`level_shifts`; MATLAB's ``detrend`` with
   breakpoints, the breakpoints found);
6. a record sampled far above its band is resampled to about ``fs = band_hi / 0.4`` with
   scipy's polyphase filter (a Kaiser-windowed anti-alias FIR of zero phase, written out in
   :func:`decimate`): high orders would otherwise be spent on the empty spectrum above the
   band, and one low order no longer resolves close modes at 400 Hz that it resolves at 50 Hz.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from armaxmodal._validate import check_outputs_carry_signal
from armaxmodal.exceptions import DataError
from armaxmodal.prepare.checks import check_quality
from armaxmodal.prepare.delay import estimate_delays
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording

__all__ = ["prepare", "Preparation", "check_band", "decimate", "level_shifts", "oversampling_note", "DETRENDS"]

DETRENDS = ("mean", "linear", "none")
#: the band's upper edge sits at this fraction of the analysis rate (0.8 of its Nyquist),
#: well inside the anti-alias filter's pass band
BAND_FRACTION_OF_FS = 0.4
#: every mode found below this share of the Nyquist frequency: the record is oversampled
#: for its structure (the measured records here: 28-66 %; the supine ride at 1 kHz: 3 %)
OVERSAMPLED_FRACTION = 0.1
#: ... and the band suggested ends at this multiple of the highest mode found
SUGGESTED_BAND_FACTOR = 2.5
#: output samples dropped at each end after resampling (the filter's half length)
RESAMPLE_EDGE = 10
#: a line explaining more than this share of a channel's variance is a drift worth a warning
DRIFT_FRACTION = 0.01
#: an offset is worth a warning when it exceeds this fraction of the channel's RMS
OFFSET_FRACTION = 0.05
#: a level shift (a sensor's offset jumping mid-record) is removed when it explains more than
#: this share of a channel's variance (measured recordings stay under 0.03 %, an
#: earthquake's onset included) ...
STEP_FRACTION = 0.01
#: ... and is sudden: the means of the STEP_EDGE-long windows either side of it differ by at
#: least STEP_Z times the spread of such differences along the channel (robust SD), or it is
#: slow wander such as a velocity channel's. The 20 channels of the four fixtures integrated
#: to velocity read 1.1-3.6 at their best breakpoints; a drift, spreading its change over the
#: record, 0.9-2.5 (the supine ride's outputs with 0.5 or 6 m/s^2 of drift over the record);
#: a shift planted on that ride 3.4-3.8 at 0.2 x RMS (missed: the modes moved by under
#: 0.2 %), 4.8-5.0 at 0.3 x RMS (which lost the 13.5 Hz mode), 7.6-8.0 at 0.5, 12 at 0.8
STEP_Z = 4.0
#: breakpoints are searched this share of the record away from either end (a start transient
#: is not a level shift), at most MAX_STEPS per channel
STEP_EDGE = 0.02
MAX_STEPS = 3


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
    rec, removed = _detrend(rec, detrend)
    found += removed
    analysis_fs = rec.fs
    if resample:
        rec, note = _resample_to_band(rec, band)
        if note is not None:
            found.append(note)
            analysis_fs = rec.fs
    meta = dict(rec.meta, preprocessing={"detrend": detrend, "analysis_fs": analysis_fs})
    rec = replace(rec, meta=meta)
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
    return replace(w, message=w.message + f" Aligned by {abs(n)} sample(s) before fitting.")


def _detrend(rec: Recording, how: str) -> tuple[Recording, list[QualityWarning]]:
    names = [rec.input_name, *rec.sensors]
    data = np.column_stack([rec.base, rec.response])
    steps = [level_shifts(col) for col in data.T]
    notes = _step_notes(names, steps, data, rec.fs, removed=how != "none")
    if how == "none":
        return rec, notes
    for col, found in zip(data.T, steps, strict=True):
        for k, jump in found:
            col[k:] -= jump  # the level before the shift continues; the mean goes below
    t = np.linspace(-1.0, 1.0, rec.n_samples)
    basis = np.ones((rec.n_samples, 1)) if how == "mean" else np.column_stack([np.ones_like(t), t])
    coef, *_ = np.linalg.lstsq(basis, data, rcond=None)
    clean = data - basis @ coef
    rms = np.sqrt(np.mean(clean**2, axis=0))
    offset = coef[0]
    big = np.abs(offset) > OFFSET_FRACTION * rms
    if big.any():
        listed = ", ".join(
            f"{n} {v:+.4g} ({abs(v) / r:.2g} x RMS)"
            for n, v, r in zip(np.array(names)[big], offset[big], rms[big], strict=True)
        )
        notes.append(
            QualityWarning(
                "offset_removed",
                tuple(np.array(names)[big]),
                f"removed each channel's mean; large offsets (gravity, sensor bias): {listed}.",
                float(np.max(np.abs(offset[big]) / rms[big])),
            )
        )
    if how == "mean":
        notes += _drift_left(names, data - coef[0], t, rec.duration)
    if how == "linear":
        drift = coef[1] * 2 / rec.duration  # per second
        listed = ", ".join(f"{n} {v:+.3g}/s" for n, v in zip(names, drift, strict=True))
        notes.append(
            QualityWarning(
                "trend_removed",
                tuple(names),
                f"removed each channel's least-squares line; drift rates: {listed}.",
                float(np.max(np.abs(drift))),
            )
        )
    return replace(rec, base=clean[:, 0], response=clean[:, 1:]), notes


def level_shifts(x: np.ndarray) -> list[tuple[int, float]]:
    """Level shifts in one channel: ``[(sample, jump)]`` in time order, the sample where the
    level changes and by how much (the mean of the segment after minus the one before).

    Binary segmentation: the best single breakpoint of what a piecewise-constant fit on the
    shifts found so far leaves (least squares: the one maximising ``S_k^2 / (k (n - k))``
    over the cumulative sum ``S`` of that rest) is a shift when it explains more than
    :data:`STEP_FRACTION` of the channel's variance and happens at once (:data:`STEP_Z`):
    a drift or a velocity's wander spreads its change, a jumping sensor offset does not.
    Up to :data:`MAX_STEPS` shifts.

    Parameters
    ----------
    x : (n_samples,) ndarray

    Returns
    -------
    list of (int, float)
    """
    x = np.asarray(x, dtype=float)
    n = x.size
    candidates = np.arange(max(1, int(STEP_EDGE * n)), min(n - 1, int((1 - STEP_EDGE) * n)) + 1)
    total = float(np.sum((x - x.mean()) ** 2))
    breaks: list[int] = []
    while len(breaks) < MAX_STEPS and candidates.size and total > 0:
        rest = x - _segment_means(x, breaks)
        cumulative = np.cumsum(rest)[candidates - 1]  # the sum of the samples before each candidate
        explained = cumulative**2 * n / (candidates * (n - candidates))
        best = int(np.argmax(explained))
        if explained[best] <= STEP_FRACTION * total:
            break
        at = int(candidates[best])
        if not _sudden(rest, at, int(candidates[0])):
            break
        breaks = sorted([*breaks, at])
    levels = _segment_means(x, breaks)
    return [(k, float(levels[k] - levels[k - 1])) for k in breaks]


def _sudden(rest: np.ndarray, at: int, window: int) -> bool:
    """The level of ``rest`` jumps at ``at``: the means of the ``window`` samples either side
    differ, in the direction of the shift, by at least :data:`STEP_Z` robust SDs of the
    differences between consecutive window means of the channel with the shift taken out."""
    without = rest - _segment_means(rest, [at])
    blocks = (rest.size // window) * window
    means = np.add.reduceat(without[:blocks], np.arange(0, blocks, window)) / window
    spread = 1.4826 * np.median(np.abs(np.diff(means)))
    whole = np.mean(rest[at:]) - np.mean(rest[:at])
    local = np.mean(rest[at : at + window]) - np.mean(rest[at - window : at])
    return bool(np.sign(local) == np.sign(whole) and abs(local) >= STEP_Z * spread)


def _segment_means(x: np.ndarray, breaks: list[int]) -> np.ndarray:
    """Each sample's segment mean, the segments cut at ``breaks`` (sorted)."""
    out = np.empty_like(x)
    for lo, hi in zip([0, *breaks], [*breaks, x.size], strict=True):
        out[lo:hi] = np.mean(x[lo:hi])
    return out


def _step_notes(names, steps, data, fs: float, removed: bool) -> list[QualityWarning]:
    """One ``offset_step`` warning listing every level shift found (see :func:`level_shifts`)."""
    listed, channels, worst = [], [], 0.0
    for name, found, col in zip(names, steps, data.T, strict=True):
        if not found:
            continue
        rms = float(np.std(col))
        channels.append(name)
        for k, jump in found:
            worst = max(worst, abs(jump) / rms)
            listed.append(f"{name} {jump:+.4g} ({abs(jump) / rms:.2g} x RMS) at t = {k / fs:.2f} s")
    if not listed:
        return []
    action = (
        "removed (the level before each shift continued)"
        if removed
        else "not removed here (detrend='none'): modes fitted across them are biased; stabilise and identify "
        "remove them with their default detrend='mean'"
    )
    return [
        QualityWarning(
            "offset_step",
            tuple(channels),
            f"level shifts (a sensor's offset jumping mid-record, at once: not a drift): {'; '.join(listed)}; "
            f"{action}.",
            worst,
        )
    ]


def _drift_left(names, centred, t, duration) -> list[QualityWarning]:
    """A ``drift`` warning for channels where a line explains more than
    :data:`DRIFT_FRACTION` of the variance left after the mean (a drifting sensor or tilt)."""
    slope = centred.T @ t / (t @ t)
    explained = slope**2 * (t @ t) / np.maximum(np.sum(centred**2, axis=0), 1e-300)
    big = explained > DRIFT_FRACTION
    if not big.any():
        return []
    listed = ", ".join(
        f"{n} {2 * b / duration:+.3g}/s ({100 * e:.1f} % of its variance)"
        for n, b, e in zip(np.array(names)[big], slope[big], explained[big], strict=True)
    )
    return [
        QualityWarning(
            "drift",
            tuple(np.array(names)[big]),
            f"a linear drift remains after the mean was removed: {listed}. It biases the modes; rerun with "
            "--detrend linear (detrend='linear').",
            float(explained[big].max()),
        )
    ]


def _resample_to_band(rec: Recording, band) -> tuple[Recording, QualityWarning | None]:
    """Decimate by the largest whole factor that keeps the band's upper edge at
    :data:`BAND_FRACTION_OF_FS` of the new rate; the band is the user's or the input's
    excited band (within 30 dB of its peak)."""
    from armaxmodal.prepare.frf import excited_band

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
        f"{source} ends at {hi:.3g} Hz, far below the Nyquist frequency {rec.fs / 2:g} Hz: resampled by "
        f"1/{factor} to {new_fs:g} Hz (anti-alias filtered) for the analysis.",
        new_fs,
    )
    return out, note


def oversampling_note(mode_freqs: np.ndarray, fs: float) -> list[QualityWarning]:
    """An ``oversampled`` warning when every mode found lies below
    :data:`OVERSAMPLED_FRACTION` of the Nyquist frequency: the input excites far above the
    structure (so the rate was kept), the poles crowd ``z = 1`` and the swept orders resolve
    them poorly (the supine ride at 1 kHz under a 0.5-400 Hz ride gave one of its four modes;
    with the band suggested here, all four). The band suggested ends at
    :data:`SUGGESTED_BAND_FACTOR` times the highest mode found.

    Parameters
    ----------
    mode_freqs : (n_modes,) ndarray
        Natural frequencies of the modes found, Hz.
    fs : float
        The analysis rate, Hz.

    Returns
    -------
    list of QualityWarning
        Empty, or one warning whose value is the highest mode's share of the Nyquist frequency.
    """
    mode_freqs = np.asarray(mode_freqs, dtype=float)
    if mode_freqs.size == 0 or mode_freqs.max() >= OVERSAMPLED_FRACTION * fs / 2:
        return []
    top = float(mode_freqs.max())
    hi = float(np.ceil(SUGGESTED_BAND_FACTOR * top))
    new_fs = fs / int(np.floor(BAND_FRACTION_OF_FS * fs / hi))
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
