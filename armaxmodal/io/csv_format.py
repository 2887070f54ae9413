"""CSV files: layout and separator checked first, comment metadata lines, a units row, text
cells, and the channels returned with the time axis.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pandas as pd

from armaxmodal.exceptions import DataError
from armaxmodal.io.time_axis import TO_SECONDS, bridge_dropped_rows, fs_from_time, time_scale


# -- CSV ------------------------------------------------------------------------------
def _check_csv_layout(path: Path) -> int:
    """Name the usual export mistakes before pandas turns them into a tokenizer error: a
    gzip file named .csv, another delimiter, metadata lines before the header. Returns how many
    columns at the end of the header have no name (a spreadsheet's trailing commas)."""
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
    # a byte-order mark at the start ("CSV UTF-8" in a spreadsheet) is read through, as pandas does
    text = head.decode("utf-8-sig", errors="replace").splitlines()[:-1]
    _check_byte_order_marks(path, text)
    lines = [ln for ln in text if ln.strip() and not ln.startswith("#")]
    if not lines:
        return 0
    _check_separator(path, lines[:200])
    commas = [ln.count(",") for ln in lines[:200]]
    if max(commas) == 0:
        return 0
    fields = max(set(commas), key=commas.count)
    leading = next((i for i, c in enumerate(commas) if c == fields), 0)
    if leading:
        raise DataError(
            f"{path.name}: {leading} line(s) before the header have fewer fields than the data (first: "
            f"{lines[0][:40]!r}): metadata lines. Put '#' before each (they are then read as comments) or "
            "delete them. Xsens DOT exports are read as they are when you pass one file per sensor."
        )
    return _check_duplicate_columns(path, lines[0])


def _check_byte_order_marks(path: Path, lines: list[str]) -> None:
    """Refuse a byte-order mark inside the file (at its start it is read through): one sits where
    a second exported file was appended to the first, and pandas would read it into a cell."""
    for i, line in enumerate(lines):
        if "\ufeff" in line:
            raise _byte_order_mark_error(path, f"line {i + 1}")


def _byte_order_mark_error(path: Path, where: str) -> DataError:
    return DataError(
        f"{path.name}: {where} holds a byte-order mark (the invisible mark a spreadsheet writes at the start of a "
        "'CSV UTF-8' file): two exported files joined into one? Keep one header and delete the mark, or analyse "
        "the parts apart."
    )


def _check_duplicate_columns(path: Path, header: str) -> int:
    """Refuse two columns of one name, naming them: pandas would rename the second ``name.1``
    in silence, and a channel renamed in silence is a wrong channel in the results. The unnamed
    columns at the header's end (``,,,,`` after every line, as spreadsheets write empty columns)
    are not a name given twice: their number is returned, for the reader to drop them."""
    import csv

    names = [name.strip() for name in next(csv.reader([header]))]
    trailing = len(names) - len("\0".join(names).rstrip("\0").split("\0")) if any(names) else 0
    names = names[: len(names) - trailing]
    seen: dict[str, list[int]] = {}
    for k, name in enumerate(names):
        seen.setdefault(name, []).append(k + 1)
    twice = {name: cols for name, cols in seen.items() if len(cols) > 1}
    if twice:
        listed = "; ".join(f"'{name}' (columns {', '.join(map(str, cols))})" for name, cols in twice.items())
        raise DataError(
            f"{path.name}: the header names a column more than once: {listed}. A channel exported twice, or two "
            "sensors given one name: rename them apart, or delete the copy."
        )
    return trailing


def _drop_unnamed_trailing(frame: pd.DataFrame, trailing: int, path: Path) -> tuple[pd.DataFrame, list]:
    """``frame`` without its ``trailing`` unnamed last columns, and a note, when every cell of
    them is empty; an unnamed column that holds data is refused by its number (a channel without
    a name cannot be used, and dropping it would lose it in silence)."""
    from armaxmodal.quality_warnings import QualityWarning

    if trailing == 0:
        return frame, []
    first = frame.shape[1] - trailing
    for k in range(first, frame.shape[1]):
        text = frame.iloc[:, k].astype(str).str.strip().str.lower()
        held = ~text.isin(_MISSING)
        if held.any():
            row = int(np.argmax(held.to_numpy()))
            raise DataError(
                f"{path.name}: column {k + 1} has no name in the header but holds data (data row {row + 1}: "
                f"{frame.iloc[row, k]!r}); give it a name, or delete the column."
            )
    note = QualityWarning(
        "empty_columns_dropped",
        (),
        f"{trailing} empty column(s) without a name at the end of every line (columns {first + 1}-{frame.shape[1]}, "
        "a spreadsheet's trailing commas) left out",
        float(trailing),
    )
    return frame.iloc[:, :first], [note]


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


def read_csv_file(path: Path, fill_gaps_s: float | None = None):
    trailing = _check_csv_layout(path)
    info = _csv_comments(path)
    try:
        # every cell a number, the common case, is parsed in C; anything else (text, empty or
        # missing cells) is read again as text below, to say which cell is wrong (the same
        # doubles either way: checked on the fixtures and a 20,000-row record)
        # pandas reads through a byte-order mark at the start itself
        options = {"comment": "#", "skipinitialspace": True, "keep_default_na": False}
        frame, dropped = _drop_unnamed_trailing(pd.read_csv(path, **options), trailing, path)
        numeric = all(dtype.kind in "iuf" for dtype in frame.dtypes)
        if not numeric:
            frame, dropped = _drop_unnamed_trailing(pd.read_csv(path, dtype=str, **options), trailing, path)
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
        channels = _text_channels(frame, path, missing_ok=fill_gaps_s is not None)
    file_fs = None
    time_col = next((c for c in channels if time_scale(c) is not None), None)
    if time_col is not None:
        t = channels.pop(time_col)
        if not np.all(np.isfinite(t)):
            raise DataError(f"{path.name}: the time column contains NaN or empty cells.")
        scale = TO_SECONDS.get(units.get(time_col, "").strip("()[] ").lower()) or time_scale(time_col)
        t, channels, bridged = bridge_dropped_rows(t * scale, channels, path, fill_gaps_s)
        file_fs, rounded = fs_from_time(t, path, _printed_digit(t, scale))
        dropped += bridged + rounded
    if dropped:
        info["read_warnings"] = dropped
    return channels, file_fs, info


def _printed_digit(t: np.ndarray, scale: float) -> float | None:
    """The last digit the time column was printed with, in seconds (``t`` in seconds, ``scale``
    seconds per unit of the column): the largest power of ten of the column's unit of which every
    stamp is a whole number; None below 1e-9 (a column printed in full, or not in decimals)."""
    raw = t / scale
    for decimals in range(10):
        scaled = raw * 10.0**decimals
        if np.all(np.abs(scaled - np.rint(scaled)) <= 1e-9 * np.maximum(1.0, np.abs(scaled))):
            return scale * 10.0**-decimals
    return None


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


def _text_channels(frame: pd.DataFrame, path: Path, missing_ok: bool = False) -> dict[str, np.ndarray]:
    """Channels of a CSV read as text: numbers parsed, text columns skipped, an all-missing
    column kept as NaN (refused by name if used), any other missing or non-numeric cell an
    error that names it; with ``missing_ok`` (``--fill-gaps``) a missing cell is NaN, for the
    gap filler to fill or refuse."""
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
        if missing_ok:
            bad &= ~text.str.lower().isin(_MISSING).to_numpy()
        if bad.any():
            row = int(np.argmax(bad))
            if text.iloc[row] == "":
                raise DataError(
                    f"{path.name}: column '{col}', data row {row + 1} is empty (a missing "
                    "sample); fill or trim it, or give --fill-gaps SECONDS (read_recording(fill_gaps=...)) to "
                    "interpolate gaps up to that length."
                )
            if "\ufeff" in frame[col].iloc[row]:
                raise _byte_order_mark_error(path, f"column '{col}', data row {row + 1}")
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
        with opener(path, "rt", encoding="utf-8-sig") as fh:
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
