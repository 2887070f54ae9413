"""``armaxmodal identify``: one shared-pole ARMAX model and its modes."""

from __future__ import annotations

import numpy as np

from armaxmodal.cli.common import DETREND_HELP, add_data_args, load_recording, model_orders, parse_pair, print_notes
from armaxmodal.cli.stabilise import print_check
from armaxmodal.io.write import write_all, write_json
from armaxmodal.modes.result import verdict


def add_parser(sub, parents) -> None:
    """Register the ``identify`` command."""
    p = sub.add_parser("identify", parents=parents, help="fit a shared-pole ARMAX model and print the modes")
    add_data_args(p)
    p.add_argument(
        "--model", default="auto", help="the model's orders, na,nb,nc,nk, or 'auto' (chosen by BIC); default auto"
    )
    p.add_argument("--band", default=None, help="frequency band LO:HI in Hz")
    p.add_argument("--detrend", choices=["mean", "linear", "none"], default="mean", help=DETREND_HELP)
    p.add_argument("--json", default=None, help="write modes as JSON")
    p.add_argument("--csv", default=None, help="write every pole of every sensor as CSV")
    p.set_defaults(func=run)


def run(args) -> int:
    from armaxmodal.identification import identify

    rec = load_recording(args)
    orders = model_orders(args.model)
    band = parse_pair(args.band, "--band") if args.band else None
    result = identify(rec, orders, band=band, progress=not args.quiet, detrend=args.detrend)
    print_notes(result.warnings, args.verbose)
    na, nb, nc, nk = result.fit.orders
    print(
        f"{args.data}: shared-pole ARMAX na={na} nb={nb} nc={nc} nk={nk}, "
        f"converged={bool(result.fit.converged.all())}, fit {np.round(result.fit.fit_percent, 1).tolist()} %"
    )
    table = result.modes[
        ["freq_hz", "damping", "damped_freq_hz", "freq_ci95_lo", "freq_ci95_hi", "damping_ci95_lo", "damping_ci95_hi"]
    ]
    print(table.to_string(float_format=lambda v: f"{v:.4f}"))
    print_check(result.check)
    outputs = []
    if args.json:
        outputs.append((args.json, lambda tmp: write_json(result.to_dict(), tmp)))
    if args.csv:
        poles = result.fit.modes().drop(columns=["pole", "residue"])
        outputs.append((args.csv, lambda tmp: poles.to_csv(tmp, index=False)))
    write_all(outputs)
    print(verdict(result.check, len(result.modes)))
    return 0
