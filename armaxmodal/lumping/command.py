"""``armaxmodal lump DATA A B``: can two segments be modelled as one? (thesis Chapter 5)"""

from __future__ import annotations

__all__ = ["add_parser"]


def add_parser(sub, parents, fs_type) -> None:
    """Register the ``lump`` command (``fs_type``: the CLI's validated positive number)."""
    p = sub.add_parser("lump", parents=parents, help="can two segments (e.g. legs, feet) be modelled as one mass?")
    p.add_argument("data", help="recording: .csv[.gz], .mat or .uff")
    p.add_argument("a", help="first segment, e.g. legs")
    p.add_argument("b", help="second segment, e.g. feet (T = B / A, both relative to the base)")
    p.add_argument("--input", default="base", help="input (base acceleration) column; default 'base'")
    p.add_argument("--fs", type=fs_type, default=None, help="sampling rate in Hz if the file has no time column")
    p.add_argument("--band", default=None, help="frequency band LO:HI in Hz (default: the excited band)")
    p.add_argument("--json", default=None, help="verdict and evidence as JSON")
    p.add_argument("--plot", default=None, help="transmissibility, scalograms and wavelet coherence (.png/.svg/.pdf)")
    p.set_defaults(func=_cmd_lump)


def _cmd_lump(args) -> int:
    from ..cli import _format, _parse_pair, _write_outputs
    from ..exceptions import DataError
    from ..io import read_recording, write_json
    from ..prepare import check_band
    from .check import lump_check

    if args.a == args.b:
        raise DataError(f"a segment cannot be lumped with itself ({args.a!r}); name two different sensors.")
    plot_format = _format(args.plot) if args.plot else None
    band = check_band(_parse_pair(args.band, "--band")) if args.band else None
    rec = read_recording(args.data, input=args.input, fs=args.fs)
    check_band(band, rec.fs)
    check = lump_check(rec, args.a, args.b, band, wavelet=True)
    print(check.message)
    outputs = []
    if args.plot:
        from .plot import plot_lump

        fig = plot_lump(check)
        outputs.append((args.plot, lambda tmp: fig.savefig(tmp, dpi=110, format=plot_format)))
    if args.json:
        report = check.to_dict()
        outputs.append((args.json, lambda tmp: write_json(report, tmp)))
    _write_outputs(outputs)
    return 0
