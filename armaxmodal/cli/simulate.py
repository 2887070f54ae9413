"""``armaxmodal simulate``: a base-excitation ride of a reference structure."""

from __future__ import annotations

from armaxmodal.cli.common import NONNEG, NONNEG_INT, POSITIVE, SYSTEMS
from armaxmodal.exceptions import DataError
from armaxmodal.io.write import write_recording_csv


def add_parser(sub, parents) -> None:
    """Register the ``simulate`` command."""
    p = sub.add_parser("simulate", parents=parents, help="simulate a base-excitation ride of a reference structure")
    p.add_argument(
        "--system",
        choices=sorted(SYSTEMS),
        default="supine",
        help="the structure: the thesis's supine body (Table 4.3) or Chapter 2's chain; default supine",
    )
    p.add_argument(
        "--excitation",
        choices=["random", "sweep"],
        default="random",
        help="the base acceleration: band-limited random vibration or a sine sweep; default random",
    )
    p.add_argument("--fs", type=POSITIVE, default=60.0, help="sampling rate, Hz; default 60")
    p.add_argument("--duration", type=POSITIVE, default=120.0, help="seconds; default 120")
    p.add_argument("--noise", type=NONNEG, default=0.05, help="sensor noise, fraction of each output's RMS")
    p.add_argument(
        "--hold",
        choices=["zoh", "bandlimited"],
        default="bandlimited",
        help="the input between samples: held (zoh) or band-limited, as an anti-aliased logger records "
        "it; default bandlimited",
    )
    p.add_argument("--seed", type=NONNEG_INT, default=0, help="seed of the excitation and the noise; default 0")
    from armaxmodal.diagnosis.inject import PARAMETERS, RIDE_EFFECTS  # numba is loaded already: no cost

    effects = "; ".join(
        f"{name} ({', '.join(need + tuple(f'[{k}]' for k in optional)) or 'no parameter'})"
        for name, (need, optional) in {**PARAMETERS, **RIDE_EFFECTS}.items()
    )
    p.add_argument(
        "--effect",
        action="append",
        help="plant an effect the diagnosis is not told: EFFECT[:CH1+CH2][:key=value,...], e.g. "
        "periodic_disturbance:head:freq_hz=11.7,amp=0.1, input_delay:legs:samples=2.5 or "
        "stiffness_nonlinearity:chest+pelvis:ratio=0.3 (a cubic spring in that joint; one channel: to the base; "
        "damping_nonlinearity: dry friction) (repeatable; one effect in the structure a ride). "
        f"Effects and their parameters ([optional]): {effects}",
    )
    p.add_argument("--out", required=True, help="CSV file to write")
    p.set_defaults(func=run)


#: A simulation longer than this many samples is refused (it would run for minutes and fill memory).
MAX_SIMULATED_SAMPLES = 10_000_000


def run(args) -> int:
    from armaxmodal.diagnosis.inject import RIDE_EFFECTS, check_effect, inject
    from armaxmodal.systems.simulation import random_vibration, sine_sweep

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
    in_structure = [e for e in effects if e[0] in RIDE_EFFECTS]
    if len(in_structure) > 1:
        raise DataError(f"--effect: one effect in the structure a ride, got {[e[0] for e in in_structure]}.")
    rec = _ride(structure, u, args, in_structure[0] if in_structure else None)
    for effect, channels, params in effects:
        if effect not in RIDE_EFFECTS:
            rec = inject(rec, effect, channels, seed=args.seed, structure=structure, **params)
    write_recording_csv(rec, args.out)
    if not args.quiet:
        print(f"wrote {args.out}: {rec.n_samples} samples, outputs {', '.join(rec.sensors)}")
    return 0


def _ride(structure, u, args, effect):
    """The simulated ride, with ``effect`` (``(name, channels, params)`` of
    :data:`~armaxmodal.diagnosis.inject.RIDE_EFFECTS`, or None) in the structure: a joint force by
    :func:`~armaxmodal.diagnosis.inject.nonlinear_joint_ride`, or a stiffening
    (:func:`~armaxmodal.diagnosis.inject.stiffened_ride`)."""
    from armaxmodal.diagnosis.inject import nonlinear_joint_ride, stiffened_ride
    from armaxmodal.systems.simulation import simulate_recording

    if effect is None:
        return simulate_recording(structure, u, args.fs, noise=args.noise, seed=args.seed, hold=args.hold)
    name, channels, params = effect
    if name == "time_varying":
        if not 0 < params["time_s"] < args.duration:
            raise DataError(
                f"--effect time_varying: time_s must lie inside the ride (0-{args.duration:g} s), "
                f"got {params['time_s']}."
            )
        return stiffened_ride(
            structure,
            u,
            args.fs,
            params["time_s"],
            params["stiffening"],
            noise=args.noise,
            seed=args.seed,
            hold=args.hold,
        )
    names = list(structure.names)
    if not channels or len(channels) > 2 or any(c not in names for c in channels) or not params["ratio"] > 0:
        raise DataError(
            f"--effect {name}: name the joint, one or two of {names} (one: to the base), and ratio > 0; "
            f"got {channels} and {params}."
        )
    if args.hold != "bandlimited":
        raise DataError(f"--effect {name}: a joint force is simulated with the band-limited input; drop --hold zoh.")
    between = (names.index(channels[0]), names.index(channels[1]) if len(channels) == 2 else -1)
    force = "cubic" if name == "stiffness_nonlinearity" else "friction"
    return nonlinear_joint_ride(
        structure, u, args.fs, between, params["ratio"], force=force, noise=args.noise, seed=args.seed
    )


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
