"""What a study is made of: a manifest CSV (``file, subject, ride, mass_kg``, any other
columns kept as labels) or a folder of recordings, checked row by row before any fit."""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from armaxmodal.exceptions import DataError

__all__ = ["Entry", "read_manifest", "RECORDING_SUFFIXES"]

RECORDING_SUFFIXES = (".csv", ".csv.gz", ".mat", ".uff", ".unv")
KNOWN_COLUMNS = ("file", "subject", "ride", "mass_kg")


@dataclass(frozen=True)
class Entry:
    """One recording of the study.

    Attributes
    ----------
    row : int
        1-based row in the manifest (or position in the folder listing).
    file : Path
        Resolved path of the recording.
    name : str
        The file as the manifest gives it (how tables and failures name it).
    subject, ride : str
    mass_kg : float or None
        Subject mass, kg (for Eq. 4.7 scaling).
    labels : dict
        The manifest's other columns.

    See Also
    --------
    armaxmodal.study.read_manifest : What makes them.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from armaxmodal.study import make_study, read_manifest
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     _ = make_study(folder, 2, feet_subjects=(), separate_feet=(), rides=("random",), duration=30.0)
    ...     entries, _ = read_manifest(pathlib.Path(folder) / "manifest.csv")
    >>> entry = entries[0]
    >>> entry.row, entry.subject, entry.ride, round(entry.mass_kg, 1), entry.file.name
    (1, 'Sub01', 'random', 85.9, 'Sub01_random.csv')
    """

    row: int
    file: Path
    name: str
    subject: str
    ride: str
    mass_kg: float | None = None
    labels: dict = field(default_factory=dict)


def read_manifest(source: str | Path) -> tuple[list[Entry], list[dict]]:
    """The study's recordings and the rows that cannot be one.

    Parameters
    ----------
    source : path
        A manifest CSV, or a folder: its ``manifest.csv`` if it has one, else every
        recording in it (subject from the file's ``# subject:`` line or its name).

    Returns
    -------
    entries : list of Entry
    failures : list of dict
        ``{"file", "reason"}`` for a missing file, a duplicate row or an unusable mass.

    See Also
    --------
    armaxmodal.study.run_study : Reads its source with it.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from armaxmodal.study import make_study, read_manifest
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     _ = make_study(folder, 2, feet_subjects=(), separate_feet=(), rides=("random",), duration=30.0)
    ...     entries, refused = read_manifest(pathlib.Path(folder) / "manifest.csv")
    >>> [(entry.subject, entry.ride, entry.name) for entry in entries], refused
    ([('Sub01', 'random', 'Sub01_random.csv'), ('Sub02', 'random', 'Sub02_random.csv')], [])
    """
    source = Path(source)
    if source.is_dir():
        if (source / "manifest.csv").is_file():
            return _from_csv(source / "manifest.csv")
        return _from_folder(source), []
    if not source.is_file():
        raise DataError(f"{source}: no such manifest or folder.")
    return _from_csv(source)


def _from_csv(path: Path) -> tuple[list[Entry], list[dict]]:
    try:
        table = pd.read_csv(path, dtype=str, keep_default_na=False, skipinitialspace=True)
    except (pd.errors.ParserError, UnicodeDecodeError, pd.errors.EmptyDataError) as exc:
        raise DataError(f"{path}: not a readable manifest CSV ({exc}).") from exc
    table.columns = [c.strip() for c in table.columns]
    if "file" not in table.columns:
        raise DataError(
            f"{path}: a manifest needs a 'file' column (and optionally subject, ride, mass_kg); "
            f"its columns are {list(table.columns)}."
        )
    entries, failures, seen = [], [], {}
    for i, row in enumerate(table.to_dict("records"), start=1):
        name = row["file"].strip()
        if not name:
            failures.append({"file": f"(row {i})", "reason": "empty 'file' cell"})
            continue
        file = (path.parent / name).resolve()
        subject = row.get("subject", "").strip() or Path(name).name.split(".")[0]
        ride = row.get("ride", "").strip() or "all"
        if (file, ride, subject) in seen:
            failures.append(
                {"file": name, "reason": f"duplicate of manifest row {seen[(file, ride, subject)]}; skipped"}
            )
            continue
        seen[(file, ride, subject)] = i
        if not file.is_file():
            failures.append({"file": name, "reason": f"file not found ({file})"})
            continue
        try:
            mass = _mass(row.get("mass_kg", ""))
        except DataError as exc:
            failures.append({"file": name, "reason": str(exc)})
            continue
        labels = {k: v for k, v in row.items() if k not in KNOWN_COLUMNS}
        entries.append(Entry(i, file, name, subject, ride, mass, labels))
    return entries, failures


def _from_folder(folder: Path) -> list[Entry]:
    files = sorted(p for p in folder.iterdir() if p.is_file() and p.name.lower().endswith(RECORDING_SUFFIXES))
    if not files:
        raise DataError(f"{folder}: no recordings ({', '.join(RECORDING_SUFFIXES)}) and no manifest.csv in it.")
    # subject "" : taken from the file's '# subject:' line when the study reads it, else its name
    return [Entry(i, p.resolve(), p.name, "", "all") for i, p in enumerate(files, start=1)]


def _mass(text: str) -> float | None:
    text = str(text).strip()
    if not text:
        return None
    try:
        mass = float(text)
    except ValueError:
        raise DataError(f"mass_kg {text!r} is not a number") from None
    if not math.isfinite(mass) or mass <= 0:
        raise DataError(f"mass_kg {text!r} must be a positive number of kilograms")
    return mass


def content_hash(path: Path) -> str:
    """SHA-256 of the file's bytes: a recording's cache key does not depend on its name."""
    digest = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()
