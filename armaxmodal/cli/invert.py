"""``armaxmodal invert``: a physical chain model (M, C, K) from identified modes."""

from __future__ import annotations

import os

import numpy as np

from armaxmodal.cli.common import POSITIVE, output_format, write_outputs
from armaxmodal.exceptions import DataError
from armaxmodal.io.read import read_recording
from armaxmodal.io.write import write_json
from armaxmodal.stats import H1_COHERENCE, Z95
from armaxmodal.systems import datasets


def add_parser(sub, parents) -> None:
    """Register the ``invert`` command."""
    p = sub.add_parser("invert", parents=parents, help="physical chain model (M, C, K) from identified modes")
    p.add_argument("modes", help="modes JSON written by 'stabilise --json', or UFF 55 ('stabilise --uff', .uff/.unv)")
    p.add_argument("--recording", default=None, help="the recording, for the measured transmissibility")
    p.add_argument("--input", default="base", help="the recording's input (base) channel; default base")
    p.add_argument(
        "--fs", type=POSITIVE, default=None, help="the recording's sampling rate, Hz, where its file has no time column"
    )
    p.add_argument(
        "--method",
        choices=["model_update", "evphc", "pia", "inner"],
        default="model_update",
        help="joint model updating of modes and transmissibility (default), the thesis's EVPHC, the "
        "Pilkey-Inman baseline, or the chain that best satisfies the eigen-equations alone (no FRF)",
    )
    p.add_argument("--total-mass", type=POSITIVE, default=None, help="subject mass in kg (sets the scale)")
    p.add_argument("--json", default=None, help="write M, C, K, components and modes as JSON")
    p.add_argument("--plot", default=None, help="predicted vs measured acceleration per sensor (.png/.svg/.pdf)")
    p.set_defaults(func=run)


def run(args) -> int:
    if args.plot and not args.recording:
        raise DataError("--plot shows the predicted against the measured motion: give --recording DATA.")
    from armaxmodal.inverse.modal_data import body_mass_bounds, modes_from_json

    data = _read_modes(args.modes)
    plot_format = output_format(args.plot) if args.plot else None
    lam, shapes, sensors = modes_from_json(data)
    bounds = None
    if set(sensors) <= set(datasets.TABLE_4_2_MASS_FRACTION):
        bounds = body_mass_bounds(sensors, datasets.TABLE_4_2_MASS_FRACTION)
    sigma, notes = _modal_noise_levels(data)
    rec = frf = None
    if args.recording:
        rec, frf = _measured_transmissibility(args, sensors, sigma)
    sol = _solve(args, lam, shapes, sensors, bounds, frf, sigma)
    sol.flags.extend(notes)
    prediction = None
    if rec is not None:
        from armaxmodal.inverse import predict_recording

        prediction = predict_recording(sol.structure, rec)
    if not args.quiet:
        _print_solution(sol, args.total_mass)
        for flag in sol.flags:
            print(f"note: {flag}")
        if prediction is not None:
            print(prediction.to_string(index=False, float_format=lambda v: f"{v:.3f}"))
    outputs = []
    if args.plot:
        from armaxmodal.io.report.diagram_plot import plot_prediction

        axes = plot_prediction(rec, prediction.attrs["prediction"], prediction.fit_percent.to_numpy())
        outputs.append((args.plot, lambda tmp: axes[0].figure.savefig(tmp, dpi=150, format=plot_format)))
    if args.json:
        report = _report(sol, prediction)
        outputs.append((args.json, lambda tmp: write_json(report, tmp)))
    write_outputs(outputs)
    return 0


def _read_modes(path: str) -> dict:
    """A ``stabilise --json`` file, or the UFF 55 modes of a ``.uff``/``.unv`` file, refused with
    advice when it holds no modes."""
    import json

    if path.lower().endswith((".uff", ".unv")):
        from armaxmodal.io.uff_modes import read_modes_uff

        if not os.path.isfile(path):
            raise DataError(f"{path}: no such file.")
        return read_modes_uff(path)
    try:
        data = json.loads(open(path, encoding="utf-8").read())
    except (OSError, json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise DataError(f"{path}: not a readable modes JSON ({exc}); write one with 'stabilise --json'.") from exc
    if not isinstance(data, dict) or not data.get("modes"):
        raise DataError(f"{path}: no modes in this JSON; 'stabilise --json' writes them under \"modes\".")
    return data


def _measured_transmissibility(args, sensors: list, sigma: dict) -> tuple:
    """The recording and its coherent H1 lines ``(freq_hz, T)``; the H1's relative error goes
    into ``sigma["frf"]``."""
    from armaxmodal.spectra import default_nperseg, h1_relative_error, measured_frf

    rec = read_recording(args.recording, input=args.input, fs=args.fs)
    if set(rec.sensors) != set(sensors):
        raise DataError(
            f"--recording {args.recording}: its sensors {list(rec.sensors)} are not the modes' {sensors}; "
            "give the recording the modes were identified from."
        )
    f, h, coh = measured_frf(rec)
    keep = (f > 0.5) & (np.min(coh, axis=1) >= H1_COHERENCE)
    sigma["frf"] = h1_relative_error(coh[keep], rec.n_samples, default_nperseg(rec))
    return rec, (f[keep], h[keep])


def _solve(args, lam, shapes, sensors, bounds, frf, sigma):
    """The chain by the chosen method."""
    from armaxmodal.inverse import evphc, inner_solve, model_update, pia

    total = args.total_mass
    if args.method == "pia":
        if total is None or bounds is None:
            raise DataError("pia needs the masses: give --total-mass for body segments of Table 4.2.")
        fr = datasets.TABLE_4_2_MASS_FRACTION
        return pia(lam, shapes, [total * fr[s] / sum(fr[x] for x in sensors) for s in sensors], names=sensors)
    if args.method == "inner":
        return inner_solve(lam, shapes, mass_ratio_bounds=bounds, total_mass=total, names=sensors)
    if args.method == "evphc":
        if frf is None:
            raise DataError("evphc needs the measured transmissibility: give --recording DATA.")
        return evphc(lam, shapes, frf, mass_ratio_bounds=bounds, total_mass=total, names=sensors)
    return model_update(lam, shapes, frf=frf, sigma=sigma, mass_ratio_bounds=bounds, total_mass=total, names=sensors)


def _report(sol, prediction) -> dict:
    """The ``invert --json`` contract."""
    comps = sol.components
    return {
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


def _modal_noise_levels(data: dict) -> tuple[dict, list[str]]:
    """Relative standard deviations of each mode's frequency and damping from the 95 %
    intervals in a stabilise JSON (model updating weighs each mode by them), and a note for
    every mode whose interval is missing or unusable: that mode alone takes the default level."""
    from armaxmodal.inverse.update import DEFAULT_SIGMA

    sigma, notes = {}, []
    for key, value, interval in (("freq", "freq_hz", "freq_ci95"), ("damping", "damping", "damping_ci95")):
        sd = np.array([_relative_sd(m, value, interval, Z95) for m in data["modes"]])
        missing = ~(np.isfinite(sd) & (sd > 0))
        if missing.any():
            numbers = ", ".join(str(i + 1) for i in np.flatnonzero(missing))
            notes.append(
                f"mode(s) {numbers}: no usable {interval} in the modes JSON; their {key} is weighted by the "
                f"default noise level ({100 * DEFAULT_SIGMA[key]:g} %)"
            )
            sd[missing] = DEFAULT_SIGMA[key]
        sigma[key] = sd
    return sigma, notes


def _relative_sd(mode: dict, value: str, interval: str, z95: float) -> float:
    """One mode's relative standard deviation from its 95 % interval; NaN when it has none."""
    try:
        lo, hi = mode[interval]
        return float((hi - lo) / (2 * z95 * mode[value]))
    except (KeyError, TypeError, ValueError, ZeroDivisionError):
        return float("nan")


def _print_solution(sol, total_mass: float | None) -> None:
    """The recovered chain's components and its modes, as two tables."""
    parts = sol.to_frame()
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


def _components_dict(comps) -> dict:
    return {"masses": comps.masses, "k": comps.k, "c": comps.c, "k_s": comps.k_s, "c_s": comps.c_s}
