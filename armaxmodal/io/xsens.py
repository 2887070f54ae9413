"""Xsens DOT exports: one CSV per sensor, each with its own clock, joined into a Recording.

An export has metadata lines (``sep=,``, ``DeviceTag:``, ...) before the header
``PacketCounter, SampleTimeFine, ..., Acc_X, Acc_Y, Acc_Z, ...``; ``SampleTimeFine`` is the
sensor's clock in microseconds (32 bits, it wraps after 71.6 min); the first packets of a
recording can be all-zero accelerations. The reader drops those, unwraps the clock, bridges
a short run of dropped packets by linear interpolation (and says so), refuses a long one,
and puts every sensor on the input sensor's time stamps over the span all sensors cover.
"""

from __future__ import annotations

import gzip
import os
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from armaxmodal.exceptions import DataError
from armaxmodal.io.time_axis import BRIDGED, whole_step_gaps
from armaxmodal.quality_warnings import QualityWarning
from armaxmodal.recording import Recording

__all__ = ["read_xsens", "MAX_BRIDGED_PACKETS"]

#: dropped packets bridged by interpolation; a longer gap is an error (it would invent data)
MAX_BRIDGED_PACKETS = 3
_CLOCK_WRAP = 2**32
_HEADER_START = "PacketCounter"


def read_xsens(
    files: Mapping[str, str | os.PathLike] | Sequence[str | os.PathLike],
    *,
    input: str,
    axis: str = "Acc_X",
    max_gap: int = MAX_BRIDGED_PACKETS,
) -> Recording:
    """Read several Xsens DOT CSV exports (``.csv`` or ``.csv.gz``) as one recording.

    Parameters
    ----------
    files : mapping name -> path, or sequence of paths
        One file per sensor. Without names, each sensor is named by its file name with the
        part every file shares removed (``run__g.csv.gz``, ``run__f1.csv.gz`` -> ``g``, ``f1``).
    input : str
        Name of the sensor on the base (the input).
    axis : str
        Column to use, default ``Acc_X`` (m/s^2, includes gravity: it is removed as an
        offset by :func:`~armaxmodal.prepare.prepare`).
    max_gap : int
        Longest run of dropped packets bridged by interpolation.

    Returns
    -------
    Recording
        ``meta["read_warnings"]`` holds a ``dropped_packet`` warning per bridged gap.

    See Also
    --------
    armaxmodal.read_recording : Read CSV, MAT or UFF recordings.

    Examples
    --------
    One export per sensor (the table's and the top floor's), put on the input's time stamps:

    >>> import tempfile, pathlib
    >>> import numpy as np
    >>> import armaxmodal as am
    >>> def export(path, acc_x):  # the columns of an Xsens DOT CSV export, one packet every 8333 us
    ...     rows = ["PacketCounter,SampleTimeFine,Euler_X,Euler_Y,Euler_Z,Acc_X,Acc_Y,Acc_Z,Gyr_X,Gyr_Y,Gyr_Z"]
    ...     rows += [f"{i},{i * 8333},0,0,0,{a},0.1,9.8,0,0,0" for i, a in enumerate(acc_x)]
    ...     pathlib.Path(path).write_text("\\n".join(rows) + "\\n")
    ...     return path
    >>> rng = np.random.default_rng(1)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     g = export(pathlib.Path(folder) / "run__g.csv", rng.standard_normal(400))
    ...     f1 = export(pathlib.Path(folder) / "run__f1.csv", rng.standard_normal(400))
    ...     rec = am.read_xsens({"g": g, "f1": f1}, input="g")
    >>> rec.input_name, rec.sensors, round(rec.fs, 2)
    ('g', ('f1',), 120.0)
    """
    named = _names(files)
    if input not in named:
        raise DataError(f"input sensor '{input}' is not among the files' names {list(named)}; name it with --input.")
    if len(named) < 2:
        raise DataError("an Xsens recording needs the base sensor and at least one other sensor file.")
    series, notes = {}, []
    for name, path in named.items():
        stamps, values, gaps = _read_one(Path(path), axis, max_gap)
        series[name] = (stamps, values)
        notes += [
            QualityWarning(
                "dropped_packet",
                (name,),
                f"'{name}' lost {n} packet(s) at {t:.3f} s; {BRIDGED}",
                float(n),
            )
            for n, t in gaps
        ]
    _check_one_rate(series, input)
    stamps = series[input][0]
    start = max(s[0] for s, _ in series.values())
    stop = min(s[-1] for s, _ in series.values())
    grid = stamps[(stamps >= start) & (stamps <= stop)]
    if grid.size < 16:
        raise DataError("the sensor files hardly overlap in time (fewer than 16 common samples); check the files.")
    step = float(np.median(np.diff(stamps)))
    columns = {name: np.interp(grid, s, v) for name, (s, v) in series.items()}
    outputs = [n for n in named if n != input]
    meta = {"source": [str(p) for p in named.values()], "format": "xsens", "read_warnings": notes}
    return Recording(
        1e6 / step,
        columns[input],
        np.column_stack([columns[n] for n in outputs]),
        tuple(outputs),
        input,
        meta=meta,
    )


#: sensors whose sample steps differ by more than this fraction run at different output rates
#: (the DOT's settings are 1-120 Hz, at least 2x apart); a clock's drift is parts per million
RATE_TOLERANCE = 0.01


def _check_one_rate(series: dict, input: str) -> None:
    """Refuse sensors exported at another rate than the input's: interpolated onto the
    input's stamps they were upsampled without a word (linear interpolation's images showed
    as undamped "periodic disturbances" at 43-56 Hz on a 60 Hz copy of a 120 Hz IMU)."""
    rates = {name: 1e6 / float(np.median(np.diff(stamps))) for name, (stamps, _) in series.items()}
    other = [name for name, rate in rates.items() if abs(rate / rates[input] - 1) > RATE_TOLERANCE]
    if other:
        listed = ", ".join(f"'{name}' {rates[name]:.4g} Hz" for name in other)
        raise DataError(
            f"the sensors were exported at different rates: {listed}, the input '{input}' {rates[input]:.4g} Hz. "
            "Export every sensor at one output rate (or resample them to one rate with an anti-alias filter "
            "first); the reader does not interpolate between rates."
        )


def _names(files) -> dict:
    if isinstance(files, Mapping):
        return {str(k): v for k, v in files.items()}
    paths = [Path(p) for p in files]
    stems = [_stem(p.name) for p in paths]
    prefix = os.path.commonprefix(stems)
    suffix = os.path.commonprefix([s[::-1] for s in stems])[::-1]
    names = [s[len(prefix) : len(s) - len(suffix)] or s for s in stems]
    if len(set(names)) != len(names):
        raise DataError(f"two files give the same sensor name {names}; pass a mapping name -> file.")
    return dict(zip(names, paths, strict=True))


def _stem(name: str) -> str:
    """The file name without its ``.gz`` and ``.csv``/``.txt`` endings (``sine2.0__g.csv.gz`` -> ``sine2.0__g``)."""
    for ending in (".gz", ".csv", ".txt"):
        if name.lower().endswith(ending):
            name = name[: -len(ending)]
    return name


def _read_one(path: Path, axis: str, max_gap: int):
    """``(stamps_us, values, [(n_dropped, at_s), ...])`` of one export."""
    if not path.is_file():
        raise FileNotFoundError(f"no such recording: {path}")
    header = _header_line(path)
    try:
        frame = pd.read_csv(path, skiprows=header)
    except (pd.errors.ParserError, UnicodeDecodeError, OSError, EOFError) as exc:
        raise DataError(f"{path.name}: not a readable Xsens CSV ({exc}).") from exc
    frame.columns = [str(c).strip() for c in frame.columns]
    need = ["SampleTimeFine", axis]
    missing = [c for c in need if c not in frame.columns]
    if missing:
        raise DataError(f"{path.name}: column(s) {missing} not found; columns are {list(frame.columns)}.")
    acc = [c for c in ("Acc_X", "Acc_Y", "Acc_Z") if c in frame.columns]
    values = frame[list(dict.fromkeys([*need, *acc]))].apply(pd.to_numeric, errors="coerce")
    if values.isna().any().any():
        row = int(values.isna().any(axis=1).to_numpy().argmax())
        raise DataError(f"{path.name}: data row {row + 1} has an empty or non-numeric value; fix or trim it.")
    zero = (values[acc] == 0).all(axis=1).to_numpy()
    first = int(np.argmin(zero)) if not zero.all() else zero.size
    values = values.iloc[first:]
    if len(values) < 16:
        raise DataError(f"{path.name}: fewer than 16 samples after the all-zero start packets.")
    stamps = values["SampleTimeFine"].to_numpy(np.int64)
    steps = np.diff(stamps)
    steps[steps < 0] += _CLOCK_WRAP  # the 32-bit microsecond clock wrapped
    stamps = stamps[0] + np.concatenate([[0], np.cumsum(steps)])
    step = float(np.median(steps))
    if step <= 0:
        raise DataError(f"{path.name}: SampleTimeFine does not increase.")
    early = np.flatnonzero(np.rint(steps / step) < 1)
    if early.size:
        at = (stamps[early[0]] - stamps[0]) * 1e-6
        raise DataError(f"{path.name}: a repeated or out-of-order time stamp at {at:.3f} s; clean the export.")
    seconds = (stamps - stamps[0]) * 1e-6
    gaps = [(n, seconds[i]) for i, n in whole_step_gaps(seconds, step * 1e-6, max_gap, "packets", path.name)]
    return stamps.astype(float), values[axis].to_numpy(float), gaps


def _header_line(path: Path) -> int:
    """Index of the line that starts with ``PacketCounter`` (the metadata lines before it)."""
    opener = gzip.open if path.suffix.lower() == ".gz" else open
    try:
        with opener(path, "rt", encoding="utf-8-sig", errors="replace") as fh:
            for i, line in enumerate(fh):
                if line.startswith(_HEADER_START):
                    return i
                if i > 50:
                    break
    except (OSError, EOFError) as exc:
        raise DataError(f"{path.name}: not a readable file ({exc}).") from exc
    raise DataError(f"{path.name}: no '{_HEADER_START}' header in the first 50 lines; is it an Xsens DOT export?")
