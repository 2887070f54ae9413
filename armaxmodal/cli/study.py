"""``armaxmodal study``: the command-line face of :mod:`armaxmodal.study`."""

from __future__ import annotations

import sys
from pathlib import Path

from armaxmodal.cli.common import DETREND_HELP, POSITIVE_INT, order_range, parse_pair
from armaxmodal.exceptions import DataError

__all__ = ["add_parser", "run"]


def add_parser(sub, parents) -> None:
    """Register the ``study`` command."""
    p = sub.add_parser(
        "study", parents=parents, help="many subjects and rides: tables, shapes, report (local or dask cluster)"
    )
    p.add_argument("source", help="manifest CSV (file, subject, ride, mass_kg, ...) or a folder of recordings")
    p.add_argument("--out", required=True, help="study folder for the tables, figures, study.json and the cache")
    p.add_argument("--report", default=None, help="HTML report path (default OUT/report.html)")
    p.add_argument("--jobs", type=POSITIVE_INT, default=None, help="local worker processes (default: all cores)")
    p.add_argument("--scheduler", default=None, help="dask.distributed scheduler address, e.g. tcp://host:8786")
    p.add_argument("--input", default="base", help="base-acceleration channel; default 'base'")
    p.add_argument("--orders", default=None, help="range of na, LO:HI; default 2:30, capped to suit each record")
    p.add_argument("--modes", type=POSITIVE_INT, default=None, help="modes per recording (default: automatic)")
    p.add_argument("--band", default=None, help="frequency band LO:HI in Hz")
    p.add_argument("--detrend", choices=["mean", "linear", "none"], default="mean", help=DETREND_HELP)
    p.add_argument("--sensors", default=None, help="comma-separated sensors to analyse (default: those most share)")
    p.add_argument("--lump", default=None, help="A,B: test whether segments A and B can be lumped (e.g. legs,feet)")
    p.add_argument("--model", action="store_true", help="fit the average subject's chain and scale it to each subject")
    p.set_defaults(func=run)


def study_settings(args):
    """The StudySettings the command line asks for (also ``track``'s)."""
    from armaxmodal.prepare.preparation import check_band
    from armaxmodal.study.job import StudySettings

    orders = None
    if args.orders is not None:
        na = order_range(args.orders)  # the same LO:HI rule as stabilise's
        orders = (na.start, na.stop - 1)
    band = check_band(parse_pair(args.band, "--band")) if args.band else None
    lump = None
    if args.lump:
        lump = tuple(s.strip() for s in args.lump.split(","))
        if len(lump) != 2 or not all(lump) or lump[0] == lump[1]:
            raise DataError(f"--lump: expected two different sensor names A,B such as legs,feet; got {args.lump!r}.")
    sensors = tuple(s.strip() for s in args.sensors.split(",") if s.strip()) if args.sensors else None
    return StudySettings(args.input, orders, args.modes, band, args.detrend, sensors, lump)


def _check_paths(args) -> None:
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise DataError(f"--out {args.out}: is a file; give a folder (it is created if missing).")
    source = Path(args.source).resolve()
    # the study's own files must not land on the manifest, nor among the recordings of a
    # folder study (the next run would read summary.csv as a recording)
    written = {
        "summary.csv",
        "modes.csv",
        "per_sensor.csv",
        "subjects.csv",
        "shapes.csv",
        "lump.csv",
        "model_scaled.csv",
        "study.json",
        "report.html",
    }
    if out.resolve() == source or (source.is_file() and out.resolve() == source.parent and source.name in written):
        raise DataError(f"--out {args.out}: would write into the study's input; choose another folder.")
    if args.report:
        report = Path(args.report)
        if report.is_dir():
            raise DataError(f"--report {args.report}: is a directory; give a file name such as study.html.")
        if report.resolve() == source:
            raise DataError(f"--report {args.report}: is the manifest; writing there would destroy it.")


def run(args) -> int:
    from armaxmodal.study.output import write_study
    from armaxmodal.study.run import run_study

    settings = study_settings(args)
    _check_paths(args)
    study = run_study(
        args.source,
        args.out,
        settings,
        jobs=args.jobs,
        scheduler=args.scheduler,
        progress=not args.quiet,
        model=args.model,
    )
    written = write_study(study, args.out, args.report)
    if not args.quiet:
        print(f"{len(study.recordings)} recordings analysed ({study.reused} reused), {len(study.failures)} left out")
        cols = ["ride", "mode", "freq_hz_mean", "freq_hz_sd", "damping_mean", "damping_sd", "n"]
        print(study.tables.summary[cols].to_string(index=False, float_format=lambda v: f"{v:.4f}"))
        print("wrote " + ", ".join(str(p) for p in written))
    for f in study.failures:
        print(f"left out {f['file']}: {f['reason']}", file=sys.stderr)
    for n in study.notes:
        print(f"note: {n}", file=sys.stderr)
    return 0
