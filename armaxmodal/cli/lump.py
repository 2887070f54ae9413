"""``armaxmodal lump DATA A B``: can two segments be modelled as one? (thesis Chapter 5)"""

from __future__ import annotations

from armaxmodal.cli.common import POSITIVE, output_format, parse_pair, write_outputs

__all__ = ["add_parser", "run"]


def add_parser(sub, parents) -> None:
    """Register the ``lump`` command."""
    p = sub.add_parser("lump", parents=parents, help="can two segments (e.g. legs, feet) be modelled as one mass?")
    p.add_argument("data", help="recording: .csv[.gz], .mat or .uff")
    p.add_argument("a", help="first segment, e.g. legs")
    p.add_argument("b", help="second segment, e.g. feet (T = B / A, both relative to the base)")
    p.add_argument("--input", default="base", help="input (base acceleration) column; default 'base'")
    p.add_argument("--fs", type=POSITIVE, default=None, help="sampling rate in Hz if the file has no time column")
    p.add_argument("--band", default=None, help="frequency band LO:HI in Hz (default: the excited band)")
    p.add_argument("--json", default=None, help="verdict and evidence as JSON")
    p.add_argument("--plot", default=None, help="transmissibility, scalograms and wavelet coherence (.png/.svg/.pdf)")
    p.set_defaults(func=run)


def run(args) -> int:
    from armaxmodal.exceptions import DataError
    from armaxmodal.io.read import read_recording
    from armaxmodal.io.write import write_json
    from armaxmodal.lumping.check import lump_check
    from armaxmodal.prepare.preparation import check_band

    if args.a == args.b:
        raise DataError(f"a segment cannot be lumped with itself ({args.a!r}); name two different sensors.")
    plot_format = output_format(args.plot) if args.plot else None
    band = check_band(parse_pair(args.band, "--band")) if args.band else None
    rec = read_recording(args.data, input=args.input, fs=args.fs)
    check_band(band, rec.fs)
    check = lump_check(rec, args.a, args.b, band, wavelet=True)
    print(check.message)
    outputs = []
    if args.plot:
        from armaxmodal.lumping.plot import plot_lump

        fig = plot_lump(check)
        outputs.append((args.plot, lambda tmp: fig.savefig(tmp, dpi=110, format=plot_format)))
    if args.json:
        report = check.to_dict()
        outputs.append((args.json, lambda tmp: write_json(report, tmp)))
    write_outputs(outputs)
    return 0
