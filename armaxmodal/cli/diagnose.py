"""``armaxmodal diagnose``: find the effect the model lacks, add it, refit, report before and after."""

from __future__ import annotations

import textwrap
from pathlib import Path

from armaxmodal.cli.common import (
    NONNEG_INT,
    add_data_args,
    check_report_path,
    load_recording,
    model_orders,
    output_format,
    parse_pair,
    print_notes,
    write_outputs,
)
from armaxmodal.diagnosis.report import short_parameters
from armaxmodal.exceptions import DataError
from armaxmodal.io.write import write_json


def add_parser(sub, parents) -> None:
    """Register the ``diagnose`` command."""
    p = sub.add_parser(
        "diagnose", parents=parents, help="find the effect the model lacks, add it, refit, report before/after"
    )
    add_data_args(p)
    p.add_argument("--band", default=None, help="frequency band LO:HI in Hz (sets the analysis rate)")
    p.add_argument("--max-rounds", type=NONNEG_INT, default=3, help="effects added at most; default 3")
    p.add_argument(
        "--model",
        default="auto",
        help="the model to diagnose, na,nb,nc,nk (shared poles), or 'auto' (orders by BIC); default auto. "
        "An order too low tries the loop's missing mode: 6,12,6,-5 on the supine ride",
    )
    p.add_argument("--json", default=None, help="write the diagnosis as JSON")
    p.add_argument("--plot", default=None, help="figure page (.png/.svg/.pdf)")
    p.add_argument("--report", default=None, help="one self-contained HTML page of the diagnosis (.html)")
    p.set_defaults(func=run)


def run(args) -> int:
    from armaxmodal.diagnosis import diagnose
    from armaxmodal.prepare.preparation import check_band

    plot_format = output_format(args.plot) if args.plot else None
    band = check_band(parse_pair(args.band, "--band")) if args.band else None
    if args.report:
        check_report_path(args.report)
    orders = model_orders(args.model)
    if orders is not None and band is not None:
        raise DataError(
            "--model with --band: the model is fitted at the record's own rate, the band resamples it; "
            "give one of them."
        )
    rec = load_recording(args)
    baseline = None
    if orders is not None:
        from armaxmodal.estimate.fit import fit_armax

        baseline = fit_armax(rec, *orders, shared_poles=True, warn=False)
    result = diagnose(
        rec, band=band, max_rounds=args.max_rounds, baseline=baseline, progress=args.verbose and not args.quiet
    )
    print_notes(result.warnings, args.verbose)
    report = result.to_dict()
    print(_diagnosis_text(args.data, report))
    outputs = []
    if args.plot:
        from armaxmodal.diagnosis.plot import plot_diagnosis

        fig = plot_diagnosis(result)
        outputs.append((args.plot, lambda tmp: fig.savefig(tmp, dpi=120, format=plot_format)))
    if args.json:
        outputs.append((args.json, lambda tmp: write_json(report, tmp)))
    if args.report:
        from armaxmodal.diagnosis.report import render_diagnosis_report

        page = render_diagnosis_report(result, args.data)
        outputs.append((args.report, lambda tmp: Path(tmp).write_text(page, encoding="utf-8")))
    write_outputs(outputs)
    return 0


#: a line of the printed diagnosis at most (a terminal's width beside another window)
WIDTH = 100


def _diagnosis_text(name: str, report: dict) -> str:
    """The diagnosis as a person reads it, at most :data:`WIDTH` characters a line: the verdict
    first, each effect kept with the held-out error that judged it, the fits before and after,
    then each effect named and refused with why (the rounds are printed only with ``--verbose``)."""
    sensors = report["outputs"]
    base, final = report["baseline"], report["final"]
    orders = report["orders"]
    lines = _wrapped(
        f"{name}: {len(sensors)} sensors at {report['analysis_fs']:g} Hz; baseline ARMAX "
        f"({orders['na']}, {orders['nb']}, {orders['nc']}, {orders['nk']})"
    )
    lines += _wrapped("verdict: " + report["verdict"])
    for e in report["effects"]:
        judged = e["judged_by"]
        lines += _wrapped(
            f"kept {e['effect']} on {', '.join(e['channels'])}: held-out {judged['error']} error "
            f"{judged['before']:.4g} -> {judged['after']:.4g} ({e['evidence']['statistic']} p = "
            f"{e['evidence']['p']:.2g})"
        )
        params = {k: v for k, v in e["parameters"].items() if not isinstance(v, dict) and k not in _SHOWN}
        lines += _wrapped(short_parameters(params), first="  ")
        if e.get("note"):
            lines += _wrapped(f"note: {e['note']}", first="  ")
    if not report["effects"]:
        lines.append("no effect kept (the tests' p-values are in the JSON's 'tests').")
    lines.append(f"{'sensor':>12} {'fit before %':>13} {'fit after %':>12} {'resid RMS':>10} {'H1 floor':>12}")
    for k, s in enumerate(sensors):
        if s in final["inputs_added"]:
            lines.append(f"{s:>12} {_fit(base['fit_val_pct'][k]):>13}   now an input (a second excitation)")
            continue
        rms = "diverges" if final["sim_resid_rms"][k] is None else f"{final['sim_resid_rms'][k]:.4g}"
        lines.append(
            f"{s:>12} {_fit(base['fit_val_pct'][k]):>13} {_fit(final['fit_val_pct'][k]):>12} "
            f"{rms:>10} {_or_unresolved(final['noise_floor_rms'][k]):>12}"
        )
    for u in report["unconfirmed"]:
        lines += _wrapped(f"refused {u['effect']} on {', '.join(u['channels'])}: {u['reason']}")
    return "\n".join(lines)


#: parameters the effect's line already shows
_SHOWN = ("criterion", "sim_error_before", "sim_error_after")


def _wrapped(text: str, first: str = "") -> list[str]:
    """``text`` in lines of at most :data:`WIDTH` characters, the continuations indented."""
    return textwrap.wrap(text, WIDTH, initial_indent=first, subsequent_indent=first + "  ", break_on_hyphens=False)


def _fit(value) -> str:
    """A held-out simulation fit (%), or "diverges" where the simulation does (the verdict says why)."""
    return "diverges" if value is None else f"{value:.1f}"


def _or_unresolved(value) -> str:
    """A noise floor, or why there is none (the record cannot resolve its lightest mode)."""
    return "unresolved" if value is None else f"{value:.4g}"
