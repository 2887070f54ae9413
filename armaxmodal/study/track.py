"""Many records of one structure: each event's modes, matched across events, and each mode's
trend with the shaking (structural-health monitoring from strong-motion records).

The rules, stated once:

* **Matching.** Events are taken in order of their peak input acceleration, since the shaking's
  amplitude is what moves the modes of a softening structure. Each track keeps the mode it last
  matched. An event's modes are assigned to tracks by least total cost (Hungarian algorithm),
  the cost ``|ln(f / f_track)| / ln(freq_ratio) + (1 - MAC) / (1 - min_mac)``; a pair is
  admissible only with ``f`` within ``freq_ratio`` of the track's and a MAC of at least
  ``min_mac``. A mode matching no track starts one.
* **Trend.** Per track, the frequency against ``log10`` of the peak input: a weighted straight
  line, each event weighted by its own variance (from its 95 % interval) plus the scatter between
  events beyond their intervals (Paule-Mandel: the ``tau**2`` that makes the weighted residual sum
  of squares its degrees of freedom). Where the peaks span less than ``min_span`` the trend is a
  constant.
* **Departure.** Each event against the trend fitted to the *other* events (leave one out, so an
  outlier cannot hide in its own fit): ``z = (f - trend) / sqrt(sd**2 + tau**2 + var(trend))``;
  flagged where ``|z|`` exceeds the normal quantile of ``level``. A track needs ``MIN_JUDGED``
  events for this (one left out leaves a line and one degree of freedom for ``tau``).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import optimize, stats
from scipy.optimize import linear_sum_assignment

from armaxmodal.exceptions import DataError
from armaxmodal.modal import mac
from armaxmodal.study.job import StudySettings
from armaxmodal.study.manifest import read_manifest

__all__ = ["Track", "TrackSettings", "fit_trend", "match_tracks", "track_modes"]

#: events a track needs before its departures are judged: one left out leaves three points,
#: a line and one degree of freedom for the scatter between events
MIN_JUDGED = 4
Z95 = stats.norm.ppf(0.975)  # the modes' intervals are 95 % ones


@dataclass(frozen=True)
class TrackSettings:
    """How modes are matched across events and when an event is flagged.

    Attributes
    ----------
    freq_ratio : float
        Largest frequency ratio between a mode and the track it joins (1.35: a bridge's
        fundamental falls by a fifth to a quarter from weak to strong shaking, Meloland's 2.95
        to 2.26 Hz between neighbouring events).
    min_mac : float
        Least MAC between a mode's shape and the track's. None by default: shapes seen by a few
        sensors are often too uncertain to gate on (the supine body's 13.5 Hz mode reads MACs of
        0.2-0.9 between neighbouring events whose frequencies are right within 1 %), so the shape
        enters the cost only, as a tie-breaker between modes of like frequency.
    level : float
        Two-sided level of the departure test (0.99: with 20 events one false flag in five studies).
    min_span : float
        Least ratio of the largest to the smallest peak input for a sloped trend.
    input_scale : float
        Factor from the recording's input units to ``input_unit`` (1/980.665 for cm/s² to g).
    input_unit : str
        The unit the peak input is reported in.

    See Also
    --------
    armaxmodal.study.track_modes : Where they apply.

    Examples
    --------
    >>> from armaxmodal.study import TrackSettings
    >>> TrackSettings(input_scale=1 / 980.665, input_unit="g").freq_ratio
    1.35
    """

    freq_ratio: float = 1.35
    min_mac: float = 0.0
    level: float = 0.99
    min_span: float = 2.0
    input_scale: float = 1.0
    input_unit: str = "as recorded"

    def __post_init__(self):
        checks = {
            "freq_ratio": self.freq_ratio > 1,
            "min_mac": 0 <= self.min_mac < 1,
            "level": 0 < self.level < 1,
            "min_span": self.min_span >= 1,
            "input_scale": self.input_scale > 0 and math.isfinite(self.input_scale),
        }
        wrong = [name for name, ok in checks.items() if not ok]
        if wrong:
            raise DataError(
                f"TrackSettings: {', '.join(f'{n}={getattr(self, n)!r}' for n in wrong)} out of range "
                "(freq_ratio > 1, 0 <= min_mac < 1, 0 < level < 1, min_span >= 1, input_scale > 0)."
            )


@dataclass
class Track:
    """Modes followed across the events of one structure.

    Attributes
    ----------
    table : DataFrame
        One row per event and mode: file, date, peak_input, quality, mode (the track, numbered by
        median frequency), freq_hz and damping with their 95 % intervals, mac (to the mode the
        track held before), trend_hz (the others' trend at this event), z and flagged.
    trends : DataFrame
        One row per mode: events, median frequency, the trend's value at a peak input of 1
        (``intercept_hz``), its slope (Hz per tenfold peak input) and the slope's SD, tau_hz
        (scatter between events beyond their intervals), judged (enough events to flag).
    events : DataFrame
        One row per event: file, date, peak_input, quality, modes found.
    settings : TrackSettings
    study : Study
        The per-event analyses (:func:`~armaxmodal.study.run_study`).
    notes : list of str

    See Also
    --------
    armaxmodal.study.track_modes : What makes one.
    armaxmodal.study.write_track : Its files.

    Examples
    --------
    Three short rides of the supine body at growing input, each mode a track of three events:

    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> from armaxmodal.study import StudySettings, track_modes
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     for k, rms in enumerate((0.5, 1.0, 2.0)):
    ...         base = am.random_vibration(60.0, 30.0, rms=rms, seed=k)
    ...         ride = am.simulate_recording(am.supine_human(), base, 60.0, noise=0.03, seed=k)
    ...         _ = am.write_recording_csv(ride, pathlib.Path(folder) / f"event{k}.csv")
    ...     followed = track_modes(folder, pathlib.Path(folder) / "out", StudySettings(orders=(2, 12)), jobs=1)
    >>> followed.table.groupby("mode").file.count().tolist(), int(followed.table.flagged.sum())
    ([3, 3, 3, 3], 0)
    """

    table: pd.DataFrame
    trends: pd.DataFrame
    events: pd.DataFrame
    settings: TrackSettings
    study: object
    notes: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        """The ``track.json`` contract.

        Returns
        -------
        dict
            Strict-JSON-ready: settings, events, trends, rows, failures and notes.
        """
        from armaxmodal.io.write import strict_json

        return strict_json(
            {
                "settings": {**asdict(self.settings), **self.study.to_dict()["settings"]},
                "events": _records(self.events),
                "trends": self.trends.to_dict("records"),
                "modes": _records(self.table),
                "failures": self.study.failures,
                "notes": self.notes,
            }
        )


def _records(frame: pd.DataFrame) -> list[dict]:
    """Rows with dates as ISO text (None where the manifest gives none)."""
    dates = [None if pd.isna(d) else d.isoformat() for d in frame.date]
    return [{**row, "date": d} for row, d in zip(frame.to_dict("records"), dates, strict=True)]


def match_tracks(
    events: list[list[tuple[float, np.ndarray]]], settings: TrackSettings
) -> list[list[tuple[int, float]]]:
    """Assign each event's modes to tracks (see the module's matching rule).

    Parameters
    ----------
    events : list of list of (freq_hz, shape)
        Per event, in the order to match (by peak input), its modes: frequency in Hz and the
        complex shape over the sensors every event shares.
    settings : TrackSettings

    Returns
    -------
    list of list of (int, float)
        Per event and mode, its track (0-based, in order of creation) and the MAC to the mode
        the track held before (NaN for a track's first mode).

    See Also
    --------
    armaxmodal.study.match_modes : A study's matching of one ride's modes to a reference.

    Examples
    --------
    Two modes that soften by 10 % between events, a third mode seen once:

    >>> import numpy as np
    >>> from armaxmodal.study import TrackSettings, match_tracks
    >>> bend, twist = np.array([1.0, 1.0]), np.array([1.0, -1.0])
    >>> tracks = match_tracks([[(4.0, bend), (6.0, twist)], [(3.6, bend), (5.4, twist), (9.0, bend)]],
    ...                       TrackSettings())
    >>> [[track for track, _ in event] for event in tracks]
    [[0, 1], [0, 1, 2]]
    """
    held: list[tuple[float, np.ndarray]] = []
    assigned = []
    for modes in events:
        labels = [(-1, math.nan)] * len(modes)
        if modes and held:
            cost = np.full((len(modes), len(held)), np.inf)
            macs = np.array([[mac(shape, track_shape) for _, track_shape in held] for _, shape in modes])
            ratio = np.abs(np.log(np.array([m[0] for m in modes])[:, None] / np.array([h[0] for h in held])[None, :]))
            ok = (ratio <= math.log(settings.freq_ratio)) & (macs >= settings.min_mac)
            cost[ok] = (ratio / math.log(settings.freq_ratio) + (1 - macs) / (1 - settings.min_mac))[ok]
            rows, cols = linear_sum_assignment(np.where(ok, cost, 1e9))
            for i, t in zip(rows, cols, strict=True):
                if ok[i, t]:
                    labels[i] = (int(t), float(macs[i, t]))
        for i, (label, mode) in enumerate(zip(labels, modes, strict=True)):
            if label[0] < 0:
                held.append(mode)
                labels[i] = (len(held) - 1, math.nan)
            else:
                held[label[0]] = mode
        assigned.append(labels)
    return assigned


@dataclass(frozen=True)
class Trend:
    """A weighted trend of frequency against ``log10`` peak input.

    Attributes
    ----------
    coef : (p,) ndarray
        ``(value at a peak input of 1, Hz per tenfold input)``, or ``(mean,)`` for a constant.
    cov : (p, p) ndarray
        Their covariance.
    tau2 : float
        Variance between events beyond their own intervals, Hz².

    See Also
    --------
    armaxmodal.study.fit_trend : What makes one.

    Examples
    --------
    >>> import numpy as np
    >>> from armaxmodal.study import Trend
    >>> trend = Trend(np.array([4.0, -0.5]), np.diag([1e-4, 1e-4]), 0.0)
    >>> value, variance = trend.at(-1.0)  # at a peak input of 0.1
    >>> round(value, 3), round(variance, 6)
    (4.5, 0.0002)
    """

    coef: np.ndarray
    cov: np.ndarray
    tau2: float

    def at(self, log_peak: float) -> tuple[float, float]:
        """The trend's value (Hz) at ``log10`` of a peak input, and that value's variance (Hz²).

        Parameters
        ----------
        log_peak : float
            ``log10`` of the peak input.

        Returns
        -------
        value : float
        variance : float
        """
        row = np.array([1.0, log_peak])[: self.coef.size]
        return float(row @ self.coef), float(row @ self.cov @ row)


def fit_trend(log_peak: np.ndarray, freq_hz: np.ndarray, sd_hz: np.ndarray, sloped: bool = True) -> Trend:
    """Weighted least squares with the Paule-Mandel scatter between events.

    Parameters
    ----------
    log_peak : (n,) array
        ``log10`` of each event's peak input.
    freq_hz, sd_hz : (n,) arrays
        Each event's frequency and its standard deviation, Hz.
    sloped : bool
        A straight line (else a constant).

    Returns
    -------
    Trend

    See Also
    --------
    armaxmodal.study.track_modes : Judges each event against the other events' trend.

    Examples
    --------
    Three events on the line ``f = 4 - 0.5 log10(a)`` and a fourth 0.1 Hz off it:

    >>> import numpy as np
    >>> from armaxmodal.study import fit_trend
    >>> trend = fit_trend(np.array([-2.0, -1.0, 0.0, 1.0]), np.array([5.0, 4.5, 4.0, 3.6]), np.full(4, 0.01))
    >>> np.round(trend.coef, 2).tolist(), round(float(np.sqrt(trend.tau2)), 3)
    ([4.04, -0.47], 0.037)
    """
    design = np.column_stack([np.ones_like(log_peak), log_peak])[:, : 2 if sloped else 1]
    dof = len(freq_hz) - design.shape[1]

    def weighted(tau2: float) -> tuple[np.ndarray, np.ndarray, float]:
        w = 1.0 / (sd_hz**2 + tau2)
        cov = np.linalg.inv(design.T @ (w[:, None] * design))
        coef = cov @ design.T @ (w * freq_hz)
        return coef, cov, float(np.sum(w * (freq_hz - design @ coef) ** 2))

    tau2 = 0.0
    if dof > 0 and weighted(0.0)[2] > dof:
        ols = np.linalg.lstsq(design, freq_hz, rcond=None)[0]
        top = 2 * float(np.sum((freq_hz - design @ ols) ** 2)) / dof  # there the weighted sum is below dof / 2
        tau2 = optimize.brentq(lambda t: weighted(t)[2] - dof, 0.0, top)
    coef, cov, _ = weighted(tau2)
    return Trend(coef, cov, tau2)


def track_modes(
    source: str | Path,
    out: str | Path,
    settings: StudySettings | None = None,
    track: TrackSettings | None = None,
    *,
    jobs: int | None = None,
    scheduler: str | None = None,
    progress: bool = False,
) -> Track:
    """Analyse every event of one structure and follow its modes from event to event.

    Parameters
    ----------
    source : path
        A manifest CSV (``file`` and optionally ``date``, ISO 8601, and any labels) or a folder of
        the structure's records.
    out : path
        Folder for the per-event cache (as :func:`~armaxmodal.study.run_study`'s).
    settings : StudySettings, optional
        What every event goes through.
    track : TrackSettings, optional
        The matching and departure rules (see the module's docstring).
    jobs, scheduler, progress
        As :func:`~armaxmodal.study.run_study`'s: local processes, a dask.distributed cluster, a tqdm bar.

    Returns
    -------
    Track

    See Also
    --------
    armaxmodal.study.write_track : Write the table, the figure and the report.
    armaxmodal.study.run_study : The per-event analyses.

    Examples
    --------
    Three events of the supine body, the input's RMS 0.5, 1 and 2:

    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> from armaxmodal.study import track_modes
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     for k, rms in enumerate((0.5, 1.0, 2.0)):
    ...         base = am.random_vibration(60.0, 60.0, rms=rms, seed=k)
    ...         ride = am.simulate_recording(am.supine_human(), base, 60.0, noise=0.03, seed=k)
    ...         _ = am.write_recording_csv(ride, pathlib.Path(folder) / f"event{k}.csv")
    ...     followed = track_modes(folder, pathlib.Path(folder) / "out", jobs=1)
    >>> followed.trends[["mode", "events"]].values.tolist()
    [[1, 3], [2, 3], [3, 3], [4, 3]]
    """
    from armaxmodal.study.run import run_study

    track = track or TrackSettings()
    entries, _ = read_manifest(source)
    for entry in entries:  # a bad date is refused before any fit
        _date(entry.labels.get("date"), entry.name)
    study = run_study(source, out, settings, jobs=jobs, scheduler=scheduler, progress=progress)
    return follow(study, track)


def follow(study, track: TrackSettings) -> Track:
    """The tracks of a finished study's events (see :func:`track_modes`).

    Parameters
    ----------
    study : Study
    track : TrackSettings

    Returns
    -------
    Track
    """
    events = _events(study, track)
    usable = events[events.quality != "poor"].sort_values("peak_input", kind="stable")
    notes = [
        f"{row.file}: quality poor (its modes do not explain its FRF), so not matched nor in any trend"
        for row in events[events.quality == "poor"].itertuples()
    ]
    notes += [
        f"{row.file}: a resonance its input does not drive named at {row.undriven_hz} Hz (undriven_resonance): "
        "no mode is reported there, so it is in no track; the figure marks it"
        for row in events[events.undriven_hz != ""].itertuples()
    ]
    records = {r["file"]: r for r in study.recordings}
    modes = [_modes(records[name], study.sensors) for name in usable.file]
    labels = match_tracks([[(m["freq_hz"], m["shape"]) for m in ms] for ms in modes], track)
    rows = [
        {**_event_row(event), **_mode_row(mode), "track": label, "mac": round_mac}
        for event, ms, ls in zip(usable.itertuples(), modes, labels, strict=True)
        for mode, (label, round_mac) in zip(ms, ls, strict=True)
    ]
    table = pd.DataFrame(rows, columns=[*_EVENT_COLUMNS, *_MODE_COLUMNS, "track", "mac"])
    table = _numbered(table)
    table, trends = _judged(table, track)
    for row in table[table.flagged].itertuples():
        notes.append(
            f"mode {row.mode} on {row.file}: {row.freq_hz:.3f} Hz against the other events' trend "
            f"{row.trend_hz:.3f} Hz (z = {row.z:+.1f}): departs beyond its interval"
        )
    notes += [
        f"mode {t.mode} seen on {t.events} event(s): too few to judge departures (at least {MIN_JUDGED})"
        for t in trends.itertuples()
        if not t.judged
    ]
    # the study's own matching of modes across one ride is not the tracks': its notes are left out
    own = [n for n in study.notes if n not in study.tables.notes]
    return Track(table, trends, events, track, study, own + notes)


_EVENT_COLUMNS = ["file", "date", "peak_input", "quality"]
_MODE_COLUMNS = ["freq_hz", "freq_ci95_lo", "freq_ci95_hi", "damping", "damping_ci95_lo", "damping_ci95_hi"]


def _date(text, name: str) -> pd.Timestamp | None:
    if text is None or not str(text).strip():
        return None
    try:
        return pd.Timestamp(str(text).strip())
    except ValueError:
        raise DataError(f"{name}: date {text!r} is not a date; write it as 2013-10-11 (ISO 8601).") from None


def _events(study, track: TrackSettings) -> pd.DataFrame:
    rows = [
        {
            "file": r["file"],
            "date": _date(r.get("labels", {}).get("date"), r["file"]),
            "peak_input": r["peak_input"] * track.input_scale,
            "quality": r["quality"],
            "modes_found": len(r["modes"]),
            "undriven_hz": " ".join(f"{hz:.3f}" for hz in undriven_hz(r)),
        }
        for r in study.recordings
    ]
    return pd.DataFrame(rows, columns=[*_EVENT_COLUMNS, "modes_found", "undriven_hz"])


def undriven_hz(record: dict) -> list[float]:
    """The frequencies (Hz) an event's ``undriven_resonance`` notes name: a resonance the record shows
    but whose input does not drive it as a mode (no mode is reported there, so it is in no track)."""
    return [w["value"] for w in record.get("warnings", ()) if w["code"] == "undriven_resonance"]


def _event_row(event) -> dict:
    return {name: getattr(event, name) for name in _EVENT_COLUMNS}


def _mode_row(mode: dict) -> dict:
    lo_f, hi_f = mode["freq_ci95"]
    lo_d, hi_d = mode["damping_ci95"]
    values = (mode["freq_hz"], lo_f, hi_f, mode["damping"], lo_d, hi_d)
    return {name: math.nan if v is None else float(v) for name, v in zip(_MODE_COLUMNS, values, strict=True)}


def _modes(record: dict, sensors) -> list[dict]:
    """An event's modes with their complex shapes over the study's sensors."""
    return [
        {
            **mode,
            "shape": np.array(
                [mode["shape"][s]["mag"] * np.exp(1j * np.radians(mode["shape"][s]["phase_deg"])) for s in sensors]
            ),
        }
        for mode in record["modes"]
    ]


def _numbered(table: pd.DataFrame) -> pd.DataFrame:
    """Tracks numbered 1, 2, ... by their median frequency."""
    order = table.groupby("track").freq_hz.median().sort_values().index
    number = {track: k for k, track in enumerate(order, start=1)}
    table = table.assign(mode=table.track.map(number)).drop(columns="track")
    return table.sort_values(["mode", "peak_input"], kind="stable").reset_index(drop=True)


def _judged(table: pd.DataFrame, track: TrackSettings) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Each event's departure from the others' trend, then each track's trend over the events
    not flagged (an outlier must not set the slope and the scatter it is judged against)."""
    table = table.assign(trend_hz=math.nan, z=math.nan)
    critical = stats.norm.ppf(0.5 + track.level / 2)
    trends = []
    for mode, group in table.groupby("mode"):
        sd = ((group.freq_ci95_hi - group.freq_ci95_lo) / (2 * Z95)).to_numpy()
        fitted = group[np.isfinite(sd) & (sd > 0)]
        x, y, s = np.log10(fitted.peak_input.to_numpy()), fitted.freq_hz.to_numpy(), sd[np.isfinite(sd) & (sd > 0)]
        sloped = len(fitted) > 2 and fitted.peak_input.max() >= track.min_span * fitted.peak_input.min()
        judged = len(fitted) >= MIN_JUDGED
        if judged:
            table.loc[fitted.index, ["trend_hz", "z"]] = _left_out(x, y, s, sloped)
        kept = ~(np.abs(table.loc[fitted.index, "z"].to_numpy()) > critical)
        row = {"mode": mode, "events": len(group), "median_hz": float(group.freq_hz.median()), "judged": judged}
        if kept.sum() >= 2:
            whole = fit_trend(x[kept], y[kept], s[kept], sloped and kept.sum() > 2)
            sloped_fit = whole.coef.size == 2
            row["intercept_hz"] = whole.coef[0] if sloped_fit else math.nan
            row["slope_hz_per_decade"] = whole.coef[1] if sloped_fit else math.nan
            row["slope_sd"] = math.sqrt(whole.cov[1, 1]) if sloped_fit else math.nan
            row["tau_hz"] = math.sqrt(whole.tau2)
        trends.append(row)
    table["flagged"] = table.z.abs() > critical  # NaN (not judged) compares False
    columns = ["mode", "events", "median_hz", "intercept_hz", "slope_hz_per_decade", "slope_sd", "tau_hz", "judged"]
    return table, pd.DataFrame(trends).reindex(columns=columns)


def _left_out(x: np.ndarray, y: np.ndarray, s: np.ndarray, sloped: bool) -> np.ndarray:
    """Per event, the trend of the others at its peak input (Hz) and its departure z."""
    out = np.empty((len(y), 2))
    for k in range(len(y)):
        others = np.arange(len(y)) != k
        trend = fit_trend(x[others], y[others], s[others], sloped)
        value, variance = trend.at(x[k])
        out[k] = value, (y[k] - value) / math.sqrt(s[k] ** 2 + trend.tau2 + variance)
    return out
