"""Detrending: each channel's mean or least-squares line removed, and a level shift where a
sensor's offset jumps mid-record (``level_shifts``; MATLAB's ``detrend`` with breakpoints,
the breakpoints found). Gravity on an accelerometer and sensor offsets would otherwise bias
the modes."""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording

__all__ = ["DETRENDS", "detrend", "level_shifts"]

#: the detrends :func:`detrend` knows
DETRENDS = ("mean", "linear", "none")
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


def detrend(rec: Recording, how: str) -> tuple[Recording, list[QualityWarning]]:
    """``rec`` with each channel's level shifts, then its mean (``how="mean"``) or least-squares
    line (``"linear"``) removed (``"none"``: nothing removed, the shifts only reported), and the
    warnings that say what was found: ``offset_step``, ``offset_removed``, ``drift``,
    ``trend_removed``."""
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
    """One ``offset_step`` warning listing every level shift found (see ``level_shifts``)."""
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
