"""Read recordings from CSV, MAT and UFF (type 58) files; write CSV, UFF and JSON.

Input files are never modified. Every output is written to a temporary file beside the
target and renamed over it only when complete, so a failed write leaves nothing behind.
"""

from __future__ import annotations

import json
import os
import re
import struct
import tempfile
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from .exceptions import DataError
from .recording import Recording

__all__ = [
    "read_recording",
    "write_recording_csv",
    "write_recording_uff",
    "write_json",
    "atomic_write",
]

_TIME_NAMES = ("time", "t", "time_s")
# A time column named with its unit, as exports write it: "time (s)", "Time [ms]", "t_ms",
# "timestamp_us"; the unit sets the scale to seconds.
_TIME_UNIT = re.compile(
    r"^(?:t|time|timestamp)(?:\s*[\(\[]\s*(s|sec|ms|us|µs)\s*[\)\]]|[_\s]+(s|sec|ms|us|µs))$", re.IGNORECASE
)
_TO_SECONDS = {"s": 1.0, "sec": 1.0, "ms": 1e-3, "us": 1e-6, "µs": 1e-6}


def _time_scale(name: str) -> float | None:
    """Seconds per unit of a time column called ``name``, or None if it is not one."""
    if name.strip().lower() in _TIME_NAMES:
        return 1.0
    match = _TIME_UNIT.match(name.strip())
    return _TO_SECONDS[(match.group(1) or match.group(2)).lower()] if match else None
# Relative jitter allowed in a time column before it counts as non-uniform (device clocks
# quantise to a microsecond: 1e-4 of a 120 Hz step).
_TIME_JITTER = 1e-3
# A time base slower than this (Hz) is a time column in ms or us read as seconds.
_SLOWEST_FS = 1.0
#: rows missing from a CSV's time column bridged by interpolation; a longer gap is an error
MAX_BRIDGED_SAMPLES = 3


def read_recording(
    path: str | os.PathLike,
    *,
    input: str = "base",
    fs: float | None = None,
    outputs: Sequence[str] | None = None,
    format: str | None = None,
    subject: str | None = None,
    mass_kg: float | None = None,
) -> Recording:
    """Read a recording: one input column, the other numeric columns as outputs.

    A column that increases in equal steps (a row index, as pandas writes by default, a
    sample counter, a time column under another name) is not taken as an output unless
    ``outputs`` names it; the recording's ``meta["axis_columns"]`` lists those left out.

    Parameters
    ----------
    path : path-like
        ``.csv`` (optionally ``.gz``), ``.mat`` or ``.uff``/``.unv``.
    input : str
        Name of the input channel (CSV column, MAT variable, UFF ``id1``).
    fs : float, optional
        Sampling rate in Hz; required when the file has no time column / sample step.
    outputs : sequence of str, optional
        Output channels to keep, in this order (default: every other numeric channel).
    format : {"csv", "mat", "uff"}, optional
        Override the format guessed from the file name.
    subject, mass_kg : optional
        Who was measured and the total mass in kg; CSV files may also carry them as
        ``# subject: ...`` and ``# mass_kg: ...`` lines before the header.

    Returns
    -------
    Recording
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such recording: {path}")
    kind = format or _guess_format(path)
    readers: dict[str, Callable] = {"csv": _read_csv, "mat": _read_mat, "uff": _read_uff}
    if kind not in readers:
        raise DataError(f"unknown format {kind!r} for {path.name}; use csv, mat or uff.")
    channels, file_fs, info = readers[kind](path)
    if not channels:
        raise DataError(f"{path.name}: no numeric channels found.")
    if kind == "csv" and input not in channels and all(_is_number(c) for c in channels):
        raise DataError(
            f"{path.name}: the first line holds numbers ({', '.join(list(channels)[:3])}, ...), not column names: "
            "the file has no header row. Add one naming the columns, e.g. 'time,base,head,chest' (time in s), "
            "and say which is the input with input=... (CLI: --input)."
        )
    # a row index, sample counter or time column under another name (pandas writes its index
    # as an unnamed first column) is not a sensor: taken as an output it was a ramp that lost
    # modes and raised 'drift'
    axes = [c for c in channels if c != input and _is_axis(channels[c])]
    if file_fs is None and fs is None and axes:
        raise DataError(
            f"{path.name}: no time column found, but column(s) {axes} increase in equal steps: if one is the "
            "time, name it 'time' (seconds) or 'time_ms' (milliseconds); else give the sampling rate with "
            "fs=... (CLI: --fs)."
        )
    fs = _resolve_fs(file_fs, fs, path)
    odd = info.get("other_lengths", {})
    wanted = [c for c in [input, *(outputs or ())] if c in odd]
    if wanted:
        n = len(next(iter(channels.values())))
        raise DataError(
            f"{path.name}: {', '.join(f'{c!r} has {odd[c]} samples' for c in wanted)} where the other channels have "
            f"{n}: a recording's channels share one time base. Trim them to a common length (aligned by time)."
        )
    if input not in channels:
        raise DataError(
            f"{path.name}: input channel '{input}' not found; channels are {list(channels)}. "
            "Name the input column with input=... (CLI: --input)."
        )
    names = list(outputs) if outputs is not None else [c for c in channels if c != input and c not in axes]
    missing = [c for c in names if c not in channels]
    if missing:
        raise DataError(f"{path.name}: unknown output channel(s) {missing}; channels are {list(channels)}.")
    if not names:
        lengths = ", ".join(f"{c!r} has {m} samples" for c, m in odd.items())
        others = f" ({lengths}, '{input}' {channels[input].size}: trim them to a common length)" if odd else ""
        raise DataError(f"{path.name}: only the input channel '{input}' is present; no outputs{others}.")
    empty = [c for c in [input, *names] if np.all(np.isnan(channels[c]))]
    if empty:
        raise DataError(
            f"{path.name}: channel(s) {empty} hold no values (every sample empty, NA or NaN): a sensor that "
            "recorded nothing. Delete the column, or choose the outputs with outputs=... (CLI: --outputs)."
        )
    lengths = {c: channels[c].size for c in [input, *names]}
    if len(set(lengths.values())) > 1:
        raise DataError(f"{path.name}: channels differ in length {lengths}; trim them to a common length.")
    meta = {"source": str(path), "format": kind, "axis_columns": tuple(c for c in axes if c not in names)}
    if "units" in info:  # a CSV's row of units under the header
        meta["units"] = info["units"]
    if info.get("read_warnings"):  # rows a logger dropped, bridged
        kept = (input, *names)
        notes = info["read_warnings"]
        meta["read_warnings"] = [replace(w, channels=tuple(c for c in w.channels if c in kept)) for w in notes]
    return Recording(
        fs,
        channels[input],
        np.column_stack([channels[c] for c in names]),
        tuple(names),
        input,
        subject if subject is not None else info.get("subject"),
        mass_kg if mass_kg is not None else info.get("mass_kg"),
        meta,
    )


def _is_number(text: str) -> bool:
    """``text`` reads as a number (a CSV header cell that is really a data cell)."""
    try:
        float(text)
    except ValueError:
        return False
    return True


def _is_axis(values: np.ndarray) -> bool:
    """Increasing in equal steps (within the time column's jitter): a row index, a sample
    counter or a time axis. No sensor records a ramp that exact."""
    steps = np.diff(values)
    if steps.size < 2 or not np.all(np.isfinite(steps)):
        return False
    step = float(np.median(steps))
    return bool(step > 0 and np.all(np.abs(steps - step) <= _TIME_JITTER * step))


def _guess_format(path: Path) -> str:
    suffixes = [s.lower() for s in path.suffixes]
    if suffixes and suffixes[-1] == ".gz":
        suffixes = suffixes[:-1]
    ext = suffixes[-1] if suffixes else ""
    return {".csv": "csv", ".txt": "csv", ".mat": "mat", ".uff": "uff", ".unv": "uff"}.get(ext, ext)


def _resolve_fs(file_fs: float | None, user_fs: float | None, path: Path) -> float:
    """The sampling rate: the user's, checked against the file's time base, or the file's.

    A time column in milliseconds (or microseconds) under a plain name reads as a rate 1,000
    (1,000,000) times too low: below 1 Hz it is refused, naming the fix, and a user's rate
    exactly that multiple of it is taken as saying so."""
    if file_fs is None and user_fs is None:
        raise DataError(
            f"{path.name}: no time column or sample step in the file; give the sampling rate with fs=... (CLI: --fs)."
        )
    if user_fs is None:
        if file_fs < _SLOWEST_FS:
            raise DataError(
                f"{path.name}: the time column, read in seconds, steps by {1 / file_fs:.4g} s ({file_fs:.4g} Hz "
                f"sampling), far too slow for a vibration record: if it is in milliseconds, name the column "
                f"'time_ms' or 'time [ms]' (or give its unit in a row under the header), or give the sampling "
                "rate with fs=... (CLI: --fs)."
            )
        return float(file_fs)
    if file_fs is not None and min(abs(file_fs * unit - user_fs) for unit in (1, 1e3, 1e6)) > _TIME_JITTER * user_fs:
        raise DataError(
            f"{path.name}: the file's time column gives fs = {file_fs:.6g} Hz but fs = "
            f"{user_fs:.6g} Hz was passed; drop one of them."
        )
    return float(user_fs)


def whole_step_gaps(t: np.ndarray, step: float, max_gap: int, unit: str, source: str) -> list[tuple[int, int]]:
    """``(i, n)`` for each step of ``t`` (seconds) after sample ``i`` that spans ``n + 1``
    whole steps of ``step`` (within the time jitter): ``n`` samples or packets a logger
    dropped there. More than ``max_gap`` at once is refused: bridging them would invent data.
    Shared by the CSV reader and :func:`armaxmodal.xsens.read_xsens`."""
    ratio = np.diff(t) / step
    whole = np.rint(ratio)
    gaps = []
    for i in np.flatnonzero((whole >= 2) & (np.abs(ratio - whole) <= _TIME_JITTER * whole)):
        n = int(whole[i]) - 1
        if n > max_gap:
            raise DataError(
                f"{source}: {n} {unit} missing after row {i} ({t[i] - t[0]:.3f} s), more than the {max_gap} "
                "that can be bridged honestly; cut the record there and analyse the parts apart."
            )
        gaps.append((int(i), n))
    return gaps


def _bridge_dropped_rows(t: np.ndarray, channels: dict, path: Path) -> tuple[np.ndarray, dict, list]:
    """Rows missing from a uniform time column (:func:`whole_step_gaps`, at most
    ``MAX_BRIDGED_SAMPLES`` at once) filled by linear interpolation in every channel, each
    gap a ``dropped_packet`` warning. Other uneven steps are left to :func:`_fs_from_time`,
    which refuses them."""
    from .quality import QualityWarning

    steps = np.diff(t)
    dt = float(np.median(steps)) if steps.size else 0.0
    if not dt > 0 or np.any(steps <= 0):  # rows out of order or repeated: refused as they are
        return t, channels, []
    gaps = whole_step_gaps(t, dt, MAX_BRIDGED_SAMPLES, "samples", path.name)
    if not gaps:
        return t, channels, []
    notes = [
        QualityWarning(
            "dropped_packet",
            tuple(channels),
            f"{n} sample(s) missing at {t[i] - t[0]:.3f} s (the time column steps {steps[i]:.6g} s there, "
            f"{n + 1} samples); bridged by linear interpolation.",
            float(n),
        )
        for i, n in gaps
    ]
    inserted = [t[i] + steps[i] * np.arange(1, n + 1) / (n + 1) for i, n in gaps]
    grid = np.sort(np.concatenate([t, *inserted]))
    return grid, {name: np.interp(grid, t, x) for name, x in channels.items()}, notes


def _fs_from_time(t: np.ndarray, path: Path) -> float:
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
    if abs(steps[worst] - dt) > _TIME_JITTER * dt:
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
    return float(f"{(t.size - 1) / float(t[-1] - t[0]):.10g}")


# -- CSV ------------------------------------------------------------------------------
def _check_csv_layout(path: Path) -> None:
    """Name the usual export mistakes before pandas turns them into a tokenizer error: a
    gzip file named .csv, another delimiter, metadata lines before the header."""
    import gzip
    import zlib

    with open(path, "rb") as fh:
        head = fh.read(1 << 16)
    if head[:2] == b"\x1f\x8b":
        if path.suffix.lower() != ".gz":
            raise DataError(
                f"{path.name}: the file is gzip-compressed; name it {path.name}.gz (read as is) or unzip it."
            )
        try:
            head = gzip.decompress(head) if len(head) < (1 << 16) else gzip.open(path).read(1 << 16)
        except (EOFError, OSError, zlib.error) as exc:
            raise DataError(f"{path.name}: a damaged or truncated gzip file ({exc}); copy or export it again.") from exc
    lines = [
        ln for ln in head.decode("utf-8", errors="replace").splitlines()[:-1] if ln.strip() and not ln.startswith("#")
    ]
    if not lines:
        return
    _check_separator(path, lines[:200])
    commas = [ln.count(",") for ln in lines[:200]]
    if max(commas) == 0:
        return
    fields = max(set(commas), key=commas.count)
    leading = next((i for i, c in enumerate(commas) if c == fields), 0)
    if leading:
        raise DataError(
            f"{path.name}: {leading} line(s) before the header have fewer fields than the data (first: "
            f"{lines[0][:40]!r}): metadata lines. Put '#' before each (they are then read as comments) or "
            "delete them. Xsens DOT exports are read as they are when you pass one file per sensor."
        )


def _check_separator(path: Path, lines: list[str]) -> None:
    """Refuse semicolon- or tab-separated files by name: most lines hold the same number of
    the separator. Such exports often write decimal commas too (a European spreadsheet),
    which once read as 'metadata lines before the header'."""
    for sep, name in ((";", "semicolons"), ("\t", "tabs")):
        counts = [ln.count(sep) for ln in lines]
        fields = max(set(counts), key=counts.count)
        if fields == 0 or counts.count(fields) < 0.8 * len(counts):
            continue
        leading = next(i for i, c in enumerate(counts) if c == fields)
        decimal = any(re.search(r"\d,\d", ln) for ln in lines[leading + 1 :])
        raise DataError(
            f"{path.name}: the columns are separated by {name}, not commas"
            + (", and the numbers use decimal commas" if decimal else "")
            + (f", after {leading} metadata line(s) before the header" if leading else "")
            + "; re-export as comma-separated CSV with a '.' decimal point"
            + (" (and '#' before each metadata line)." if leading else ".")
        )


_MISSING = ("", "na", "n/a", "nan", "null", "none", "-")


def _read_csv(path: Path):
    _check_csv_layout(path)
    info = _csv_comments(path)
    try:
        # every cell a number, the common case, is parsed in C; anything else (text, empty or
        # missing cells) is read again as text below, to say which cell is wrong (the same
        # doubles either way: checked on the fixtures and a 20,000-row record)
        frame = pd.read_csv(path, comment="#", skipinitialspace=True, keep_default_na=False)
        numeric = all(dtype.kind in "iuf" for dtype in frame.dtypes)
        if not numeric:
            frame = pd.read_csv(path, comment="#", skipinitialspace=True, dtype=str, keep_default_na=False)
    except pd.errors.EmptyDataError as exc:
        raise DataError(f"{path.name}: the file is empty; expected a header row and data.") from exc
    except (pd.errors.ParserError, UnicodeDecodeError, OSError, EOFError) as exc:
        raise DataError(f"{path.name}: not a readable CSV file ({exc}).") from exc
    if frame.shape[0] == 0:
        raise DataError(f"{path.name}: header only, no data rows.")
    frame.columns = [str(c).strip() for c in frame.columns]
    units = {} if numeric else _units_row(frame)
    if units:
        frame = frame.iloc[1:].reset_index(drop=True)
        info["units"] = units
    if numeric:
        channels = {col: frame[col].to_numpy(dtype=float) for col in frame.columns}
    else:
        channels = _text_channels(frame, path)
    file_fs = None
    time_col = next((c for c in channels if _time_scale(c) is not None), None)
    if time_col is not None:
        t = channels.pop(time_col)
        if not np.all(np.isfinite(t)):
            raise DataError(f"{path.name}: the time column contains NaN or empty cells.")
        scale = _TO_SECONDS.get(units.get(time_col, "").strip("()[] ").lower()) or _time_scale(time_col)
        t, channels, info["read_warnings"] = _bridge_dropped_rows(t * scale, channels, path)
        file_fs = _fs_from_time(t, path)
    return channels, file_fs, info


def _units_row(frame: pd.DataFrame) -> dict[str, str]:
    """``{column: unit}`` when the first row under the header is a row of units (every cell
    text, such as ``s, m/s^2``, above rows of numbers), as many exports write; else empty."""
    if len(frame) < 2:
        return {}
    first = frame.iloc[0].str.strip()
    if pd.to_numeric(first, errors="coerce").notna().any():  # a blank unit is allowed
        return {}
    second = pd.to_numeric(frame.iloc[1].str.strip(), errors="coerce")
    return dict(zip(frame.columns, first, strict=True)) if second.notna().all() else {}


def _text_channels(frame: pd.DataFrame, path: Path) -> dict[str, np.ndarray]:
    """Channels of a CSV read as text: numbers parsed, text columns skipped, an all-missing
    column kept as NaN (refused by name if used), any other missing or non-numeric cell an
    error that names it."""
    channels: dict[str, np.ndarray] = {}
    for col in frame.columns:
        text = frame[col].str.strip()
        values = pd.to_numeric(text, errors="coerce").to_numpy(dtype=float)
        bad = np.isnan(values) & ~text.str.lower().isin(["nan"]).to_numpy()
        if text.str.lower().isin(_MISSING).all():
            channels[col] = np.full(len(text), np.nan)  # refused by name if it is used
            continue
        if bad.all():
            continue  # a text column (labels, comments): not a channel
        if bad.any():
            row = int(np.argmax(bad))
            if text.iloc[row] == "":
                raise DataError(
                    f"{path.name}: column '{col}', data row {row + 1} is empty (a missing "
                    "sample); fill or trim it before analysis."
                )
            raise DataError(
                f"{path.name}: column '{col}', data row {row + 1}: {frame[col].iloc[row]!r} is "
                "not a number; fix or remove that cell."
            )
        channels[col] = values
    return channels


def _csv_comments(path: Path) -> dict:
    """``# key: value`` lines before the header (subject, mass_kg)."""
    import gzip

    opener = gzip.open if path.suffix.lower() == ".gz" else open
    info: dict = {}
    try:
        with opener(path, "rt", encoding="utf-8") as fh:
            for line in fh:
                if not line.startswith("#"):
                    break
                key, _, value = line[1:].partition(":")
                key, value = key.strip().lower(), value.strip()
                if key == "subject":
                    info["subject"] = value
                elif key == "mass_kg":
                    try:
                        info["mass_kg"] = float(value)
                    except ValueError as exc:
                        raise DataError(f"{path.name}: '# mass_kg: {value}' is not a number.") from exc
    except (UnicodeDecodeError, OSError, EOFError) as exc:
        raise DataError(f"{path.name}: not a readable text file ({exc}).") from exc
    return info


# -- MAT ------------------------------------------------------------------------------
def _read_mat(path: Path):
    import zlib

    import scipy.io
    from scipy.io.matlab import MatReadError

    try:
        data = scipy.io.loadmat(path, squeeze_me=False)
    except NotImplementedError as exc:
        raise DataError(
            f"{path.name}: MATLAB v7.3 (HDF5) files are not supported; save with save(..., '-v7') or export to CSV."
        ) from exc
    except (
        MatReadError, ValueError, TypeError, IndexError, KeyError, OSError, struct.error, EOFError, zlib.error,
        UnicodeDecodeError, OverflowError, MemoryError,
    ) as exc:  # fmt: skip  -- what scipy raises on random bytes (tests/test_fuzz.py)
        raise DataError(f"{path.name}: not a readable MAT file ({type(exc).__name__}: {exc}).") from exc
    arrays = _struct_fields({k: v for k, v in data.items() if not k.startswith("__") and isinstance(v, np.ndarray)})
    numeric = {k: np.squeeze(v) for k, v in arrays.items() if v.dtype.kind in "fiu" and v.size > 0}
    file_fs = None
    for key in ("fs", "Fs", "FS"):
        if key in numeric and numeric[key].size == 1:
            file_fs = float(numeric.pop(key))
            break
    time_key = next((k for k in numeric if _time_scale(k) is not None), None)
    if time_key is not None:
        t = numeric.pop(time_key).ravel().astype(float) * _time_scale(time_key)
        t_fs = _fs_from_time(t, path)
        file_fs = file_fs if file_fs is not None else t_fs
    sensor_names = None
    if "sensors" in arrays and arrays["sensors"].dtype.kind in "OU":
        sensor_names = [str(np.squeeze(s)) for s in np.ravel(arrays["sensors"])]
    vectors = [v for v in numeric.values() if v.ndim == 1]
    matrices = [v for v in numeric.values() if v.ndim >= 2]
    n = max((v.size for v in vectors), default=max((max(v.shape) for v in matrices), default=0))
    channels: dict[str, np.ndarray] = {}
    for key, v in numeric.items():
        v = v.astype(float)
        if v.ndim == 1 and v.size == n:
            channels[key] = v
        elif v.ndim == 2 and n in v.shape:
            cols = v if v.shape[0] == n else v.T
            names = (
                sensor_names
                if key == "response" and sensor_names and len(sensor_names) == cols.shape[1]
                else [f"{key}_{i + 1}" for i in range(cols.shape[1])]
            )
            channels.update({name: cols[:, i].copy() for i, name in enumerate(names)})
    # vectors of another length are not channels of this record (a frequency axis, a
    # calibration table) unless the user names one: then their length is the error to report
    others = {key: v.size for key, v in numeric.items() if v.ndim == 1 and v.size > 1 and key not in channels}
    return channels, file_fs, {"other_lengths": others}


def _struct_fields(arrays: dict) -> dict:
    """A MATLAB struct's fields as variables of their own (``data.head`` -> ``head``, or
    ``data.head`` when a variable of that name exists): labs often save a record as one
    struct, which read as 'no numeric channels'. One struct level; struct arrays are skipped."""
    out = {k: v for k, v in arrays.items() if v.dtype.names is None}
    for name, record in arrays.items():
        if record.dtype.names is None or record.size != 1:
            continue
        for field in record.dtype.names:
            value = record.flat[0][field]
            if isinstance(value, np.ndarray):
                out[field if field not in arrays and field not in out else f"{name}.{field}"] = value
    return out


# -- UFF ------------------------------------------------------------------------------
def _read_uff(path: Path):
    import pyuff

    try:
        sets = pyuff.UFF(str(path)).read_sets()
    except (
        ValueError,
        IndexError,
        KeyError,
        TypeError,
        UnicodeDecodeError,
        struct.error,
        OSError,
        EOFError,
        AttributeError,
    ) as exc:
        raise DataError(f"{path.name}: not a readable UFF file ({exc}).") from exc
    except Exception as exc:  # pyuff raises a bare Exception for a data set it cannot parse
        raise DataError(
            f"{path.name}: not a readable UFF file: a data set could not be parsed ({exc}). Check that it is a "
            "complete UFF export (type 58 time histories, each closed by a '-1' line), or export to CSV."
        ) from exc
    _check_uff_complete(path)
    sets = [sets] if isinstance(sets, dict) else list(sets)
    series = [s for s in sets if s.get("type") == 58]
    if not series:
        raise DataError(f"{path.name}: no type-58 (function at node) data sets in this UFF file.")
    channels: dict[str, np.ndarray] = {}
    steps = set()
    for s in series:
        if int(s.get("func_type", 1)) != 1:
            raise DataError(
                f"{path.name}: data set '{s.get('id1', '')}' has function type "
                f"{s.get('func_type')}, not a time response (1); armaxmodal needs time histories."
            )
        name = str(s.get("id1", "")).strip() or f"node{s.get('rsp_node')}:{s.get('rsp_dir')}"
        if name in channels:
            raise DataError(f"{path.name}: two data sets are named '{name}'; give each channel its own id1.")
        data = np.asarray(s["data"])
        if np.iscomplexobj(data):
            raise DataError(f"{path.name}: data set '{name}' is complex; expected a real time history.")
        channels[name] = data.astype(float)
        steps.add(float(s.get("abscissa_inc", 0.0)))
    steps.discard(0.0)
    if len(steps) > 1:
        raise DataError(f"{path.name}: channels have different sample steps {sorted(steps)}.")
    file_fs = 1.0 / steps.pop() if steps else None
    return channels, file_fs, {}


def _check_uff_complete(path: Path) -> None:
    """Every UFF data set closes with a ``-1`` line; pyuff silently drops a set the file ends
    inside, so a truncated file would lose its last channels without a word."""
    with open(path, "rb") as fh:
        fh.seek(0, os.SEEK_END)
        fh.seek(max(fh.tell() - 256, 0))
        tail = fh.read().rstrip()
    if tail.rsplit(b"\n", 1)[-1].strip() != b"-1":
        raise DataError(
            f"{path.name}: the UFF file ends inside a data set (no closing '-1' line): it is truncated, "
            "and its last channels would be lost. Copy or export it again."
        )


# -- writers --------------------------------------------------------------------------
def atomic_write(path: str | os.PathLike, write: Callable[[str], None]) -> Path:
    """Call ``write(tmp_path)`` and move the file into place only if it succeeds."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def write_all(outputs) -> list[Path]:
    """Write every ``(path, write)`` pair or none: each ``write(tmp)`` fills a temporary file
    beside its target; only when all have succeeded are they moved into place."""
    staged: list[tuple[str, Path]] = []
    try:
        for path, write in outputs:
            path = Path(path)
            path.parent.mkdir(parents=True, exist_ok=True)
            fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
            os.close(fd)
            staged.append((tmp, path))
            write(tmp)
        umask = os.umask(0)
        os.umask(umask)
        for tmp, path in staged:
            os.chmod(tmp, 0o666 & ~umask)
            os.replace(tmp, path)
    finally:
        for tmp, _ in staged:
            if os.path.exists(tmp):
                os.unlink(tmp)
    return [path for _, path in staged]


def write_recording_csv(recording: Recording, path: str | os.PathLike, float_format: str = "%.9g") -> Path:
    """Write ``time``, the input and every sensor as CSV, with subject lines if known."""

    def write(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8", newline="") as fh:
            if recording.subject is not None:
                fh.write(f"# subject: {recording.subject}\n")
            if recording.mass_kg is not None:
                fh.write(f"# mass_kg: {recording.mass_kg:.6g}\n")
            frame = recording.to_frame()
            # Enough digits that the sampling rate read back from the times is exact.
            frame["time"] = [f"{t:.12g}" for t in frame["time"]]
            frame.to_csv(fh, index=False, float_format=float_format, lineterminator="\n")

    return atomic_write(path, write)


def write_recording_uff(recording: Recording, path: str | os.PathLike) -> Path:
    """Write every channel (input first) as a type-58 time-response data set."""
    import pyuff

    names = [recording.input_name, *recording.sensors]
    signals = [recording.base, *recording.response.T]

    def write(tmp: str) -> None:
        os.unlink(tmp)  # pyuff refuses to overwrite in 'add' mode; let it create the file
        uff = pyuff.UFF(tmp)
        for node, (name, x) in enumerate(zip(names, signals, strict=True), start=1):
            uff.write_sets(
                pyuff.prepare_58(
                    id1=name,
                    func_type=1,
                    rsp_node=node,
                    rsp_dir=3,
                    ref_node=1,
                    ref_dir=3,
                    ord_data_type=4,
                    abscissa_spacing=1,
                    abscissa_min=0.0,
                    abscissa_inc=1.0 / recording.fs,
                    num_pts=x.size,
                    data=np.asarray(x),
                    x=recording.time,
                    ordinate_spec_data_type=12,
                    abscissa_spec_data_type=17,
                    orddenom_spec_data_type=0,  # pyuff has no default for this one
                ),
                mode="add",
            )

    return atomic_write(path, write)


def strict_json(obj):
    """``obj`` with numpy values made plain and every non-finite float made ``None``: strict
    JSON has no NaN or Infinity, and strict parsers reject them."""
    if isinstance(obj, dict):
        return {str(k): strict_json(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [strict_json(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return strict_json(obj.tolist())
    if isinstance(obj, np.generic):
        obj = obj.item()
    if isinstance(obj, float) and not np.isfinite(obj):
        return None
    if isinstance(obj, complex):
        raise TypeError("cannot write a complex number to JSON; split it into real and imaginary parts")
    return obj


def write_json(obj, path: str | os.PathLike) -> Path:
    """Write ``obj`` as indented strict JSON (numpy values converted, NaN and infinities as
    ``null``; ``allow_nan=False`` so a bare NaN can never slip through)."""
    clean = strict_json(obj)

    def write(tmp: str) -> None:
        with open(tmp, "w", encoding="utf-8") as fh:
            json.dump(clean, fh, indent=2, allow_nan=False)
            fh.write("\n")

    return atomic_write(path, write)
