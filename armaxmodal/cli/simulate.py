"""``armaxmodal simulate``: a base-excitation ride of a reference structure."""

from __future__ import annotations

from armaxmodal.cli.common import NONNEG, NONNEG_INT, POSITIVE, SYSTEMS
from armaxmodal.exceptions import DataError
from armaxmodal.io.write import write_recording_csv


def add_parser(sub, parents) -> None:
    """Register the ``simulate`` command."""
    p = sub.add_parser("simulate", parents=parents, help="simulate a base-excitation ride of a reference structure")
    p.add_argument("--system", choices=sorted(SYSTEMS), default="supine",
                   help="the structure: the thesis's supine body (Table 4.3) or Chapter 2's chain; default supine")
    p.add_argument("--excitation", choices=["random", "sweep"], default="random",
                   help="the base acceleration: band-limited random vibration or a sine sweep; default random")
    p.add_argument("--fs", type=POSITIVE, default=60.0, help="sampling rate, Hz; default 60")
    p.add_argument("--duration", type=POSITIVE, default=120.0, help="seconds; default 120")
    p.add_argument("--noise", type=NONNEG, default=0.05, help="sensor noise, fraction of each output's RMS")
    p.add_argument("--hold", choices=["zoh", "bandlimited"], default="bandlimited",
                   help="the input between samples: held (zoh) or band-limited, as an anti-aliased logger records "
                        "it; default bandlimited")
    p.add_argument("--seed", type=NONNEG_INT, default=0, help="seed of the excitation and the noise; default 0")
    from armaxmodal.diagnosis.inject import PARAMETERS  # numba is loaded already: no cost to the CLI's start

    effects = "; ".join(f"{name} ({', '.join(need + tuple(f'[{k}]' for k in optional)) or 'no parameter'})"
                        for name, (need, optional) in PARAMETERS.items())  # fmt: skip
    p.add_argument(
        "--effect",
        action="append",
        help="plant an effect the diagnosis is not told: EFFECT[:CH1+CH2][:key=value,...], e.g. "
        "periodic_disturbance:head:freq_hz=11.7,amp=0.1 or input_delay:legs:samples=2.5 (repeatable). "
        f"Effects and their parameters ([optional]): {effects}",
    )
    p.add_argument("--out", required=True, help="CSV file to write")
    p.set_defaults(func=run)


#: A simulation longer than this many samples is refused (it would run for minutes and fill memory).
MAX_SIMULATED_SAMPLES = 10_000_000


def run(args) -> int:
    from armaxmodal.diagnosis.inject import check_effect
    from armaxmodal.systems.simulation import random_vibration, simulate_recording, sine_sweep

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
        from armaxmodal.diagnosis.inject import inject

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
