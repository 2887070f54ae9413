"""Run a study: read and check every recording, analyse them in parallel (local processes or
a dask.distributed cluster), reuse cached results, and gather the tables."""

from __future__ import annotations

import json
import os
import sys
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from armaxmodal.exceptions import ArmaxModalError, DataError
from armaxmodal.io.read import read_recording
from armaxmodal.io.write import atomic_write, strict_json
from armaxmodal.study.job import StudySettings, analyse_recording
from armaxmodal.study.manifest import Entry, content_hash, read_manifest
from armaxmodal.study.tables import StudyTables, build_tables

__all__ = ["Study", "run_study"]

CACHE_FOLDER = ".cache"
#: the form of a cached result: raised when a result gains a field, so that older files are not read
RESULT_FORM = 2


@dataclass
class Study:
    """A finished study.

    Attributes
    ----------
    settings : StudySettings
    sensors : tuple of str
        The sensors every analysed recording shares (the modes and shapes use these).
    recordings : list of dict
        One per analysed recording: its manifest fields and :func:`analyse_recording`'s result.
    failures : list of dict
        ``{"file", "reason"}`` for every recording left out.
    tables : StudyTables
        modes, per-sensor, per-subject and summary tables, geometric-mean shapes.
    reused : int
        Recordings taken from the cache of an earlier run.

    See Also
    --------
    armaxmodal.study.run_study : What makes one.
    armaxmodal.study.write_study : Its files.

    Examples
    --------
    Two subjects' random rides (:func:`~armaxmodal.study.make_study`) analysed:

    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> from armaxmodal.study import StudySettings, make_study
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     _ = make_study(folder, 2, feet_subjects=(), separate_feet=(), rides=("random",), duration=60.0)
    ...     study = am.run_study(pathlib.Path(folder) / "manifest.csv", pathlib.Path(folder) / "out",
    ...                          StudySettings(orders=(2, 12)), jobs=1)
    >>> study.sensors, len(study.recordings), study.failures, study.reused
    (('head', 'chest', 'pelvis', 'legs'), 2, [], 0)
    """

    settings: StudySettings
    sensors: tuple[str, ...]
    recordings: list[dict]
    failures: list[dict]
    tables: StudyTables
    reused: int = 0
    notes: list[str] = field(default_factory=list)
    models: list[dict] | None = None
    scaled: list[dict] | None = None

    def to_dict(self) -> dict:
        """The ``study.json`` contract: settings, recordings, failures, summary.

        Returns
        -------
        dict
            Strict-JSON-ready (no NaN): what ``study.json`` holds.
        """
        recordings = [{k: v for k, v in r.items() if k != "figure_png"} for r in self.recordings]
        return strict_json(
            {
                "settings": {
                    **self.settings.to_dict(),
                    "sensors": list(self.sensors),
                    "model": self.models is not None,
                },
                "recordings": recordings,
                "failures": self.failures,
                "summary": self.tables.summary.to_dict("records"),
                "subjects": self.tables.subjects.to_dict("records"),
                "shape_geomean": self.tables.shape_records(),
                "notes": self.notes,
                "models": self.models,
            }
        )


def run_study(
    source: str | Path,
    out: str | Path,
    settings: StudySettings | None = None,
    *,
    jobs: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
    model: bool = False,
) -> Study:
    """Analyse every recording of a manifest or folder.

    Parameters
    ----------
    source : path
        Manifest CSV or folder (see :func:`~armaxmodal.study.read_manifest`).
    out : path
        The study folder: each finished recording is cached in ``out/.cache`` (keyed by the
        file's content hash and the settings) so an interrupted study resumes where it stopped.
    settings : StudySettings, optional
    jobs : int, optional
        Local worker processes (default: every core; 1 runs in this process).
    scheduler : str, optional
        Address of a dask.distributed scheduler (``tcp://host:8786``); overrides ``jobs``.
    progress : bool
        A tqdm bar over recordings.
    model : bool
        Also fit the chain model of each ride's average subject and scale it to every subject
        (``armaxmodal.study.model.average_subject_models``).

    Returns
    -------
    Study

    See Also
    --------
    armaxmodal.study.write_study : Write a finished study's tables, figures and report.
    armaxmodal.select_modes : What each recording's job runs.

    Examples
    --------
    Two subjects' rides in one folder, analysed and tabled:

    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     for k in (1, 2):
    ...         ride = am.simulate_recording(am.supine_human(), am.random_vibration(60.0, 60.0, seed=k), 60.0,
    ...                                      noise=0.03, seed=k)
    ...         _ = am.write_recording_csv(ride, pathlib.Path(folder) / f"Sub0{k}_ride.csv")
    ...     study = am.run_study(folder, pathlib.Path(folder) / "out", jobs=1)
    >>> sorted(set(study.tables.modes.subject))
    ['Sub01_ride', 'Sub02_ride']
    """
    settings = settings or StudySettings()
    entries, failures = read_manifest(source)
    loaded = _load_all(entries, settings, failures, progress)
    if not loaded:
        raise DataError(f"{source}: no recording could be read; the reasons: {_reasons(failures)}")
    sensors, notes = _common_sensors(loaded, settings, failures)
    loaded = [item for item in loaded if set(sensors) <= set(item[1].sensors)]
    notes += _rate_notes(loaded)
    cache = Path(out) / CACHE_FOLDER
    results, todo = {}, []
    for entry, rec, digest in loaded:
        cached = _read_cache(cache, digest, settings, sensors)
        if cached is not None:
            results[entry.row] = cached
        else:
            todo.append((entry, rec, digest))
    reused = len(results)

    def finished(entry: Entry, digest: str, result: dict | str) -> None:
        if isinstance(result, str):
            failures.append({"file": entry.name, "reason": result})
            return
        # through JSON at once: a fresh result and one read back from the cache are then identical
        text = json.dumps(strict_json(result), allow_nan=False)
        results[entry.row] = json.loads(text)
        atomic_write(_cache_path(cache, digest, settings, sensors), lambda tmp: Path(tmp).write_text(text, "utf-8"))

    _dispatch(todo, settings, sensors, jobs, scheduler, progress, finished)
    recordings = [_record(entry, digest, results[entry.row]) for entry, _, digest in loaded if entry.row in results]
    failures.sort(key=lambda f: str(f["file"]))
    tables = build_tables(recordings, sensors)
    study = Study(settings, sensors, recordings, failures, tables, reused, notes + tables.notes)
    if model:
        from armaxmodal.study.model import average_subject_models

        study.models, study.scaled = average_subject_models(study)
        study.notes += [
            f"{r['file']}: no mass_kg, so the average subject's model is not scaled to {r['subject']} (Eq. 4.7)"
            for r in recordings
            if r.get("mass_kg") is None
        ]
    return study


def _load_all(entries, settings, failures, progress) -> list[tuple[Entry, object, str]]:
    """Read every recording here, first: a corrupt file is a failure in seconds, not after the fits."""
    from tqdm import tqdm

    loaded = []
    for entry in tqdm(entries, desc="reading", unit="file", disable=not progress, file=sys.stderr):
        try:
            rec = read_recording(entry.file, input=settings.input, mass_kg=entry.mass_kg)
        except (ArmaxModalError, OSError, ValueError) as exc:
            failures.append({"file": entry.name, "reason": f"unreadable: {exc}"})
            continue
        if not entry.subject:
            entry = Entry(
                entry.row,
                entry.file,
                entry.name,
                rec.subject or entry.name.split(".")[0],
                entry.ride,
                rec.mass_kg,
                entry.labels,
            )
        elif entry.mass_kg is None and rec.mass_kg is not None:
            entry = Entry(entry.row, entry.file, entry.name, entry.subject, entry.ride, rec.mass_kg, entry.labels)
        loaded.append((entry, rec, content_hash(entry.file)))
    return loaded


def _common_sensors(loaded, settings, failures) -> tuple[tuple[str, ...], list[str]]:
    """The sensors the study analyses: as given, else those at least half the recordings
    have. A recording without one of them is a failure that says which."""
    if settings.sensors:
        sensors = tuple(settings.sensors)
    else:
        counts = Counter(s for _, rec, _ in loaded for s in rec.sensors)
        first = loaded[0][1].sensors
        order = list(first) + sorted(s for s in counts if s not in first)
        sensors = tuple(s for s in order if counts[s] * 2 >= len(loaded))
    notes = []
    for entry, rec, _ in loaded:
        missing = [s for s in sensors if s not in rec.sensors]
        if missing:
            failures.append(
                {
                    "file": entry.name,
                    "reason": f"lacks sensor(s) {missing} that the study analyses "
                    f"(its outputs: {list(rec.sensors)}); rename its columns or choose --sensors",
                }
            )
    extra = sorted({s for _, rec, _ in loaded for s in rec.sensors} - set(sensors))
    if extra and settings.sensors:
        notes.append(f"channel(s) {extra} not analysed: not among the chosen sensors {list(sensors)}")
    elif extra:
        notes.append(f"sensor(s) {extra} are on fewer than half the recordings: not in the modes (--lump may use them)")
    return sensors, notes


def _rate_notes(loaded) -> list[str]:
    rates = Counter(rec.fs for _, rec, _ in loaded)
    if len(rates) <= 1:
        return []
    usual = rates.most_common(1)[0][0]
    odd = [f"{e.name} ({rec.fs:g} Hz)" for e, rec, _ in loaded if rec.fs != usual]
    return [
        f"mixed sample rates: most recordings at {usual:g} Hz, but {', '.join(odd)}; each is analysed at "
        "its own rate (modes in Hz are comparable, thumbnails differ in span)"
    ]


def _dispatch(todo, settings, sensors, jobs, scheduler, progress, finished: Callable) -> None:
    from tqdm import tqdm

    bar = tqdm(total=len(todo), desc="recordings", unit="rec", disable=not progress or not todo, file=sys.stderr)
    try:
        if scheduler:
            _on_dask(todo, settings, sensors, scheduler, finished, bar)
        elif (jobs or os.cpu_count() or 1) <= 1 or len(todo) <= 1:
            for entry, rec, digest in todo:
                finished(entry, digest, _guarded(rec, settings, sensors))
                bar.update()
        else:
            _on_processes(todo, settings, sensors, jobs or os.cpu_count() or 1, finished, bar)
    finally:
        bar.close()


def _guarded(rec, settings, sensors) -> dict | str:
    """The analysis, or the reason it failed: one bad recording must not end the study."""
    try:
        return analyse_recording(rec, settings, sensors)
    except ArmaxModalError as exc:
        return str(exc)
    except Exception as exc:  # noqa: BLE001 - reported per recording, with its type, and the study goes on
        return f"{type(exc).__name__}: {exc}"


def _on_processes(todo, settings, sensors, jobs, finished, bar) -> None:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from armaxmodal.estimate.fit import load_kernels

    # fork, as the order sweep does: spawn would re-import the caller's script (which then
    # needs a __main__ guard) and compile or load every kernel once per worker
    load_kernels()
    ctx = multiprocessing.get_context("fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn")
    with ProcessPoolExecutor(min(jobs, len(todo)), mp_context=ctx) as pool:
        futures = {pool.submit(_guarded, rec, settings, sensors): (entry, digest) for entry, rec, digest in todo}
        for future in as_completed(futures):
            entry, digest = futures[future]
            finished(entry, digest, future.result())
            bar.update()


def _on_dask(todo, settings, sensors, address, finished, bar) -> None:
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise DataError(
            "--scheduler needs dask.distributed: pip install 'armaxmodal[cluster]' (or distributed), then retry."
        ) from None

    with Client(address) as client:
        futures = {
            client.submit(_guarded, rec, settings, sensors, pure=False): (entry, digest) for entry, rec, digest in todo
        }
        for future in as_completed(list(futures)):
            entry, digest = futures[future]
            finished(entry, digest, future.result())
            bar.update()


def _cache_path(cache: Path, digest: str, settings: StudySettings, sensors) -> Path:
    key = StudySettings(**{**settings.__dict__, "sensors": tuple(sensors)}).key()
    return cache / f"{digest[:24]}-{key}-r{RESULT_FORM}.json"


def _read_cache(cache: Path, digest, settings, sensors) -> dict | None:
    path = _cache_path(cache, digest, settings, sensors)
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None  # absent or half-written by a crash: analyse again


def _record(entry: Entry, digest: str, result: dict) -> dict:
    return {
        "file": entry.name,
        "subject": entry.subject,
        "ride": entry.ride,
        "mass_kg": entry.mass_kg,
        "labels": entry.labels,
        "content_sha256": digest,
        **result,
    }


def _reasons(failures) -> str:
    return "; ".join(f"{f['file']}: {f['reason']}" for f in failures[:5])
