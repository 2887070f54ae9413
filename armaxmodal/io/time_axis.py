"""A file's time column: its unit, its sampling rate, and the dropped rows a logger leaves
(bridged when a few samples are missing, refused when more are).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from armaxmodal.exceptions import DataError

_TIME_NAMES = ("time", "t", "time_s")


# A time column named with its unit, as exports write it: "time (s)", "Time [ms]", "t_ms",
# "timestamp_us"; the unit sets the scale to seconds.
_TIME_UNIT = re.compile(
    r"^(?:t|time|timestamp)(?:\s*[\(\[]\s*(s|sec|ms|us|µs)\s*[\)\]]|[_\s]+(s|sec|ms|us|µs))$", re.IGNORECASE
)


TO_SECONDS = {"s": 1.0, "sec": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}


def time_scale(name: str) -> float | None:
    """Seconds per unit of a time column called ``name``, or None if it is not one."""
    if name.strip().lower() in _TIME_NAMES:
        return 1.0
    match = _TIME_UNIT.match(name.strip())
    return TO_SECONDS[(match.group(1) or match.group(2)).lower()] if match else None


# Relative jitter allowed in a time column before it counts as non-uniform (device clocks
# quantise to a microsecond: 1e-4 of a 120 Hz step).
TIME_JITTER = 1e-3


# A time base slower than this (Hz) is a time column in ms or us read as seconds.
SLOWEST_FS = 1.0


#: rows missing from a CSV's time column bridged by interpolation; a longer gap is an error
MAX_BRIDGED_SAMPLES = 3
#: what a bridged gap means for the result, said with every ``dropped_packet`` note: the bridged
#: samples are wrong in every channel at one instant and the fit takes them as data (two rows of a
#: 120 s ride put a mode outside its interval and hid another), so the verdict is ``uncertain``
BRIDGED = (
    "bridged by linear interpolation. The bridged samples enter the fit as data and can move modes, so the "
    "verdict is at most uncertain; cut the record at the gap for a clean fit."
)


def is_number(text: str) -> bool:
    """``text`` reads as a number (a CSV header cell that is really a data cell)."""
    try:
        float(text)
    except ValueError:
        return False
    return True


def is_axis(values: np.ndarray) -> bool:
    """Increasing in equal steps (within the time column's jitter): a row index, a sample
    counter or a time axis. No sensor records a ramp that exact."""
    steps = np.diff(values)
    if steps.size < 2 or not np.all(np.isfinite(steps)):
        return False
    step = float(np.median(steps))
    return bool(step > 0 and np.all(np.abs(steps - step) <= TIME_JITTER * step))


def whole_step_gaps(t: np.ndarray, step: float, max_gap: int, unit: str, source: str) -> list[tuple[int, int]]:
    """``(i, n)`` for each step of ``t`` (seconds) after sample ``i`` that spans ``n + 1``
    whole steps of ``step`` (within the time jitter): ``n`` samples or packets a logger
    dropped there. More than ``max_gap`` at once is refused: bridging them would invent data.
    Shared by the CSV reader and :func:`armaxmodal.io.xsens.read_xsens`."""
    ratio = np.diff(t) / step
    whole = np.rint(ratio)
    gaps = []
    for i in np.flatnonzero((whole >= 2) & (np.abs(ratio - whole) <= TIME_JITTER * whole)):
        n = int(whole[i]) - 1
        if n > max_gap:
            raise DataError(
                f"{source}: {n} {unit} missing after row {i} ({t[i] - t[0]:.3f} s), more than the {max_gap} "
                "that can be bridged honestly; cut the record there and analyse the parts apart."
            )
        gaps.append((int(i), n))
    return gaps


def bridge_dropped_rows(t: np.ndarray, channels: dict, path: Path, fill_gaps_s: float | None = None):
    """Rows missing from a uniform time column (:func:`whole_step_gaps`, at most
    ``MAX_BRIDGED_SAMPLES`` at once, or as many as ``fill_gaps_s`` seconds hold when the user
    asks) filled by linear interpolation in every channel, each gap a ``dropped_packet`` warning.
    Other uneven steps are left to :func:`fs_from_time`, which refuses them. Returns
    ``(t, channels, warnings)``."""
    from armaxmodal.quality_warnings import QualityWarning

    steps = np.diff(t)
    dt = float(np.median(steps)) if steps.size else 0.0
    if not dt > 0 or np.any(steps <= 0):  # rows out of order or repeated: refused as they are
        return t, channels, []
    limit = MAX_BRIDGED_SAMPLES if fill_gaps_s is None else max(MAX_BRIDGED_SAMPLES, int(fill_gaps_s / dt + 1e-9))
    gaps = whole_step_gaps(t, dt, limit, "samples", path.name)
    if not gaps:
        return t, channels, []
    notes = [
        QualityWarning(
            "dropped_packet",
            tuple(channels),
            f"{n} sample(s) missing at {t[i] - t[0]:.3f} s (the time column steps {steps[i]:.6g} s there, "
            f"{n + 1} samples); {BRIDGED}",
            float(n),
        )
        for i, n in gaps
    ]
    inserted = [t[i] + steps[i] * np.arange(1, n + 1) / (n + 1) for i, n in gaps]
    grid = np.sort(np.concatenate([t, *inserted]))
    return grid, {name: np.interp(grid, t, x) for name, x in channels.items()}, notes


def fs_from_time(t: np.ndarray, path: Path, printed_digit: float | None = None) -> tuple[float, list]:
    """The sampling rate of a time column ``t`` (s), from its whole span.

    Parameters
    ----------
    t : (n,) ndarray
        Time stamps, s.
    path : Path
        The file, for the messages.
    printed_digit : float, optional
        The last digit the column was printed with, s (1e-4 for ``0.0167``). A column whose steps
        are uneven only by that rounding (``0.0166`` and ``0.0167`` at 60 Hz) is read at the rate
        of its span (:func:`rounded_to_print`).

    Returns
    -------
    fs : float
        Hz.
    notes : list of QualityWarning
        A ``time_rounded`` note where the rounding made the steps uneven.
    """
    if t.size < 2:
        raise DataError(f"{path.name}: the time column needs at least two samples.")
    if not np.all(np.isfinite(t)):
        raise DataError(f"{path.name}: the time column holds NaN or infinite values; fix it, or drop it and give --fs.")
    steps = np.diff(t)
    dt = float(np.median(steps))
    if dt <= 0:
        raise DataError(f"{path.name}: the time column does not increase.")
    back = np.flatnonzero(steps <= 0)
    if back.size:
        i = int(back[0])
        raise DataError(
            f"{path.name}: the time column does not increase from data row {i + 1} to {i + 2} ({t[i]:.6g} s, "
            f"then {t[i + 1]:.6g} s; {back.size} such step(s)): rows out of order, repeated, or a clock reset. "
            "Sort the rows, drop the repeats, or cut the record there."
        )
    worst = int(np.argmax(np.abs(steps - dt)))
    notes = []
    if abs(steps[worst] - dt) > TIME_JITTER * dt:
        notes = rounded_to_print(t, printed_digit)
    if abs(steps[worst] - dt) > TIME_JITTER * dt and not notes:
        raise DataError(
            f"{path.name}: the time column is not uniformly spaced: from data row {worst + 1} to {worst + 2} it "
            f"steps {steps[worst]:.6g} s against a median of {dt:.6g} s (a dropped or "
            "repeated sample?). Resample the data to a uniform grid first."
            + (
                " A step of a second or more suggests the time column is in milliseconds: convert it to "
                "seconds, or drop it and give --fs."
                if dt >= 1
                else ""
            )
        )
    # The mean step over the whole record is far less sensitive to printed rounding; ten
    # significant digits is more than any printed time column carries.
    return float(f"{(t.size - 1) / float(t[-1] - t[0]):.10g}"), notes


def rounded_to_print(t: np.ndarray, printed_digit: float | None) -> list:
    """A ``time_rounded`` note when every stamp of ``t`` (s) lies within half a printed digit of a
    uniform grid at the rate of the column's whole span; else ``[]`` (the steps are uneven beyond
    the rounding: jitter, a gap).

    The grid's step is the span over the steps, its offset the one that centres the stamps' own
    deviations. The first and last stamps are rounded too, which tilts the grid by up to one digit
    over the record, so the stamps may stand up to one digit from it, never more: a 60 Hz logger
    printing 4 decimals (steps 0.0166 and 0.0167 s) lies within 0.0001 s of its grid, while one
    dropped row stands 0.0167 s off."""
    from armaxmodal.quality_warnings import QualityWarning

    if printed_digit is None:
        return []
    dt = float(t[-1] - t[0]) / (t.size - 1)
    off = t - t[0] - dt * np.arange(t.size)
    off -= (off.max() + off.min()) / 2
    worst = float(np.abs(off).max())
    if worst > printed_digit * (1 + 1e-6):
        return []
    steps = np.diff(t)
    return [
        QualityWarning(
            "time_rounded",
            (),
            f"the time column is printed to {printed_digit:.0e} s, so its steps are uneven ({steps.min():.6g} to "
            f"{steps.max():.6g} s); every stamp lies within {worst:.2g} s of a uniform grid: read at the rate of its "
            "whole "
            f"span, {1 / dt:.4f} Hz",
            float(worst),
        )
    ]


def fill_missing_samples(channels: dict, max_samples: int, source: str) -> tuple[dict, list]:
    """Runs of missing samples (NaN cells, a dropped packet a logger wrote as empty) of at most
    ``max_samples`` filled by linear interpolation between the samples either side, each run a
    ``gap_filled`` warning with its rows. Asked for by the user (``--fill-gaps``): without it a
    missing sample is refused. A longer run, or one at the start or end of the record (nothing to
    interpolate from), is refused with its rows.

    Parameters
    ----------
    channels : dict of str to (n,) ndarray
    max_samples : int
        The longest run filled.
    source : str
        The file, for the messages.

    Returns
    -------
    channels : dict
        Copies with the runs filled (unchanged channels are the same arrays).
    warnings : list of QualityWarning
    """
    from armaxmodal.quality_warnings import QualityWarning

    out, notes = dict(channels), []
    for name, x in channels.items():
        missing = ~np.isfinite(x)
        if not missing.any():
            continue
        edges = np.flatnonzero(np.diff(np.r_[0, missing.astype(int), 0]))
        runs = list(zip(edges[::2], edges[1::2], strict=True))  # [start, stop) of each run
        for start, stop in runs:
            where = f"{source}: channel '{name}', data rows {start + 1}-{stop}"
            if stop - start > max_samples:
                raise DataError(
                    f"{where}: {stop - start} missing samples, more than the {max_samples} samples --fill-gaps allows; "
                    "cut the record there and analyse the parts apart, or allow a longer gap."
                )
            if start == 0 or stop == x.size:
                raise DataError(
                    f"{where}: missing at the {'start' if start == 0 else 'end'} of the record, with "
                    "nothing to interpolate from on one side; trim those rows."
                )
        idx = np.arange(x.size)
        out[name] = np.where(missing, np.interp(idx, idx[~missing], x[~missing]), x)
        notes += [
            QualityWarning(
                "gap_filled",
                (name,),
                f"channel '{name}', data rows {start + 1}-{stop}: {stop - start} "
                "missing sample(s) filled by linear interpolation (--fill-gaps)",
                float(stop - start),
            )
            for start, stop in runs
        ]
    return out, notes
