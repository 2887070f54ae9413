"""A track's files: the tables, the figure of each mode against the shaking and the date, and
the HTML report, written whole or not at all."""

from __future__ import annotations

import html
import json
from pathlib import Path

import numpy as np
import pandas as pd

from armaxmodal.io.report.html_page import figure_uri, page, table
from armaxmodal.io.write import write_all
from armaxmodal.study.track import Track

__all__ = ["plot_track", "write_track", "TRACK_FILES"]

TRACK_FILES = ("track.csv", "trends.csv", "events.csv", "track.json", "track.png", "track.html")


def plot_track(track: Track):
    """Each mode's frequency and damping, with their 95 % intervals, against the event's peak
    input (log scale; the trend fitted to the events not flagged drawn through it) and, where the
    manifest gives dates, against the date. Flagged events are ringed in red.

    Parameters
    ----------
    track : Track

    Returns
    -------
    matplotlib.figure.Figure

    See Also
    --------
    armaxmodal.study.write_track : Saves it as ``track.png`` beside the tables.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> from armaxmodal.study import StudySettings, plot_track, track_modes
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     for k, rms in enumerate((0.5, 2.0)):
    ...         base = am.random_vibration(60.0, 30.0, rms=rms, seed=k)
    ...         ride = am.simulate_recording(am.supine_human(), base, 60.0, noise=0.03, seed=k)
    ...         _ = am.write_recording_csv(ride, pathlib.Path(folder) / f"event{k}.csv")
    ...     followed = track_modes(folder, pathlib.Path(folder) / "out", StudySettings(orders=(2, 12)), jobs=1)
    >>> fig = plot_track(followed)
    >>> [ax.get_ylabel() for ax in fig.axes]
    ['natural frequency (Hz)', 'damping ratio']
    """
    import matplotlib.pyplot as plt

    rows = track.table
    dated = rows.date.notna().any()
    fig, axes = plt.subplots(2, 2 if dated else 1, figsize=(11 if dated else 6.5, 7), squeeze=False, sharex="col")
    unit = track.settings.input_unit
    for (mode, group), colour in zip(rows.groupby("mode"), plt.cm.tab10.colors * 10, strict=False):
        label = f"mode {mode} ({group.freq_hz.median():.2f} Hz, {len(group)} event{'s' * (len(group) > 1)})"
        for col, x in enumerate(["peak_input", "date"][: 1 + dated]):
            if x == "date":
                group = group[group.date.notna()]
            for r, (y, lo, hi) in enumerate(
                [("freq_hz", "freq_ci95_lo", "freq_ci95_hi"), ("damping", "damping_ci95_lo", "damping_ci95_hi")]
            ):
                ax = axes[r, col]
                err = np.vstack([group[y] - group[lo], group[hi] - group[y]]).clip(min=0)
                ax.errorbar(
                    group[x],
                    group[y],
                    yerr=err,
                    fmt="o",
                    color=colour,
                    ms=4,
                    capsize=2,
                    label=label if (r, col) == (0, 0) else None,
                )
                flagged = group[group.flagged]
                ax.scatter(flagged[x], flagged[y], s=140, facecolors="none", edgecolors="red", zorder=3)
        _draw_trend(axes[0, 0], track, mode, group, colour)
    for r, name in enumerate(["natural frequency (Hz)", "damping ratio"]):
        axes[r, 0].set_ylabel(name)
        axes[r, 0].set_xscale("log")
        axes[1, 0].set_xlabel(f"peak input acceleration ({unit})")
        if dated:
            axes[1, 1].set_xlabel("date of the event")
            axes[r, 1].tick_params(axis="x", labelrotation=30)
    _draw_undriven(axes[0, : 1 + dated], track.events)
    if rows.empty and not (track.events.undriven_hz != "").any():  # nothing to draw: say so where the modes would be
        axes[0, 0].text(
            0.5, 0.5, "no event's modes to follow (see the notes)", ha="center", transform=axes[0, 0].transAxes
        )
    else:
        axes[0, 0].legend(fontsize=7, loc="best")
    fig.suptitle("modes across events (red rings: beyond the other events' trend)", fontsize=10)
    fig.tight_layout()
    return fig


def _draw_undriven(axes, events: pd.DataFrame) -> None:
    """Each event's named undriven resonances (no mode, no interval): hollow diamonds on the
    frequency panels, against the peak input and the date."""
    named = [(e.peak_input, e.date, float(hz)) for e in events.itertuples() for hz in e.undriven_hz.split()]
    for ax, at in zip(axes, (0, 1), strict=False):
        x = [item[at] for item in named if pd.notna(item[at])]
        y = [item[2] for item in named if pd.notna(item[at])]
        label = "resonance the input does not drive (no mode)" if x else None
        ax.scatter(x, y, marker="D", s=30, facecolors="none", edgecolors="k", label=label)


def _draw_trend(ax, track: Track, mode: int, group: pd.DataFrame, colour) -> None:
    trend = track.trends.set_index("mode").loc[mode]
    kept = group[~group.flagged]
    if not np.isfinite(trend.slope_hz_per_decade):
        return
    span = np.linspace(np.log10(kept.peak_input.min()), np.log10(kept.peak_input.max()), 20)
    ax.plot(10**span, trend.intercept_hz + trend.slope_hz_per_decade * span, color=colour, lw=1, alpha=0.7)


def render_track_report(track: Track, figure) -> str:
    """The HTML text of the track report.

    Parameters
    ----------
    track : Track
    figure : matplotlib.figure.Figure
        :func:`plot_track`'s figure.

    Returns
    -------
    str
    """
    esc = html.escape
    settings = pd.DataFrame([{"setting": k, "value": str(v)} for k, v in track.to_dict()["settings"].items()])
    notes = "".join(f"<li class=note>{esc(n)}</li>" for n in track.notes)
    flagged = track.table[track.table.flagged]
    fails = "".join(
        f"<li class=fail><b>{esc(f['file'])}</b>: {esc(str(f['reason']))}</li>" for f in track.study.failures
    )
    shown = track.table.drop(columns=["mac"]).assign(date=track.table.date.astype(str).replace("NaT", ""))
    body = f"""
<h1>armaxmodal track</h1>
<p>{len(track.events)} events, {track.table["mode"].nunique()} modes followed, {len(flagged)} departures
from the other events' trend flagged.</p>
<img alt='modes against peak input and date' src='{figure_uri(figure)}'>
<h2>Each mode's trend</h2>
<p>Frequency against log10 of the peak input, over the events not flagged: slope in Hz per tenfold
input, tau the scatter between events beyond their own intervals.</p>{table(track.trends, 4)}
{"<h2>Notes</h2><ul>" + notes + "</ul>" if notes else ""}
<h2>Events</h2>{table(track.events.assign(date=track.events.date.astype(str).replace("NaT", "")), 4)}
<h2>Every event's modes</h2><div class=wide>{table(shown, 4)}</div>
<h2>Failures</h2>{"<ul>" + fails + "</ul>" if fails else "<p>none</p>"}
<h2>Settings</h2>{table(settings)}
"""
    return page("armaxmodal track", body)


def write_track(track: Track, out: str | Path) -> list[Path]:
    """Write ``track.csv`` (every event's modes), ``trends.csv``, ``events.csv``, ``track.json``,
    ``track.png`` and ``track.html``: staged, then moved in together.

    Parameters
    ----------
    track : Track
    out : str or Path
        The folder (created).

    Returns
    -------
    list of Path
        The files written.

    See Also
    --------
    armaxmodal.study.track_modes : Follow the modes.
    armaxmodal.study.write_study : A study's files, as these are a track's.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> import armaxmodal as am
    >>> from armaxmodal.study import StudySettings, track_modes, write_track
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     for k, rms in enumerate((0.5, 2.0)):
    ...         base = am.random_vibration(60.0, 30.0, rms=rms, seed=k)
    ...         ride = am.simulate_recording(am.supine_human(), base, 60.0, noise=0.03, seed=k)
    ...         _ = am.write_recording_csv(ride, pathlib.Path(folder) / f"event{k}.csv")
    ...     followed = track_modes(folder, pathlib.Path(folder) / "out", StudySettings(orders=(2, 12)), jobs=1)
    ...     written = write_track(followed, pathlib.Path(folder) / "out")
    >>> sorted(path.name for path in written)
    ['events.csv', 'track.csv', 'track.html', 'track.json', 'track.png', 'trends.csv']
    """
    import matplotlib.pyplot as plt

    out = Path(out)
    data = json.dumps(track.to_dict(), indent=1, allow_nan=False) + "\n"
    fig = plot_track(track)
    try:
        text = render_track_report(track, fig)
        return write_all(
            [
                (out / "track.csv", lambda tmp: track.table.to_csv(tmp, index=False)),
                (out / "trends.csv", lambda tmp: track.trends.to_csv(tmp, index=False)),
                (out / "events.csv", lambda tmp: track.events.to_csv(tmp, index=False)),
                (out / "track.json", lambda tmp: Path(tmp).write_text(data, encoding="utf-8")),
                (out / "track.png", lambda tmp: fig.savefig(tmp, dpi=110, format="png")),
                (out / "track.html", lambda tmp: Path(tmp).write_text(text, encoding="utf-8")),
            ]
        )
    finally:
        plt.close(fig)
