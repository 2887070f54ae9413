"""Command-line interface: a thin layer over the public API.

armaxmodal info DATA [--input COL] [--fs HZ]
armaxmodal modes --system supine|chapter2 [--json OUT]
armaxmodal simulate --system supine --excitation random|sweep --out DATA.csv
armaxmodal diagnose DATA [--input COL] [--fs HZ] [--json OUT] [--plot OUT]
armaxmodal study MANIFEST_OR_FOLDER --out DIR [--report FILE] [--jobs N] [--scheduler ADDRESS]
armaxmodal lump DATA A B [--json OUT] [--plot OUT]
"""

from __future__ import annotations

import argparse
import gc
import os
import sys
from collections.abc import Sequence

import numpy as np

from . import datasets
from .exceptions import ArmaxModalError, DataError, OrderError
from .io import read_recording, write_all, write_json, write_recording_csv

SYSTEMS = {"supine": datasets.supine_human, "chapter2": datasets.chapter2_system}
#: Output options checked before any work (every command that writes files).
OUTPUT_OPTIONS = ("json", "csv", "plot", "out")
#: A simulation longer than this many samples is refused (it would run for minutes and fill memory).
MAX_SIMULATED_SAMPLES = 10_000_000


def _number(kind, lo: float, lo_open: bool, what: str):
    """An argparse type: a finite number of ``kind`` above ``lo`` (strictly when ``lo_open``)."""

    def parse(text: str):
        try:
            value = kind(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}") from exc
        if not np.isfinite(value) or value < lo or (lo_open and value == lo):
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}")
        return value

    return parse


_POSITIVE_INT = _number(int, 1, False, "a whole number >= 1")
_NONNEG_INT = _number(int, 0, False, "a whole number >= 0")
_POSITIVE = _number(float, 0.0, True, "a finite number > 0")
_NONNEG = _number(float, 0.0, False, "a finite number >= 0")


def check_output_paths(args) -> None:
    """Every output path usable before any work: not a directory, its parent a directory (or
    creatable), not one of the input files, and no two outputs the same file."""
    from pathlib import Path

    inputs = [Path(p).resolve() for p in _input_files(args)]
    seen = {}
    for option in OUTPUT_OPTIONS:
        value = getattr(args, option, None)
        if value is None or (option == "out" and args.command == "study"):  # a study's --out is a folder
            continue
        path = Path(value).resolve()
        flag = f"--{option}"
        if path.is_dir():
            raise DataError(f"{flag} {value}: is a directory; give a file name inside it.")
        if path in inputs:
            raise DataError(f"{flag} {value}: is an input file; writing there would destroy it. Choose another name.")
        if path in seen:
            raise DataError(f"{flag} and {seen[path]} name the same file {value}; give each its own.")
        seen[path] = flag
        parent = next((q for q in path.parents if q.exists()), None)
        if parent is not None and not parent.is_dir():
            raise DataError(f"{flag} {value}: {parent} is a file, not a folder; choose a path in a folder.")
        if parent is not None and not os.access(parent, os.W_OK):
            raise DataError(f"{flag} {value}: no permission to write in {parent}.")


def _input_files(args) -> list[str]:
    data = getattr(args, "data", None)
    files = list(data) if isinstance(data, list) else ([data] if data else [])
    for option in ("modes", "recording"):
        value = getattr(args, option, None)
        if isinstance(value, str):
            files.append(value)
    return files


def _add_data_args(p: argparse.ArgumentParser) -> None:
    p.add_argument("data", nargs="+", help="recording: .csv[.gz], .mat or .uff; or one Xsens DOT export per sensor")
    p.add_argument("--input", default="base", help="input (base acceleration) column or sensor; default 'base'")
    p.add_argument("--fs", type=_POSITIVE, default=None, help="sampling rate in Hz if the file has no time column")
    p.add_argument("--outputs", default=None, help="comma-separated output columns to use (default: all)")
    p.add_argument("--axis", default="Acc_X", help="Xsens exports: the column to use; default Acc_X")


def _load(args):
    outputs = args.outputs.split(",") if args.outputs else None
    if len(args.data) > 1:
        from .xsens import read_xsens

        rec = read_xsens(args.data, input=args.input, axis=args.axis)
        args.data = " + ".join(args.data)
        return rec if outputs is None else rec.select(outputs)
    args.data = args.data[0]
    rec = read_recording(args.data, input=args.input, fs=args.fs, outputs=outputs)
    skipped = rec.meta.get("axis_columns", ())
    if skipped and not getattr(args, "quiet", False):
        named = ", ".join(f"'{c}'" for c in skipped)
        print(f"{args.data}: column(s) {named} increase in equal steps (a row index or time axis): not outputs")
    return rec


def _cmd_info(args) -> int:
    rec = _load(args)
    print(f"{args.data}: {rec.n_samples} samples at {rec.fs:g} Hz ({rec.duration:.1f} s)")
    print(f"input  {rec.input_name}: rms {np.sqrt(np.mean(rec.base**2)):.4g}")
    for name, col in zip(rec.sensors, rec.response.T, strict=True):
        print(f"output {name}: rms {np.sqrt(np.mean(col**2)):.4g}")
    if rec.subject or rec.mass_kg:
        print(f"subject: {rec.subject or '-'}  mass: {rec.mass_kg or '-'} kg")
    return 0


def _parse_pair(text: str, what: str) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except ValueError as exc:
        raise DataError(f"{what}: expected LO:HI in Hz, got {text!r}.") from exc
    return lo, hi


def _cmd_identify(args) -> int:
    from .identify import identify

    rec = _load(args)
    orders = None
    if args.orders != "auto":
        try:
            orders = tuple(int(v) for v in args.orders.split(","))
        except ValueError as exc:
            raise OrderError(f"--orders: expected 'auto' or na,nb,nc,nk, got {args.orders!r}.") from exc
        if len(orders) != 4:
            raise OrderError(f"--orders: expected four integers na,nb,nc,nk, got {args.orders!r}.")
    band = _parse_pair(args.band, "--band") if args.band else None
    result = identify(rec, orders, band=band, progress=not args.quiet, detrend=args.detrend)
    _print_warnings(result.warnings)
    na, nb, nc, nk = result.fit.orders
    print(
        f"{args.data}: shared-pole ARMAX na={na} nb={nb} nc={nc} nk={nk}, "
        f"converged={bool(result.fit.converged.all())}, fit {np.round(result.fit.fit_percent, 1).tolist()} %"
    )
    table = result.modes[
        ["freq_hz", "damping", "damped_freq_hz", "freq_ci95_lo", "freq_ci95_hi", "damping_ci95_lo", "damping_ci95_hi"]
    ]
    print(table.to_string(float_format=lambda v: f"{v:.4f}"))
    _print_check(result.check)
    outputs = []
    if args.json:
        outputs.append((args.json, lambda tmp: write_json(result.to_dict(), tmp)))
    if args.csv:
        poles = result.fit.modes().drop(columns=["pole", "residue"])
        outputs.append((args.csv, lambda tmp: poles.to_csv(tmp, index=False)))
    write_all(outputs)
    print(_verdict(result.check, len(result.modes)))
    return 0


def _cmd_stabilise(args) -> int:
    from .prepare import check_band
    from .stabilisation import select_modes, stabilisation_diagram

    plot_format = _format(args.plot) if args.plot else None
    orders = None if args.orders is None else _order_range(args.orders)
    band = check_band(_parse_pair(args.band, "--band")) if args.band else None
    rec = _load(args)
    check_band(band, rec.fs)
    if not args.quiet:
        outputs = ", ".join(rec.sensors)
        print(f"{args.data}: input {rec.input_name}; outputs {outputs}; {rec.n_samples} samples at {rec.fs:g} Hz")
    diagram = stabilisation_diagram(rec, orders, band=band, detrend=args.detrend, progress=not args.quiet)
    try:
        selection = select_modes(diagram, args.modes, band)
    except OrderError:
        # no mode: the diagram and the pole table still show the user why
        _print_warnings(diagram.warnings)
        _write_outputs(_diagram_outputs(args, diagram, None, plot_format))
        raise
    if not args.quiet:
        prep = diagram.preparation
        if prep is not None and prep.analysis_fs != prep.original_fs:
            print(f"analysis at {prep.analysis_fs:g} Hz (resampled from {prep.original_fs:g} Hz)")
        print(
            selection.modes[
                [
                    "freq_hz",
                    "damping",
                    "damped_freq_hz",
                    "freq_ci95_lo",
                    "freq_ci95_hi",
                    "damping_ci95_lo",
                    "damping_ci95_hi",
                    "count",
                ]
            ].to_string(float_format=lambda v: f"{v:.4f}")
        )
        _print_check(selection.check)
    _print_warnings(selection.warnings)
    outputs = _diagram_outputs(args, diagram, selection, plot_format)
    if args.json:
        report = selection.to_dict(args.shapes.replace("-", "_"))
        outputs.append((args.json, lambda tmp: write_json(report, tmp)))
    _write_outputs(outputs)
    print(_verdict(selection.check, len(selection.modes)))
    return 0


def _order_range(text: str) -> range:
    """``--orders LO:HI`` as the even-step range of ``na``."""
    try:
        lo, hi = (int(v) for v in text.split(":"))
    except ValueError as exc:
        raise OrderError(f"--orders: expected LO:HI model orders such as 2:40, got {text!r}.") from exc
    if not 1 <= lo <= hi:
        raise OrderError(f"--orders: expected 1 <= LO <= HI, got {text!r}.")
    return range(lo, hi + 1, 2)


def _print_check(check) -> None:
    """The modal-model check per output, beside the H1's own random error."""
    from .modal_check import MODEL_ERROR_LIMIT

    print(
        "modal-model check (LSFD of each H1 by the selected poles, residual terms and a delay; "
        f"model error = misfit beyond the H1's random error, limit {100 * MODEL_ERROR_LIMIT:.0f} %):"
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


def _verdict(check, n_modes: int) -> str:
    """The closing line: whether the modes explain the record."""
    if check is not None and check.passed:
        return f"quality: good -- the {n_modes} selected mode(s) explain the measured FRF of every checked output"
    if check is not None and check.unconfirmed_hz and not check.failing:
        where = ", ".join(f"{f:.2f}" for f in check.unconfirmed_hz)
        return f"quality: POOR -- the record does not confirm the mode(s) at {where} Hz (no coherent H1 there)"
    if check is None or not check.failing:
        return "quality: POOR -- no output has coherent lines to check the modes against: treat them as unconfirmed"
    worst = float(np.nanmax(check.model_error))
    return (
        f"quality: POOR -- the selected modes do not explain the measured FRF of {', '.join(check.failing)} "
        f"(model error up to {100 * worst:.0f} %): treat them as unconfirmed (see the warning)"
    )


def _cmd_diagnose(args) -> int:
    from .diagnose import diagnose
    from .prepare import check_band

    plot_format = _format(args.plot) if args.plot else None
    band = check_band(_parse_pair(args.band, "--band")) if args.band else None
    rec = _load(args)
    result = diagnose(rec, band=band, max_rounds=args.max_rounds, progress=not args.quiet)
    _print_warnings(result.warnings)
    report = result.to_dict()
    print(_diagnosis_text(args.data, report))
    outputs = []
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from .diagnose.plot import plot_diagnosis

        fig = plot_diagnosis(result)
        outputs.append((args.plot, lambda tmp: fig.savefig(tmp, dpi=120, format=plot_format)))
    if args.json:
        outputs.append((args.json, lambda tmp: write_json(report, tmp)))
    _write_outputs(outputs)
    return 0


def _diagnosis_text(name: str, report: dict) -> str:
    """The diagnosis as a person reads it: fits before and after, each effect with its numbers."""
    sensors = report["outputs"]
    base, final = report["baseline"], report["final"]
    lines = [f"{name}: {len(sensors)} sensors at {report['analysis_fs']:g} Hz; baseline orders {report['orders']}"]
    lines.append(f"{'sensor':>12} {'fit before %':>13} {'fit after %':>12} {'resid RMS':>10} {'H1 floor':>12}")
    for k, s in enumerate(sensors):
        if final["fit_val_pct"][k] is None:
            lines.append(f"{s:>12} {base['fit_val_pct'][k]:13.1f}   now an input (a second excitation)")
            continue
        lines.append(
            f"{s:>12} {base['fit_val_pct'][k]:13.1f} {final['fit_val_pct'][k]:12.1f} "
            f"{final['sim_resid_rms'][k]:10.4g} {_or_unresolved(final['noise_floor_rms'][k]):>12}"
        )
    if not report["effects"]:
        lines.append("no effect kept (the tests' p-values are in the JSON's 'tests').")
    for e in report["effects"]:
        params = {k: v for k, v in e["parameters"].items() if not isinstance(v, dict)}
        lines.append(
            f"effect {e['effect']} on {', '.join(e['channels'])}: "
            f"{e['evidence']['statistic']} p = {e['evidence']['p']:.2g}; "
            f"held-out one-step RMS {e['error_before']:.4g} -> {e['error_after']:.4g}; {_short(params)}"
        )
        if e.get("note"):
            lines.append(f"  note: {e['note']}")
    for u in report["unconfirmed"]:
        lines.append(f"unconfirmed {u['effect']} on {', '.join(u['channels'])}: {u['reason']}")
    if report["not_tested"]:
        lines.append("not tested by this version: " + ", ".join(report["not_tested"]))
    lines.append("verdict: " + report["verdict"])
    return "\n".join(lines)


def _or_unresolved(value) -> str:
    """A noise floor, or why there is none (the record cannot resolve its lightest mode)."""
    return "unresolved" if value is None else f"{value:.4g}"


def _short(params: dict) -> str:
    def fmt(v):
        if isinstance(v, float):
            return f"{v:.4g}"
        if isinstance(v, list):
            return "[" + ", ".join(fmt(x) for x in v) + "]"
        return str(v)

    return ", ".join(f"{k} {fmt(v)}" for k, v in params.items())


def _print_warnings(warnings) -> None:
    """Data-quality warnings go to stderr, one line each, even with --quiet."""
    for w in warnings:
        print(f"warning [{w.code}]: {w.message}", file=sys.stderr)


def _diagram_outputs(args, diagram, selection, plot_format) -> list:
    """The stabilisation plot and pole table as ``(path, write)`` pairs for :func:`write_all`."""
    outputs = []
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        ax, _ = diagram.plot(selection)
        outputs.append((args.plot, lambda tmp: ax.figure.savefig(tmp, dpi=150, format=plot_format)))
    if args.csv:
        table = diagram.to_frame()
        outputs.append((args.csv, lambda tmp: table.to_csv(tmp, index=False)))
    return outputs


def _write_outputs(outputs) -> None:
    """All outputs or none, then the figures closed."""
    try:
        write_all(outputs)
    finally:
        # pyplot is loaded only when a figure was drawn; importing it to close nothing
        # cost every run without --plot 0.7 s
        if "matplotlib.pyplot" in sys.modules:
            sys.modules["matplotlib.pyplot"].close("all")


def _format(path: str) -> str:
    ext = path.rsplit(".", 1)[-1].lower()
    if ext not in ("png", "svg", "pdf"):
        raise DataError(f"--plot: expected a .png, .svg or .pdf file name, got {path!r}.")
    return ext


def _modal_noise_levels(data: dict) -> dict:
    """Relative standard deviations of each mode's frequency and damping from the 95 %
    intervals in a stabilise JSON (model updating weighs each mode by them)."""
    sigma = {}
    for key, value, interval in (("freq", "freq_hz", "freq_ci95"), ("damping", "damping", "damping_ci95")):
        try:
            sd = [(m[interval][1] - m[interval][0]) / (2 * 1.96 * m[value]) for m in data["modes"]]
        except (KeyError, TypeError, IndexError, ZeroDivisionError):
            continue  # no intervals given: the documented defaults apply
        if all(np.isfinite(sd)) and min(sd) > 0:
            sigma[key] = np.asarray(sd)
    return sigma


def _print_solution(sol, total_mass: float | None) -> None:
    """The recovered chain's components and its modes, as two tables."""
    table = sol.to_frame()
    parts = table[table.component != "mode"].dropna(axis=1, how="all").drop(columns="method")
    if parts.size:
        first = sol.structure.names[0]
        scale = (
            f"the total mass is {total_mass:g} kg"
            if total_mass is not None
            else f"no --total-mass: the scale is unknown, so the mass of '{first}' is set to 1 kg; multiply every "
            f"value by its true mass in kg (or give --total-mass)"
        )
        print(f"components ({sol.method}; {scale}):")
        print(parts.to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    print("modes of the recovered model:")
    print(sol.modes.to_frame().to_string(index=False, float_format=lambda v: f"{v:.4g}"))


def _cmd_invert(args) -> int:
    import json

    if args.plot and not args.recording:
        raise DataError("--plot shows the predicted against the measured motion: give --recording DATA.")

    from .inverse import evphc, inner_solve, model_update, pia
    from .inverse._modal_data import body_mass_bounds, modes_from_json

    try:
        data = json.loads(open(args.modes, encoding="utf-8").read())
    except (OSError, json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise DataError(f"{args.modes}: not a readable modes JSON ({exc}); write one with 'stabilise --json'.") from exc
    if not isinstance(data, dict) or not data.get("modes"):
        raise DataError(f"{args.modes}: no modes in this JSON; 'stabilise --json' writes them under \"modes\".")
    plot_format = _format(args.plot) if args.plot else None
    lam, shapes, sensors = modes_from_json(data)
    bounds = None
    if set(sensors) <= set(datasets.TABLE_4_2_MASS_FRACTION):
        bounds = body_mass_bounds(sensors, datasets.TABLE_4_2_MASS_FRACTION)
    frf, sigma = None, _modal_noise_levels(data)
    if args.recording:
        from .frf import default_nperseg, h1_relative_error, measured_frf

        rec = read_recording(args.recording, input=args.input, fs=args.fs)
        if set(rec.sensors) != set(sensors):
            raise DataError(
                f"--recording {args.recording}: its sensors {list(rec.sensors)} are not the modes' {sensors}; "
                "give the recording the modes were identified from."
            )
        f, h, coh = measured_frf(rec)
        keep = (f > 0.5) & (np.min(coh, axis=1) >= 0.8)
        frf = (f[keep], h[keep])
        sigma["frf"] = h1_relative_error(coh[keep], rec.n_samples, default_nperseg(rec))
    total = args.total_mass
    if args.method == "pia":
        if total is None or bounds is None:
            raise DataError("pia needs the masses: give --total-mass for body segments of Table 4.2.")
        fr = datasets.TABLE_4_2_MASS_FRACTION
        sol = pia(lam, shapes, [total * fr[s] / sum(fr[x] for x in sensors) for s in sensors], names=sensors)
    elif args.method == "inner":
        sol = inner_solve(lam, shapes, mass_ratio_bounds=bounds, total_mass=total, names=sensors)
    elif args.method == "evphc":
        if frf is None:
            raise DataError("evphc needs the measured transmissibility: give --recording DATA.")
        sol = evphc(lam, shapes, frf, mass_ratio_bounds=bounds, total_mass=total, names=sensors)
    else:
        sol = model_update(lam, shapes, frf=frf, sigma=sigma, mass_ratio_bounds=bounds, total_mass=total, names=sensors)
    prediction = None
    if args.recording:
        from .inverse import predict_recording

        prediction = predict_recording(sol.structure, rec)
    if not args.quiet:
        _print_solution(sol, total)
        for flag in sol.flags:
            print(f"note: {flag}")
        if prediction is not None:
            print(prediction.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    outputs = []
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        from .plot import plot_prediction

        axes = plot_prediction(rec, prediction.attrs["prediction"], prediction.fit_percent.to_numpy())
        outputs.append((args.plot, lambda tmp: axes[0].figure.savefig(tmp, dpi=150, format=plot_format)))
    if args.json:
        comps = sol.components
        report = {
            "method": sol.method,
            "M": sol.structure.M,
            "C": sol.structure.C,
            "K": sol.structure.K,
            "names": list(sol.structure.names),
            "components": None if comps is None else _components_dict(comps),
            "components_std": None if sol.std is None else _components_dict(sol.std),
            "modes": sol.modes.to_dict()["modes"],
            "misfits": sol.misfits,
            "flags": sol.flags,
            "converged": sol.converged,
            "time_s": sol.time_s,
            "prediction_fit_percent": None
            if prediction is None
            else dict(zip(prediction.sensor, map(float, prediction.fit_percent), strict=True)),
        }
        outputs.append((args.json, lambda tmp: write_json(report, tmp)))
    _write_outputs(outputs)
    return 0


def _components_dict(comps) -> dict:
    return {"masses": comps.masses, "k": comps.k, "c": comps.c, "k_s": comps.k_s, "c_s": comps.c_s}


def _cmd_modes(args) -> int:
    modes = SYSTEMS[args.system]().modes()
    print(modes.to_frame().to_string(index=False, float_format=lambda v: f"{v:.4f}"))
    if args.json:
        write_json(modes.to_dict(), args.json)
        if not args.quiet:
            print(f"wrote {args.json}")
    return 0


def _cmd_simulate(args) -> int:
    from .diagnose.inject import check_effect
    from .simulate import random_vibration, simulate_recording, sine_sweep

    effects = [_parse_effect(text) for text in args.effect or ()]
    for effect, _, params in effects:  # before the simulation
        check_effect(effect, params)
    structure = SYSTEMS[args.system]()
    if args.duration * args.fs > MAX_SIMULATED_SAMPLES:
        raise DataError(
            f"--duration {args.duration:g} s at --fs {args.fs:g} Hz is {args.duration * args.fs:.3g} samples, "
            f"more than {MAX_SIMULATED_SAMPLES:.0e}; simulate a shorter ride."
        )
    if args.duration * args.fs < 200:
        raise DataError(
            f"--duration {args.duration:g} s at {args.fs:g} Hz gives under 200 samples; nothing to identify."
        )
    if args.excitation == "random":
        u = random_vibration(args.fs, args.duration, (0.5, min(28.0, 0.47 * args.fs)), seed=args.seed)
    else:
        u = sine_sweep(args.fs, args.duration)
    rec = simulate_recording(structure, u, args.fs, noise=args.noise, seed=args.seed, hold=args.hold)
    for effect, channels, params in effects:
        from .diagnose.inject import inject

        rec = inject(rec, effect, channels, seed=args.seed, structure=structure, **params)
    write_recording_csv(rec, args.out)
    if not args.quiet:
        print(f"wrote {args.out}: {rec.n_samples} samples, outputs {', '.join(rec.sensors)}")
    return 0


def _parse_effect(text: str):
    """``EFFECT[:CH1+CH2][:key=value,...]`` -> (effect, channels or None, params)."""
    parts = text.split(":")
    effect, channels, params = parts[0], None, {}
    if len(parts) > 1 and parts[1]:
        channels = parts[1].split("+")
    if len(parts) > 2 and parts[2]:
        for item in parts[2].split(","):
            key, _, value = item.partition("=")
            try:
                params[key] = float(value)
            except ValueError as exc:
                raise DataError(f"--effect {text!r}: expected key=number pairs, got {item!r}.") from exc
    if len(parts) > 3:
        raise DataError(f"--effect {text!r}: expected EFFECT[:CH1+CH2][:key=value,...].")
    return effect, channels, params


_DETREND_HELP = (
    "remove each channel's mean (default) or least-squares line before fitting, and any level shift "
    "(a sensor offset jumping mid-record); 'none' only reports them"
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="armaxmodal", description="Time-domain modal analysis of base-excited systems."
    )
    parser.add_argument("--quiet", action="store_true", help="no progress or chatter")
    # --quiet is accepted after the command too; SUPPRESS keeps a subcommand's unset default
    # from overwriting the top-level flag
    quiet = argparse.ArgumentParser(add_help=False)
    quiet.add_argument("--quiet", action="store_true", default=argparse.SUPPRESS, help="no progress or chatter")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser(
        "stabilise", parents=[quiet], help="order sweep, stabilisation plot and automatic mode selection"
    )
    _add_data_args(p)
    p.add_argument(
        "--orders", default=None, help="range of na, LO:HI (even steps); default 2:30, capped to suit the record"
    )
    p.add_argument("--modes", type=_POSITIVE_INT, default=None, help="number of modes to keep (default: automatic)")
    p.add_argument("--band", default=None, help="frequency band LO:HI in Hz")
    p.add_argument("--plot", default=None, help="stabilisation plot (.png, .svg or .pdf)")
    p.add_argument("--json", default=None, help="selected modes as JSON")
    p.add_argument("--csv", default=None, help="every pole of the sweep as CSV")
    p.add_argument(
        "--detrend",
        choices=["mean", "linear", "none"],
        default="mean",
        help=_DETREND_HELP,
    )
    p.add_argument(
        "--shapes",
        choices=["shared", "per-sensor"],
        default="shared",
        help="mode shapes from the shared-pole fit, or per sensor with gaps filled by Eq. 3.34",
    )
    p.set_defaults(func=_cmd_stabilise)

    p = sub.add_parser("invert", parents=[quiet], help="physical chain model (M, C, K) from identified modes")
    p.add_argument("modes", help="modes JSON written by 'stabilise --json'")
    p.add_argument("--recording", default=None, help="the recording, for the measured transmissibility")
    p.add_argument("--input", default="base")
    p.add_argument("--fs", type=_POSITIVE, default=None)
    p.add_argument("--method", choices=["model_update", "evphc", "pia", "inner"], default="model_update")
    p.add_argument("--total-mass", type=_POSITIVE, default=None, help="subject mass in kg (sets the scale)")
    p.add_argument("--json", default=None, help="write M, C, K, components and modes as JSON")
    p.add_argument("--plot", default=None, help="predicted vs measured acceleration per sensor (.png/.svg/.pdf)")
    p.set_defaults(func=_cmd_invert)

    p = sub.add_parser("identify", parents=[quiet], help="fit a shared-pole ARMAX model and print the modes")
    _add_data_args(p)
    p.add_argument("--orders", default="auto", help="'auto' (BIC) or na,nb,nc,nk; default auto")
    p.add_argument("--band", default=None, help="frequency band LO:HI in Hz")
    p.add_argument("--detrend", choices=["mean", "linear", "none"], default="mean", help=_DETREND_HELP)
    p.add_argument("--json", default=None, help="write modes as JSON")
    p.add_argument("--csv", default=None, help="write every pole of every sensor as CSV")
    p.set_defaults(func=_cmd_identify)

    p = sub.add_parser(
        "diagnose", parents=[quiet], help="find the effect the model lacks, add it, refit, report before/after"
    )
    _add_data_args(p)
    p.add_argument("--band", default=None, help="frequency band LO:HI in Hz (sets the analysis rate)")
    p.add_argument("--max-rounds", type=_NONNEG_INT, default=3, help="effects added at most; default 3")
    p.add_argument("--json", default=None, help="write the diagnosis as JSON")
    p.add_argument("--plot", default=None, help="figure page (.png/.svg/.pdf)")
    p.set_defaults(func=_cmd_diagnose)

    p = sub.add_parser("info", parents=[quiet], help="summarise a recording")
    _add_data_args(p)
    p.set_defaults(func=_cmd_info)

    p = sub.add_parser("modes", parents=[quiet], help="exact modes of a reference structure from the thesis")
    p.add_argument("--system", choices=sorted(SYSTEMS), default="supine")
    p.add_argument("--json", default=None, help="write the modes as JSON")
    p.set_defaults(func=_cmd_modes)

    p = sub.add_parser("simulate", parents=[quiet], help="simulate a base-excitation ride of a reference structure")
    p.add_argument("--system", choices=sorted(SYSTEMS), default="supine")
    p.add_argument("--excitation", choices=["random", "sweep"], default="random")
    p.add_argument("--fs", type=_POSITIVE, default=60.0)
    p.add_argument("--duration", type=_POSITIVE, default=120.0, help="seconds; default 120")
    p.add_argument("--noise", type=_NONNEG, default=0.05, help="sensor noise, fraction of RMS")
    p.add_argument("--hold", choices=["zoh", "bandlimited"], default="bandlimited")
    p.add_argument("--seed", type=_NONNEG_INT, default=0)
    p.add_argument(
        "--effect",
        action="append",
        help="plant an effect the diagnosis is not told: EFFECT[:CH1+CH2][:key=value,...], e.g. "
        "periodic_disturbance:head:freq_hz=11.7,amp=0.1 or input_delay:legs:samples=2.5 (repeatable)",
    )
    p.add_argument("--out", required=True, help="CSV file to write")
    p.set_defaults(func=_cmd_simulate)

    from .lumping.command import add_parser as add_lump
    from .study.command import add_parser as add_study

    add_study(sub, [quiet], {"positive_int": _POSITIVE_INT})
    add_lump(sub, [quiet], _POSITIVE)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        check_output_paths(args)
        return args.func(args)
    except (ArmaxModalError, FileNotFoundError) as exc:
        print(f"armaxmodal: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        # outputs are staged and moved in whole, so an interrupted run leaves none behind
        print("armaxmodal: interrupted; no output was written.", file=sys.stderr)
        return 130


def run() -> None:
    """Console entry point: :func:`main`, then exit with its status."""
    status = main()
    # The process ends here with every output written and closed. Moving the live objects
    # (the imported libraries, the fits) out of the collector's reach spares the
    # interpreter's final collection, about 0.4 s of a 5 s command; only that scan is
    # skipped. Not in main(): called in-process, it would pin the caller's objects.
    gc.freeze()
    sys.exit(status)
