"""Regenerate the bundled fixtures byte for byte.

Each fixture is a CSV recording (``time``, ``base``, one column per sensor, subject lines
on top) and a ``.truth.json`` with the structure, its exact modes and how the data were
made. Run:  python tools/make_fixtures.py [--out fixtures]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import armaxmodal as am
from armaxmodal.io.write import write_json

SUBJECTS = {
    "supine_human": "supine-human model (thesis Section 4.4)",
    "chapter2_system": "four-DOF system (thesis Section 2.3.1)",
}
# name: (structure factory, fs, excitation, hold, output noise, input noise, seed)
FIXTURES = {
    "supine_random": (am.supine_human, 60.0, "random", "bandlimited", 0.05, 0.01, 11),
    "supine_sweep": (am.supine_human, 60.0, "sweep", "bandlimited", 0.05, 0.01, 12),
    "supine_random_zoh": (am.supine_human, 60.0, "random", "zoh", 0.05, 0.0, 13),
    "chapter2_random_zoh": (am.chapter2_system, 100.0, "random", "zoh", 0.05, 0.0, 14),
}
DURATION_S = 120.0
RANDOM_BAND_HZ = {60.0: (0.5, 28.0), 100.0: (0.5, 45.0)}
FLOAT_FORMAT = "%.8g"


def excitation(kind: str, fs: float, seed: int):
    if kind == "random":
        return am.random_vibration(fs, DURATION_S, RANDOM_BAND_HZ[fs], rms=1.0, seed=seed)
    return am.sine_sweep(fs, DURATION_S, 0.5, 20.0, amplitude=2.0, power_exponent=1.0)


def truth(
    structure: am.Structure,
    fs: float,
    kind: str,
    hold: str,
    noise: float,
    input_noise: float,
    seed: int,
) -> dict:
    modes = structure.modes()
    comps = structure.chain_components()
    return {
        "fs": fs,
        "duration_s": DURATION_S,
        "input": "base",
        "outputs": list(structure.names),
        "excitation": kind,
        "band_hz": list(RANDOM_BAND_HZ[fs]) if kind == "random" else [0.5, 20.0],
        "hold": hold,
        "measured_quantity": "absolute acceleration (m/s^2)",
        "output_noise_rel_rms": noise,
        "input_noise_rel_rms": input_noise,
        "seed": seed,
        "structure": {
            "M": structure.M,
            "C": structure.C,
            "K": structure.K,
            "components": {
                "masses": comps.masses,
                "k": comps.k,
                "c": comps.c,
                "k_s": comps.k_s,
                "c_s": comps.c_s,
            },
        },
        **modes.to_dict(),
    }


def make(out: Path) -> list[Path]:
    written = []
    for name, (factory, fs, kind, hold, noise, input_noise, seed) in FIXTURES.items():
        structure = factory()
        u = excitation(kind, fs, seed)
        rec = am.simulate_recording(structure, u, fs, noise=noise, input_noise=input_noise, seed=seed + 1000, hold=hold)
        rec = am.Recording(
            rec.fs,
            rec.base,
            rec.response,
            rec.sensors,
            "base",
            subject=SUBJECTS[factory.__name__],
            mass_kg=float(structure.masses.sum()),
        )
        written.append(am.write_recording_csv(rec, out / f"{name}.csv", FLOAT_FORMAT))
        written.append(
            write_json(
                truth(structure, fs, kind, hold, noise, input_noise, seed),
                out / f"{name}.truth.json",
            )
        )
    return written


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[1] / "fixtures")
    args = parser.parse_args()
    for path in make(args.out):
        print(path)


if __name__ == "__main__":
    main()
