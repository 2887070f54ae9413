"""Read a recording from CSV, MAT or UFF (type 58): the format by the file's name, the
sampling rate from its time column or the user, and the input and outputs by name. Input files
are never modified.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path

import numpy as np

from armaxmodal.exceptions import DataError
from armaxmodal.io.csv_format import read_csv_file
from armaxmodal.io.mat_format import read_mat_file
from armaxmodal.io.time_axis import SLOWEST_FS, TIME_JITTER, fill_missing_samples, is_axis, is_number
from armaxmodal.io.uff_format import read_uff_file
from armaxmodal.recording import Recording


def read_recording(
    path: str | os.PathLike,
    *,
    input: str = "base",
    fs: float | None = None,
    outputs: Sequence[str] | None = None,
    format: str | None = None,
    subject: str | None = None,
    mass_kg: float | None = None,
    fill_gaps: float | None = None,
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
    fill_gaps : float, optional
        Fill gaps of up to this many seconds (missing cells, rows a logger dropped) by linear
        interpolation, each a warning with its rows (``gap_filled``, ``dropped_packet``). Without
        it a missing sample is refused, and at most 3 dropped rows are bridged.

    Returns
    -------
    Recording

    See Also
    --------
    armaxmodal.read_xsens : Read an Xsens IMU export.
    armaxmodal.write_recording_csv : Write a recording as CSV.
    armaxmodal.stabilisation_diagram : Sweep the model order over the recording.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 20.0, seed=1), 60.0, seed=2)
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     path = am.write_recording_csv(ride, pathlib.Path(folder) / "ride.csv")  # time, base, head, ...
    ...     back = am.read_recording(path, input="base", outputs=["head", "pelvis"])
    >>> back.input_name, back.sensors, back.fs
    ('base', ('head', 'pelvis'), 60.0)
    """
    if isinstance(path, (list, tuple)):
        raise DataError(
            f"read_recording reads one file; got {len(path)}. For one export per sensor (Xsens DOT, a shake table's "
            "IMUs) use read_xsens(paths, input=...), as the command line does when given several files."
        )
    if not isinstance(path, (str, os.PathLike)):
        raise DataError(f"read_recording: expected a file path, got {type(path).__name__}.")
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no such recording: {path}")
    if fill_gaps is not None and not (np.isfinite(fill_gaps) and fill_gaps > 0):
        raise DataError(f"fill_gaps: expected the longest gap to fill in seconds (> 0), got {fill_gaps!r}.")
    kind = format or _guess_format(path)
    readers: dict[str, Callable] = {"csv": read_csv_file, "mat": read_mat_file, "uff": read_uff_file}
    if kind not in readers:
        raise DataError(f"unknown format {kind!r} for {path.name}; use csv, mat or uff.")
    channels, file_fs, info = readers[kind](path, fill_gaps) if kind == "csv" else readers[kind](path)
    if not channels:
        raise DataError(f"{path.name}: no numeric channels found.")
    if kind == "csv" and input not in channels and all(is_number(c) for c in channels):
        raise DataError(
            f"{path.name}: the first line holds numbers ({', '.join(list(channels)[:3])}, ...), not column names: "
            "the file has no header row. Add one naming the columns, e.g. 'time,base,head,chest' (time in s), "
            "and say which is the input with input=... (CLI: --input)."
        )
    # a row index, sample counter or time column under another name (pandas writes its index
    # as an unnamed first column) is not a sensor: taken as an output it was a ramp that lost
    # modes and raised 'drift'
    axes = [c for c in channels if c != input and is_axis(channels[c])]
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
    names = _output_names(channels, input, outputs, axes, odd, path)
    if fill_gaps is not None:
        used = {c: channels[c] for c in (input, *names)}
        filled, notes = fill_missing_samples(used, int(fill_gaps * fs + 1e-9), path.name)
        channels.update(filled)
        info["read_warnings"] = list(info.get("read_warnings", ())) + notes
    meta = {"source": str(path), "format": kind, "axis_columns": tuple(c for c in axes if c not in names)}
    if "units" in info:  # a CSV's row of units under the header
        meta["units"] = info["units"]
    if info.get("read_warnings"):  # rows a logger dropped, bridged; gaps filled
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


def _output_names(channels: dict, input: str, outputs, axes: list, odd: dict, path: Path) -> list[str]:
    """The output channels to read: those named, else every channel but the input and the
    axes; refused when one is unknown, none is left, one holds no value, or lengths differ."""
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
    return names


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
        if file_fs < SLOWEST_FS:
            raise DataError(
                f"{path.name}: the time column, read in seconds, steps by {1 / file_fs:.4g} s ({file_fs:.4g} Hz "
                f"sampling), far too slow for a vibration record: if it is in milliseconds, name the column "
                f"'time_ms' or 'time [ms]' (or give its unit in a row under the header), or give the sampling "
                "rate with fs=... (CLI: --fs)."
            )
        return float(file_fs)
    if file_fs is not None and min(abs(file_fs * unit - user_fs) for unit in (1, 1e3, 1e6)) > TIME_JITTER * user_fs:
        raise DataError(
            f"{path.name}: the file's time column gives fs = {file_fs:.6g} Hz but fs = "
            f"{user_fs:.6g} Hz was passed; drop one of them."
        )
    return float(user_fs)
