"""``armaxmodal track``: the command-line face of :func:`armaxmodal.study.track_modes`."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from armaxmodal.cli.common import DETREND_HELP, POSITIVE, POSITIVE_INT, _number
from armaxmodal.exceptions import DataError

__all__ = ["add_parser", "run"]

FRACTION = _number(float, 0.0, False, "a number in [0, 1)")


def add_parser(sub, parents) -> None:
    """Register the ``track`` command."""
    p = sub.add_parser(
        "track",
        parents=parents,
        help="many events of one structure: each mode followed across them, its trend with the shaking, outliers",
    )
    p.add_argument("source", help="manifest CSV (file, date, ...) or a folder of one structure's records")
    p.add_argument("--out", required=True, help="folder for track.csv, trends.csv, track.png, track.html and the cache")
    p.add_argument("--jobs", type=POSITIVE_INT, default=None, help="local worker processes (default: all cores)")
    p.add_argument("--scheduler", default=None, help="dask.distributed scheduler address, e.g. tcp://host:8786")
    p.add_argument("--input", default="base", help="base-acceleration channel; default 'base'")
    p.add_argument("--orders", default=None, help="range of na, LO:HI; default 2:30, capped to suit each record")
    p.add_argument("--band", default=None, help="frequency band LO:HI in Hz")
    p.add_argument("--detrend", choices=["mean", "linear", "none"], default="mean", help=DETREND_HELP)
    p.add_argument("--sensors", default=None, help="comma-separated sensors to analyse (default: those most share)")
    p.add_argument(
        "--freq-ratio",
        type=POSITIVE,
        default=1.35,
        help="largest frequency ratio between a mode and the track it joins; default 1.35",
    )
    p.add_argument(
        "--min-mac",
        type=FRACTION,
        default=0.0,
        help="least MAC to join a track; default 0 (the shape only breaks ties)",
    )
    p.add_argument("--level", type=POSITIVE, default=0.99, help="level of the departure test; default 0.99")
    p.add_argument(
        "--input-scale",
        type=POSITIVE,
        default=1.0,
        help="factor from the input's units to --input-unit (0.0010197 for cm/s2 to g)",
    )
    p.add_argument("--input-unit", default="as recorded", help="the unit of the peak input in the outputs")
    p.set_defaults(func=run, modes=None, lump=None)


def _track_settings(args):
    from armaxmodal.study.track import TrackSettings

    return TrackSettings(
        args.freq_ratio, args.min_mac, args.level, input_scale=args.input_scale, input_unit=args.input_unit
    )


def _check_out(args) -> None:
    out, source = Path(args.out).resolve(), Path(args.source).resolve()
    if out.exists() and not out.is_dir():
        raise DataError(f"--out {args.out}: is a file; give a folder (it is created if missing).")
    if out == source or (source.is_file() and out == source.parent):
        raise DataError(f"--out {args.out}: would write among the records it reads; choose another folder.")


def run(args: argparse.Namespace) -> int:
    from armaxmodal.cli.study import study_settings
    from armaxmodal.study.track import track_modes
    from armaxmodal.study.track_output import write_track

    track_settings = _track_settings(args)
    settings = study_settings(args)
    _check_out(args)
    track = track_modes(
        args.source,
        args.out,
        settings,
        track_settings,
        jobs=args.jobs,
        scheduler=args.scheduler,
        progress=not args.quiet,
    )
    written = write_track(track, args.out)
    print(
        f"{len(track.events)} events, {track.table['mode'].nunique()} modes followed, "
        f"{int(track.table.flagged.sum())} departures flagged"
    )
    cols = ["mode", "events", "median_hz", "slope_hz_per_decade", "slope_sd", "tau_hz"]
    print(track.trends[cols].to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    for note in track.notes:
        print(f"note: {note}")
    for failure in track.study.failures:
        print(f"left out {failure['file']}: {failure['reason']}", file=sys.stderr)
    print("wrote " + ", ".join(str(p) for p in written))
    return 0
