"""``track`` on the three bridges of ``../shared/realdata``: each event's modes and verdict, each
mode's trend with the shaking, and the Welch H1's peak as an independent check (issue 68).

Writes ``benchmarks/results/track/<bridge>/``: ``track.csv``, ``trends.csv``, ``events.csv`` (the
command's own tables) and ``h1.csv`` (per event the H1 peak base -> deck, its coherence, the
reported mode nearest it and whether it is within 3 %). The docs build draws the validation
page's bridge figures and tables from these files (:func:`write_page`, run by ``docs/conf.py``).

Run:  python scripts/track_bridges.py [--shared ../shared] [--jobs 2]
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import signal

from armaxmodal.io.read import read_recording
from armaxmodal.study import TrackSettings, track_modes
from armaxmodal.study.track import undriven_hz

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results" / "track"
G = 980.665  # cm/s² in one g: CSMIP's V2 blocks are in cm/s²
#: the H1 peak is sought over the bridges' first modes' band
H1_BAND = (1.0, 10.0)
#: nearer than this to the H1 peak, a reported mode is "at" it (the issue's measure)
NEAR = 0.03
#: events and their dates, from each folder's README
EVENTS = {
    "painter": [
        ("bridge_painter/painter_nc73666231.csv.gz", "2021-12-20"),
        ("bridge_painter/painter_nc73925281.csv.gz", "2023-08-17"),
        ("bridge_painter/painter_bayview_11oct2013.csv.gz", "2013-10-11"),
        ("bridge_painter/painter_ferndale_28jan2015.csv.gz", "2015-01-28"),
        ("bridge_painter/painter_nc73821036.csv.gz", "2022-12-20"),
    ],
    "meloland": [
        ("bridge_meloland/meloland_calexico_20nov2008.csv.gz", "2008-11-20"),
        ("bridge_meloland/meloland_superstitionhills87.csv.gz", "1987-11-24"),
        ("bridge_meloland/meloland_imperialvalley79.csv.gz", "1979-10-15"),
    ],
    "capistrano": [
        ("bridge_capistrano/capistrano_borregosprings.csv", "2010-07-07"),
        ("bridge_capistrano/capistrano_ocotillo.csv", "2010-06-14"),
        ("bridge_capistrano/capistrano_calexico.csv", "2010-04-04"),
        ("bridge_capistrano/capistrano_inglewood.csv", "2009-05-17"),
    ],
}


def h1_peaks(path: Path) -> list[tuple[str, float, float]]:
    """Per output channel the peak of the Welch H1 base -> channel over ``H1_BAND`` (1024-sample
    segments, or a quarter of a short record; the peak placed between lines by a parabola through
    the three lines about it) and the coherence at that line."""
    rec = read_recording(path, input="base")
    nperseg = min(1024, 2 ** int(np.log2(rec.n_samples / 4)))
    f, pxx = signal.welch(rec.base, rec.fs, nperseg=nperseg)
    inside = np.flatnonzero((f >= H1_BAND[0]) & (f <= H1_BAND[1]))
    peaks = []
    for k, channel in enumerate(rec.sensors):
        _, pxy = signal.csd(rec.base, rec.response[:, k], rec.fs, nperseg=nperseg)
        _, coh = signal.coherence(rec.base, rec.response[:, k], rec.fs, nperseg=nperseg)
        gain = np.abs(pxy / pxx)
        i = inside[np.argmax(gain[inside])]
        a, b, c = gain[i - 1 : i + 2]
        shift = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c < 0 else 0.0
        peaks.append((channel, float(f[i] + shift * (f[1] - f[0])), float(coh[i])))
    return peaks


def checked(track, real: Path, events: list[tuple[str, str]]) -> pd.DataFrame:
    """One row per event and output channel: the H1 peak, its coherence and the nearest mode."""
    rows = []
    for name, _ in events:
        file = str(real / name)
        event = track.events.set_index("file").loc[file]
        done = track.study.recordings[[r["file"] for r in track.study.recordings].index(file)]
        freqs = np.array([m["freq_hz"] for m in done["modes"]])
        named = np.array(undriven_hz(done))  # named in a note: the frequency said, no mode reported
        for channel, peak, coherence in h1_peaks(real / name):
            nearest = float(freqs[np.argmin(np.abs(np.log(freqs / peak)))]) if freqs.size else np.nan
            rows.append(
                {
                    "event": Path(name).name.split(".")[0],
                    "date": event.date.date().isoformat(),
                    "peak_input_g": event.peak_input,
                    "quality": event.quality,
                    "modes_hz": " ".join(f"{f:.2f}" for f in np.sort(freqs)),
                    "channel": channel,
                    "h1_peak_hz": peak,
                    "h1_coherence": coherence,
                    "nearest_mode_hz": nearest,
                    "within_3pct": bool(abs(nearest / peak - 1) <= NEAR) if freqs.size else False,
                    "named_hz": " ".join(f"{f:.2f}" for f in named),
                    "named_within_3pct": bool(np.any(np.abs(named / peak - 1) <= NEAR)),
                }
            )
    return pd.DataFrame(rows)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shared", default=str(ROOT.parent / "shared"))
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args()
    real = Path(args.shared) / "realdata"
    settings = TrackSettings(input_scale=1 / G, input_unit="g")
    for bridge, events in EVENTS.items():
        out = RESULTS / bridge
        out.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory() as tmp:
            manifest = Path(tmp) / "manifest.csv"
            pd.DataFrame([{"file": str(real / f), "date": d} for f, d in events]).to_csv(manifest, index=False)
            track = track_modes(manifest, Path(tmp) / "cache", track=settings, jobs=args.jobs, progress=True)
        short = {str(real / f): Path(f).name.split(".")[0] for f, _ in events}
        h1 = checked(track, real, events)
        for frame, name in ((track.table, "track.csv"), (track.events, "events.csv")):
            frame.assign(file=frame.file.map(short)).to_csv(out / name, index=False)
        track.trends.to_csv(out / "trends.csv", index=False)
        h1.to_csv(out / "h1.csv", index=False)
        print(bridge)
        print(h1.drop(columns=["date"]).to_string(index=False, float_format=lambda v: f"{v:.3f}"))
        coherent = h1[h1.h1_coherence >= 0.9]
        named = int((coherent.named_within_3pct & ~coherent.within_3pct).sum())
        print(
            f"coherent H1 peaks (>= 0.9) with a mode within 3 %: {int(coherent.within_3pct.sum())} of {len(coherent)}; "
            f"with a resonance named within 3 % instead: {named}"
        )
        print(track.trends.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    print(write_page())


# ---- the validation page, written from the saved results (the docs build runs this) ----

DOCS = ROOT / "docs" / "validation"
TITLES = {
    "painter": "Painter Street Overpass (CSMIP 89324)",
    "meloland": "Meloland Road Overpass (CSMIP 01336)",
    "capistrano": "Capistrano Beach I5/Via California bridge (CSMIP 13795)",
}


def _saved_track(bridge: str):
    """The :class:`~armaxmodal.study.Track` of a bridge as its saved tables hold it (no study)."""
    from armaxmodal.study import Track

    folder = RESULTS / bridge
    table = pd.read_csv(folder / "track.csv", parse_dates=["date"])
    events = pd.read_csv(folder / "events.csv", parse_dates=["date"], dtype={"undriven_hz": str}).fillna(
        {"undriven_hz": ""}
    )
    trends = pd.read_csv(folder / "trends.csv")
    return Track(table, trends, events, TrackSettings(input_scale=1 / G, input_unit="g"), study=None)


def _bridge_section(bridge: str) -> list[str]:
    import matplotlib.pyplot as plt

    from armaxmodal.study import plot_track

    # one mode a row: read as text, not a number
    h1 = pd.read_csv(RESULTS / bridge / "h1.csv", dtype={"modes_hz": str, "named_hz": str}).fillna({"named_hz": ""})
    track = _saved_track(bridge)
    fig = plot_track(track)
    (DOCS / "images").mkdir(exist_ok=True)
    fig.savefig(DOCS / "images" / f"track_{bridge}.png", dpi=90)
    plt.close(fig)
    coherent = h1[h1.h1_coherence >= 0.9]
    lines = [
        f"## {TITLES[bridge]}",
        "",
        "| event | date | peak input (g) | verdict | modes (Hz) | H1 peak per channel (Hz, coherence) |",
        "|---|---|---|---|---|---|",
    ]
    for event, group in h1.groupby("event", sort=False):
        first = group.iloc[0]
        peaks = "; ".join(
            f"{r.channel} {r.h1_peak_hz:.2f} ({r.h1_coherence:.2f})"
            f"{' ✓' if r.within_3pct else ' (named)' if r.named_within_3pct else ''}"
            for r in group.itertuples()
        )
        lines.append(
            f"| {event} | {first.date} | {first.peak_input_g:.3f} | {first.quality} | "
            f"{first.modes_hz if isinstance(first.modes_hz, str) else '—'}"
            f"{f'; undriven resonance named at {first.named_hz}' if first.named_hz else ''} | {peaks} |"
        )
    lines += [
        "",
        f"A ✓ marks an H1 peak with a reported mode within 3 %; (named), one with no such mode but an "
        "`undriven_resonance` note naming a frequency within 3 % (a column of the diagram's poles with negative "
        "damping there: the input does not drive that resonance as it drives a mode of a structure on one moving "
        f"base). Of the {len(coherent)} peaks whose coherence is at least 0.9, {int(coherent.within_3pct.sum())} have "
        f"a mode and {int((coherent.named_within_3pct & ~coherent.within_3pct).sum())} more a named resonance.",
        "",
    ]
    lines += [f"![modes of the {TITLES[bridge]} against the peak input and the date](images/track_{bridge}.png)", ""]
    lines += [
        "| mode | events | median (Hz) | slope (Hz per tenfold input) | scatter between events (Hz) | flagged |",
        "|---|---|---|---|---|---|",
    ]
    for t in track.trends.itertuples():
        flagged = track.table[(track.table["mode"] == t.mode) & track.table.flagged].file.tolist()
        slope = "—" if pd.isna(t.slope_hz_per_decade) else f"{t.slope_hz_per_decade:+.3f} ± {t.slope_sd:.3f}"
        tau = "—" if pd.isna(t.tau_hz) else f"{t.tau_hz:.3f}"
        lines.append(
            f"| {t.mode} | {t.events} | {t.median_hz:.3f} | {slope} | {tau} | {', '.join(flagged) or 'none'} |"
        )
    return [*lines, ""]


def write_page() -> Path:
    """``docs/validation/bridges.md`` and its figures from ``benchmarks/results/track/``."""
    lines = [
        "<!-- written by scripts/track_bridges.py from benchmarks/results/track/; do not edit -->",
        "",
        "# Bridges under earthquakes",
        "",
        "Three overpasses of the California strong-motion network, twelve earthquakes between them",
        "(CSMIP's corrected records, in the project's shared data folder). Each bridge's events go through",
        "one `track` run, as a structural engineer would run it:",
        "",
        "```bash",
        "armaxmodal track manifest.csv --out painter --input-scale 0.0010197 --input-unit g",
        "```",
        "",
        "The manifest lists each record with its date; the input is the ground or column-base channel,",
        "the outputs the deck's transverse channels. Each event's modes and verdict are checked against",
        "the Welch H1 from input to each output (1024-sample segments, or a quarter of a short record):",
        "a bridge shaken at several supports is not a single-input system, so the H1 peaks are a check,",
        "not a truth. The figures and tables below are drawn from `benchmarks/results/track/`, written by",
        "`python scripts/track_bridges.py`.",
        "",
    ]
    for bridge in EVENTS:
        if (RESULTS / bridge / "h1.csv").is_file():
            lines += _bridge_section(bridge)
    page = DOCS / "bridges.md"
    text = "\n".join(lines)
    if not page.is_file() or page.read_text() != text:
        page.write_text(text)
    return page


if __name__ == "__main__":
    main()
