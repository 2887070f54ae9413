"""A study's tables: modes matched across recordings, Table 3.2 per sensor, Table 3.3 per
subject and across subjects, and the Fig. 3.7 geometric-mean mode shapes.

:func:`~armaxmodal.study.summarise_subjects` is Table 3.3 from per-subject results the caller
already has: per subject the ``|M|``-weighted frequency and damping (Eqs. 3.35-3.36), then the
mean and standard deviation over subjects, and the geometric-mean mode-shape magnitudes
(Fig. 3.7)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.optimize import linear_sum_assignment

from armaxmodal.exceptions import DataError

__all__ = ["StudyTables", "build_tables", "match_modes", "summarise_subjects"]

#: a recording's mode is the ride's mode r when their frequencies are within this ratio
MATCH_RATIO = 1.25
SHAPE_FLOOR = 1e-6  # |phi| below this is taken as this in the geometric mean


@dataclass
class StudyTables:
    """Tidy tables (one row per observation) a person loads with pandas.

    Attributes
    ----------
    modes : DataFrame
        One row per recording and mode: file, subject, ride, mode (matched across the ride's
        recordings; empty for a mode no other recording has), rank (order in its own
        recording), freq_hz, damping, their 95 % intervals, the Eq. 3.35-3.36 weighted values.
    per_sensor : DataFrame
        Table 3.2: one row per recording, sensor and mode; NaN where the sensor's own model
        does not show the mode (the thesis's X), ``shown`` says which.
    subjects : DataFrame
        Table 3.3 rows: per ride, subject and mode the mean over that subject's recordings.
    summary : DataFrame
        Table 3.3's Average and SD rows: per ride and mode the mean and sample SD over subjects.
    shapes : DataFrame
        One row per recording, mode and sensor: the shape magnitude (largest component 1).
    geomean : DataFrame
        Per ride, mode and sensor the geometric mean of the subjects' magnitudes (Fig. 3.7).

    See Also
    --------
    armaxmodal.study.build_tables : What makes them.

    Examples
    --------
    The ride's modes over two subjects, each body scaled to its subject (``n``: the subjects whose
    selection found the mode; the exact means are 5.33, 8.62, 14.28 and 16.95 Hz):

    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> from armaxmodal.study import StudySettings, make_study
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     _ = make_study(folder, 2, feet_subjects=(), separate_feet=(), rides=("random",), duration=60.0)
    ...     study = am.run_study(pathlib.Path(folder) / "manifest.csv", pathlib.Path(folder) / "out",
    ...                          StudySettings(orders=(2, 12)), jobs=1)
    >>> study.tables.summary[["mode", "freq_hz_mean", "freq_hz_sd", "n"]].round(1)
       mode  freq_hz_mean  freq_hz_sd  n
    0     1           5.3         0.1  2
    1     2           8.6         0.1  2
    2     3          14.6         0.3  2
    3     4          16.9         0.7  2
    """

    modes: pd.DataFrame
    per_sensor: pd.DataFrame
    subjects: pd.DataFrame
    summary: pd.DataFrame
    shapes: pd.DataFrame
    geomean: pd.DataFrame
    notes: list[str] = field(default_factory=list)

    def shape_records(self) -> list[dict]:
        return self.geomean.to_dict("records")


def match_modes(freqs: list[np.ndarray]) -> tuple[np.ndarray, list[np.ndarray]]:
    """Number the modes of several recordings consistently.

    The reference is the per-rank median of the recordings with the most common number of
    modes; each recording's modes are assigned to reference modes by least total
    log-frequency distance (Hungarian algorithm), within ``MATCH_RATIO``.

    Parameters
    ----------
    freqs : list of 1-D arrays
        Each recording's natural frequencies, Hz, ascending.

    Returns
    -------
    reference : (n_ref,) ndarray, Hz
    labels : list of int arrays
        Per recording, the 1-based reference mode of each of its modes, 0 where none fits.

    See Also
    --------
    armaxmodal.study.match_tracks : Across events of one structure, by amplitude.

    Examples
    --------
    >>> import numpy as np
    >>> from armaxmodal.study import match_modes
    >>> reference, labels = match_modes([np.array([5.8, 8.3, 13.5]), np.array([5.9, 8.4, 13.4]),
    ...                                  np.array([5.7, 13.6])])  # the third recording lacks the 8 Hz mode
    >>> [round(float(f), 2) for f in reference], [mode.tolist() for mode in labels]
    ([5.85, 8.35, 13.45], [[1, 2, 3], [1, 2, 3], [1, 3]])
    """
    counts = pd.Series([f.size for f in freqs])
    usual = int(counts.mode().max()) if len(counts) else 0
    typical = [f for f in freqs if f.size == usual]
    reference = np.median(np.array(typical), axis=0) if usual else np.zeros(0)
    labels = []
    for f in freqs:
        lab = np.zeros(f.size, dtype=int)
        if f.size and reference.size:
            cost = np.abs(np.log(f[:, None] / reference[None, :]))
            rows, cols = linear_sum_assignment(cost)
            ok = cost[rows, cols] <= np.log(MATCH_RATIO)
            lab[rows[ok]] = cols[ok] + 1
        labels.append(lab)
    return reference, labels


def build_tables(recordings: list[dict], sensors) -> StudyTables:
    """All tables from the analysed recordings (see :class:`~armaxmodal.study.StudyTables`).

    Parameters
    ----------
    recordings : list of dict
        :func:`~armaxmodal.study.analyse_recording`'s results, each with its manifest entry.
    sensors : tuple of str
        The study's common sensors.

    Returns
    -------
    StudyTables

    See Also
    --------
    armaxmodal.study.StudyTables : What it returns.

    Examples
    --------
    The tables again from a finished study's recordings: each mode is numbered across the ride
    (``mode``), not within its recording (``rank``); the two are the same here, where every subject
    shows its four modes (Sub01's exact 5.40, 8.68, 14.49 and 17.28 Hz):

    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> from armaxmodal.study import StudySettings, make_study
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     _ = make_study(folder, 2, feet_subjects=(), separate_feet=(), rides=("random",), duration=60.0)
    ...     study = am.run_study(pathlib.Path(folder) / "manifest.csv", pathlib.Path(folder) / "out",
    ...                          StudySettings(orders=(2, 12)), jobs=1)
    >>> from armaxmodal.study import build_tables
    >>> tables = build_tables(study.recordings, study.sensors)
    >>> tables.modes[["subject", "mode", "rank", "freq_hz"]].round(1)
      subject  mode  rank  freq_hz
    0   Sub01     1     1      5.4
    1   Sub01     2     2      8.7
    2   Sub01     3     3     14.8
    3   Sub01     4     4     17.4
    4   Sub02     1     1      5.3
    5   Sub02     2     2      8.5
    6   Sub02     3     3     14.4
    7   Sub02     4     4     16.4
    """
    mode_rows, sensor_rows, shape_rows, notes = [], [], [], []
    for ride in sorted({r["ride"] for r in recordings}):
        group = [r for r in recordings if r["ride"] == ride]
        reference, labels = match_modes([np.array([m["freq_hz"] for m in r["modes"]], float) for r in group])
        for r, lab in zip(group, labels, strict=True):
            n_unmatched = int(np.sum(lab == 0))
            if n_unmatched:
                notes.append(
                    f"{r['file']}: {n_unmatched} mode(s) match none of the modes of ride {ride!r} "
                    f"({np.round(reference, 2).tolist()} Hz); listed without a mode number"
                )
            mode_rows += _mode_rows(r, lab)
            sensor_rows += _sensor_rows(r, lab)
            shape_rows += _shape_rows(r, lab)
    modes = pd.DataFrame(mode_rows, columns=MODE_COLUMNS)
    per_sensor = pd.DataFrame(sensor_rows, columns=SENSOR_COLUMNS)
    shapes = pd.DataFrame(shape_rows, columns=["file", "subject", "ride", "mode", "sensor", "mag"])
    subjects, summary = _across_subjects(modes)
    return StudyTables(modes, per_sensor, subjects, summary, shapes, _geomean(shapes, sensors), notes)


MODE_COLUMNS = [
    "file",
    "subject",
    "ride",
    "mode",
    "rank",
    "freq_hz",
    "damping",
    "freq_ci95_lo",
    "freq_ci95_hi",
    "damping_ci95_lo",
    "damping_ci95_hi",
    "freq_hz_weighted",
    "damping_weighted",
    "mass_kg",
]
SENSOR_COLUMNS = ["file", "subject", "ride", "sensor", "mode", "rank", "shown", "freq_hz", "damping"]


def _num(v) -> float:
    return np.nan if v is None else float(v)


def _mode_rows(r: dict, labels) -> list[dict]:
    rows = []
    for m, lab in zip(r["modes"], labels, strict=True):
        rows.append(
            {
                "file": r["file"],
                "subject": r["subject"],
                "ride": r["ride"],
                "mode": int(lab) if lab else pd.NA,
                "rank": m["rank"],
                "freq_hz": _num(m["freq_hz"]),
                "damping": _num(m["damping"]),
                "freq_ci95_lo": _num(m["freq_ci95"][0]),
                "freq_ci95_hi": _num(m["freq_ci95"][1]),
                "damping_ci95_lo": _num(m["damping_ci95"][0]),
                "damping_ci95_hi": _num(m["damping_ci95"][1]),
                "freq_hz_weighted": _num(m["freq_hz_weighted"]),
                "damping_weighted": _num(m["damping_weighted"]),
                "mass_kg": _num(r.get("mass_kg")),
            }
        )
    return rows


def _sensor_rows(r: dict, labels) -> list[dict]:
    rows = []
    for p in r["per_sensor"]:
        lab = labels[p["mode"] - 1]
        rows.append(
            {
                "file": r["file"],
                "subject": r["subject"],
                "ride": r["ride"],
                "sensor": p["sensor"],
                "mode": int(lab) if lab else pd.NA,
                "rank": p["mode"],
                "shown": p["freq_hz"] is not None,
                "freq_hz": _num(p["freq_hz"]),
                "damping": _num(p["damping"]),
            }
        )
    return rows


def _shape_rows(r: dict, labels) -> list[dict]:
    return [
        {
            "file": r["file"],
            "subject": r["subject"],
            "ride": r["ride"],
            "mode": int(lab),
            "sensor": s,
            "mag": _num(v["mag"]),
        }
        for m, lab in zip(r["modes"], labels, strict=True)
        if lab
        for s, v in m["shape"].items()
    ]


def _across_subjects(modes: pd.DataFrame) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Table 3.3: a subject's recordings of one ride averaged first, then mean and SD over subjects."""
    values = ["freq_hz", "damping", "freq_hz_weighted", "damping_weighted"]
    matched = modes.dropna(subset=["mode"]).astype({"mode": int})
    subjects = matched.groupby(["ride", "subject", "mode"], as_index=False)[values].mean()
    subjects["recordings"] = matched.groupby(["ride", "subject", "mode"]).size().to_numpy()
    grouped = subjects.groupby(["ride", "mode"])
    summary = grouped[values].agg(["mean", "std"])
    summary.columns = [f"{v}_{'sd' if s == 'std' else s}" for v, s in summary.columns]
    summary = summary.rename(columns={"damping_mean": "damping_mean"}).reset_index()
    summary["n"] = grouped.size().to_numpy()
    first = ["ride", "mode", "freq_hz_mean", "freq_hz_sd", "damping_mean", "damping_sd", "n"]
    return subjects, summary[first + [c for c in summary.columns if c not in first]]


def _geomean(shapes: pd.DataFrame, sensors) -> pd.DataFrame:
    """Fig. 3.7: per subject the mean log-magnitude, then the geometric mean over subjects."""
    if shapes.empty:
        return pd.DataFrame(columns=["ride", "mode", "sensor", "geomean", "n"])
    logs = shapes.assign(log=np.log(np.clip(shapes.mag.to_numpy(float), SHAPE_FLOOR, None)))
    per_subject = logs.groupby(["ride", "mode", "sensor", "subject"], as_index=False).log.mean()
    out = per_subject.groupby(["ride", "mode", "sensor"], as_index=False).log.agg(["mean", "size"])
    out = out.rename(columns={"size": "n"})
    out["geomean"] = np.exp(out.pop("mean"))
    out["sensor"] = pd.Categorical(out.sensor, categories=list(sensors), ordered=True)
    return out.sort_values(["ride", "mode", "sensor"]).reset_index(drop=True)[
        ["ride", "mode", "sensor", "geomean", "n"]
    ]


def summarise_subjects(
    weighted: Sequence[pd.DataFrame], shapes: Sequence[np.ndarray] | None = None, subjects: Sequence[str] | None = None
) -> dict:
    """Table 3.3 and the Fig. 3.7 geometric-mean shapes over subjects.

    Parameters
    ----------
    weighted : sequence of DataFrame
        Per subject, one row per mode with ``freq_hz`` and ``damping`` (the Eq. 3.35-3.36
        weighted values, e.g. ``ModeSelection.weighted``); every subject must have the
        same modes in the same order.
    shapes : sequence of (n_sensors, n_modes) arrays, optional
        Per subject mode shapes; magnitudes are normalised to a unit largest component.
    subjects : sequence of str, optional

    Returns
    -------
    dict
        ``table`` (one row per subject plus ``Average`` and ``SD`` rows, sample SD) and
        ``shape_geomean`` ((n_sensors, n_modes), when shapes are given).

    See Also
    --------
    armaxmodal.study.build_tables : Builds Table 3.3 from a study's recordings.

    Examples
    --------
    Table 3.3's Average and SD rows over two subjects:

    >>> import pandas as pd
    >>> from armaxmodal.study import summarise_subjects
    >>> one = pd.DataFrame({"freq_hz": [5.8, 8.3], "damping": [0.25, 0.35]})
    >>> two = pd.DataFrame({"freq_hz": [6.2, 8.7], "damping": [0.27, 0.33]})
    >>> summarise_subjects([one, two], subjects=["Sub01", "Sub02"])["table"].round(3)
             f1_hz  f2_hz  damping1  damping2
    Sub01    5.800  8.300     0.250     0.350
    Sub02    6.200  8.700     0.270     0.330
    Average  6.000  8.500     0.260     0.340
    SD       0.283  0.283     0.014     0.014
    """
    counts = {len(w) for w in weighted}
    if len(counts) != 1:
        raise DataError(
            f"subjects have different numbers of modes {sorted(counts)}; select the same number "
            "for each (select_modes(..., n_modes=N), CLI --modes N) before summarising."
        )
    names = list(subjects) if subjects is not None else [f"Sub{i + 1}" for i in range(len(weighted))]
    n_modes = counts.pop()
    f = np.array([w.freq_hz.to_numpy() for w in weighted], dtype=float)
    x = np.array([w.damping.to_numpy() for w in weighted], dtype=float)
    cols = [f"f{i + 1}_hz" for i in range(n_modes)] + [f"damping{i + 1}" for i in range(n_modes)]
    table = pd.DataFrame(np.hstack([f, x]), index=names, columns=cols)
    table.loc["Average"] = np.hstack([f.mean(axis=0), x.mean(axis=0)])
    table.loc["SD"] = np.hstack([f.std(axis=0, ddof=1), x.std(axis=0, ddof=1)])
    out = {"table": table}
    if shapes is not None:
        mags = np.array([np.abs(s) / np.abs(s).max(axis=0, keepdims=True) for s in shapes])
        out["shape_geomean"] = np.exp(np.mean(np.log(mags), axis=0))
    return out
