"""``armaxmodal info``: summarise a recording."""

from __future__ import annotations

import numpy as np

from armaxmodal.cli.common import add_data_args, load_recording


def add_parser(sub, parents) -> None:
    """Register the ``info`` command."""
    p = sub.add_parser("info", parents=parents, help="summarise a recording")
    add_data_args(p)
    p.set_defaults(func=run)


def run(args) -> int:
    rec = load_recording(args)
    print(f"{args.data}: {rec.n_samples} samples at {rec.fs:g} Hz ({rec.duration:.1f} s)")
    print(f"input  {rec.input_name}: rms {np.sqrt(np.mean(rec.base**2)):.4g}")
    for name, col in zip(rec.sensors, rec.response.T, strict=True):
        print(f"output {name}: rms {np.sqrt(np.mean(col**2)):.4g}")
    if rec.subject or rec.mass_kg:
        print(f"subject: {rec.subject or '-'}  mass: {rec.mass_kg or '-'} kg")
    return 0
