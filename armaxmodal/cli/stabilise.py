"""``armaxmodal stabilise``: order sweep, stabilisation plot and automatic mode selection."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from armaxmodal.cli.common import (
    DETREND_HELP,
    POSITIVE_INT,
    add_data_args,
    check_report_path,
    load_recording,
    order_range,
    output_format,
    parse_pair,
    print_notes,
    write_outputs,
)
from armaxmodal.exceptions import DataError, OrderError, PickError
from armaxmodal.io.write import write_json


def add_parser(sub, parents) -> None:
    """Register the ``stabilise`` command."""
    p = sub.add_parser(
        "stabilise", parents=parents, help="order sweep, stabilisation plot and automatic mode selection"
    )
    add_data_args(p)
    p.add_argument(
        "--orders", default=None, help="range of na, LO:HI (even steps); default 2:30, capped to suit the record"
    )
    p.add_argument("--modes", type=POSITIVE_INT, default=None, help="number of modes to keep (default: automatic)")
    p.add_argument(
        "--pick",
        default=None,
        help="modes picked by hand, F1,F2,... in Hz: each takes the nearest stable column "
        "of the diagram (within 5 %%); not with --modes",
    )
    p.add_argument("--band", default=None, help="frequency band LO:HI in Hz")
    p.add_argument("--plot", default=None, help="stabilisation plot (.png, .svg or .pdf)")
    p.add_argument("--json", default=None, help="selected modes as JSON")
    p.add_argument("--csv", default=None, help="every pole of the sweep as CSV")
    p.add_argument("--report", default=None, help="one self-contained HTML page of the run (.html)")
    p.add_argument("--uff", default=None, help="the modes as UFF 55 and the measured and modal-model FRFs as UFF 58")
    p.add_argument("--shapes-plot", default=None, help="the selected modes' shapes over the sensors (.png, .svg, .pdf)")
    p.add_argument(
        "--positions",
        default=None,
        help="each sensor's place along the chain, NAME=VALUE,... (a height, a storey): "
        "the shapes figure then draws the deflected chain",
    )
    p.add_argument(
        "--detrend",
        choices=["mean", "linear", "none"],
        default="mean",
        help=DETREND_HELP,
    )
    p.add_argument(
        "--shapes",
        choices=["shared", "per-sensor"],
        default="shared",
        help="mode shapes from the shared-pole fit, or per sensor with gaps filled by Eq. 3.34",
    )
    p.set_defaults(func=run)


def run(args) -> int:
    from armaxmodal.modes.clusters import check_picks
    from armaxmodal.modes.diagram import stabilisation_diagram
    from armaxmodal.modes.pipeline import select_modes
    from armaxmodal.prepare.preparation import check_band

    plot_format = output_format(args.plot) if args.plot else None
    shapes_format = output_format(args.shapes_plot, "--shapes-plot") if args.shapes_plot else None
    orders = None if args.orders is None else order_range(args.orders)
    band = check_band(parse_pair(args.band, "--band")) if args.band else None
    picks = _picks(args.pick, args.modes)
    positions = _positions(args.positions, args.shapes_plot)
    if args.report:
        check_report_path(args.report)
    rec = load_recording(args)
    check_band(band, rec.fs)
    if picks is not None:  # refused before the sweep, not after it
        check_picks(picks, band, rec.fs)
    if positions is not None:
        from armaxmodal.io.report.shape_plot import check_positions

        check_positions(positions, list(rec.sensors))
    outputs = ", ".join(rec.sensors)  # what was read, the modes and the check print under --quiet too: it
    read = f"{rec.n_samples} samples at {rec.fs:g} Hz"  # turns the progress off, not the result
    print(_fill(f"{args.data}: input {rec.input_name}; outputs {outputs}; {read}"))
    diagram = stabilisation_diagram(rec, orders, band=band, detrend=args.detrend, progress=not args.quiet)
    try:
        selection = select_modes(diagram, args.modes, band, progress=not args.quiet, picks=picks)
    except OrderError:
        # no mode: the diagram and the pole table still show the user why
        print_notes(diagram.warnings, args.verbose)
        write_outputs(_diagram_outputs(args, diagram, None, plot_format))
        raise
    prep = diagram.preparation
    if prep is not None and prep.analysis_fs != prep.original_fs:
        print(f"analysis at {prep.analysis_fs:g} Hz (resampled from {prep.original_fs:g} Hz)")
    print_modes(selection.modes, selection.picks is not None)
    if selection.check is not None:
        print_check(selection.check)
    outputs = _diagram_outputs(args, diagram, selection, plot_format)
    if args.shapes_plot:
        from armaxmodal.io.report.shape_plot import plot_shapes

        shapes_fig = plot_shapes(selection, positions=positions)
        outputs.append((args.shapes_plot, lambda tmp: shapes_fig.savefig(tmp, dpi=150, format=shapes_format)))
    if args.uff:
        outputs.append((args.uff, _uff_writer(selection)))
    if args.report:
        from armaxmodal.io.report.selection_report import render_selection_report

        used = {"band (Hz)": args.band, "detrend": args.detrend}
        page = render_selection_report(selection, selection.verdict, args.data, used, _provenance(args))
        outputs.append((args.report, lambda tmp: Path(tmp).write_text(page, encoding="utf-8")))
    if args.json:
        report = selection.to_dict(args.shapes.replace("-", "_"))
        outputs.append((args.json, lambda tmp: write_json(report, tmp)))
    write_outputs(outputs)
    print(_fill(selection.verdict), flush=True)
    print_notes(selection.warnings, args.verbose)  # after the verdict: what it rests on, one line per code
    return 0


def _uff_writer(selection):
    """``write(tmp)`` of the modes (UFF 55) and, per sensor, the measured H1 and the modal model's
    FRF on the check's lines inside its band (UFF 58)."""
    from armaxmodal.io.uff_modes import write_modes_uff
    from armaxmodal.spectra import excited_band, measured_frf

    rec, check, modes = selection.diagram.recording, selection.check, selection.modes
    frfs = []
    if check is not None:
        f, h, _ = measured_frf(rec, check.nperseg)
        lo, hi = selection.refinement.band_hz if selection.refinement is not None else excited_band(rec)
        keep = (f >= lo) & (f <= hi)
        model = check.frf(f[keep])
        for k in range(len(rec.sensors)):
            frfs += [("measured H1", k, f[keep], h[keep, k]), ("modal model", k, f[keep], model[:, k])]
    shapes, sensors = selection.shapes, list(rec.sensors)
    return lambda tmp: write_modes_uff(tmp, modes.freq_hz, modes.damping, shapes, sensors, frfs)


def _positions(text: str | None, shapes_plot: str | None) -> dict | None:
    """``--positions head=1.7,chest=1.3,...`` as ``{sensor: position}``; only with --shapes-plot."""
    if text is None:
        return None
    if shapes_plot is None:
        raise DataError("--positions places the sensors in the shapes figure: give --shapes-plot FILE as well.")
    try:
        pairs = [item.split("=") for item in text.split(",") if item.strip()]
        return {name.strip(): float(value) for name, value in pairs}
    except ValueError as exc:
        raise DataError(f"--positions: expected NAME=VALUE pairs such as head=1.7,chest=1.3; got {text!r}.") from exc


def _picks(text: str | None, n_modes: int | None) -> list[float] | None:
    """``--pick F1,F2,...`` as frequencies (Hz); refused with ``--modes`` or when not numbers."""
    if text is None:
        return None
    if n_modes is not None:
        raise PickError("--pick and --modes do not mix: pick the modes, or give their number, not both.")
    try:
        return [float(v) for v in text.split(",") if v.strip()]
    except ValueError as exc:
        raise PickError(
            f"--pick: expected frequencies in Hz separated by commas, such as 5.8,8.3,13.5; got {text!r}."
        ) from exc


def _fill(text: str) -> str:
    """``text`` wrapped to the notes' width, continuation lines indented."""
    import textwrap

    from armaxmodal.cli.common import NOTE_WIDTH

    return textwrap.fill(text, NOTE_WIDTH, subsequent_indent="  ", break_on_hyphens=False)


def print_modes(modes, picked: bool = False) -> None:
    """The modes as a person reads them, within the notes' width: frequency and damping, each
    with its 95 % interval, the orders that support it, and the pick it answers where the modes were
    ``picked`` by hand (the JSON and ``--csv`` hold every column)."""
    picked = picked and bool(np.isfinite(modes.picked_hz.to_numpy(float)).any())
    print(
        f"{'mode':>4} {'f (Hz)':>9}  {'95 % interval (Hz)':<22} {'damping':>7}  {'95 % interval':<16} {'orders':>6}"
        + ("  picked (Hz)" if picked else "")
    )
    for k, m in enumerate(modes.itertuples(index=False), start=1):
        f_ci = f"[{m.freq_ci95_lo:.4f}, {m.freq_ci95_hi:.4f}]"
        x_ci = f"[{m.damping_ci95_lo:.4f}, {m.damping_ci95_hi:.4f}]"
        pick = f"  {m.picked_hz:11.4f}" if picked and np.isfinite(m.picked_hz) else ""
        orders = f"{int(m.count)}" if m.count > 0 else "-"
        print(f"{k:>4} {m.freq_hz:9.4f}  {f_ci:<22} {m.damping:7.4f}  {x_ci:<16} {orders:>6}{pick}")
    if (modes["count"] == 0).any():  # a zero would read as a mode no order supports
        print("  orders -: added by the modal model's count; no column of the diagram holds it")


def print_check(check) -> None:
    """The modal-model check per output, beside the H1's own random error."""
    print(
        _fill(
            "modal-model check (LSFD of each H1 by the selected poles, residual terms and a delay; model error = "
            f"misfit beyond the H1's random error, limit {100 * check.limit:.0f} %):"
        )
    )
    for k, sensor in enumerate(check.sensors):
        if not np.isfinite(check.error[k]):
            print(f"  {sensor}: not checked (too few lines where its coherence is at least 0.8)")
            continue
        print(
            f"  {sensor}: misfit {100 * check.error[k]:.1f} %, H1 random error {100 * check.random_error[k]:.1f} %, "
            f"model error {100 * check.model_error[k]:.1f} %, delay {1e3 * check.delay_s[k]:+.1f} ms, "
            f"{check.n_lines[k]} lines"
        )


def _provenance(args) -> dict:
    """The full command line and the input's SHA-256, for the report."""
    import shlex

    from armaxmodal.study.manifest import content_hash

    files = [Path(p) for p in (args.data if isinstance(args.data, list) else [args.data])]
    checksum = ", ".join(f"{content_hash(p)} ({p.name})" for p in files if p.is_file())
    return {"command": shlex.join(args.command_line), "checksum": checksum}


def _diagram_outputs(args, diagram, selection, plot_format) -> list:
    """The stabilisation plot and pole table as ``(path, write)`` pairs for :func:`write_all`."""
    outputs = []
    if args.plot:
        ax, _ = diagram.plot(selection)
        outputs.append((args.plot, lambda tmp: ax.figure.savefig(tmp, dpi=150, format=plot_format)))
    if args.csv:
        table = diagram.to_frame()
        outputs.append((args.csv, lambda tmp: table.to_csv(tmp, index=False)))
    return outputs
