"""Coverage of the 95 % intervals `diagnose` reports for an effect's parameters (issue 10,
item 6): over simulated supine rides (60 Hz, 120 s, 5 % sensor noise, one ride per seed),
each effect planted with a known size; an interval counts when it holds the planted value.

- offset 0.3 and drift 0.004 /s on chest: ``offset_ci95``, ``drift_ci95_per_s``;
- a line at 11.3 Hz of RMS 10 % of head's: ``amp_ci95`` (peak amplitude, ``sqrt(2)`` x RMS);
- legs recorded 2.4 samples late: ``delay_ci95_ms`` (40 ms);
- chest's clock drifting 120 ppm: ``rate_ci95_ppm``;
- pelvis reading 1.1 times more from 70.5 s: ``factor_ci95``, ``time_ci95_s``;
- head's offset stepping by 0.15 x its RMS at 45.25 s: ``size_ci95``, ``time_ci95_s``.

    python scripts/diagnose_coverage.py --seeds 40 [--only TEXT]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import armaxmodal as am
from armaxmodal.diagnosis import diagnose
from armaxmodal.diagnosis.inject import inject

FS = 60.0


def ride(seed: int) -> am.Recording:
    u = am.random_vibration(FS, 120.0, band=(0.5, 28.0), seed=seed)
    return am.simulate_recording(am.supine_human(), u, FS, noise=0.05, seed=seed + 1000, hold="bandlimited")


def _effect(d, name: str, channel: str):
    """The accepted effect ``name`` on ``channel``, or None."""
    for e in d.effects:
        if e.finding.effect == name and channel in e.finding.channels:
            return e
    return None


def planted_cases(rec: am.Recording):
    """``(label, recording, effect, channel, [(parameter path, truth), ...])`` per case."""
    head_rms = float(np.std(rec.response[:, rec.sensors.index("head")]))
    yield (
        "offset+drift chest",
        inject(rec, "offset_drift", ["chest"], offset=0.3, drift_per_s=0.004),
        "offset_drift",
        "chest",
        [(("per_channel", "chest", "offset_ci95"), 0.3), (("per_channel", "chest", "drift_ci95_per_s"), 0.004)],
    )
    yield (
        "line 11.3 Hz head",
        inject(rec, "periodic_disturbance", ["head"], freq_hz=11.3, amp=0.1),
        "periodic_disturbance",
        "head",
        [(("per_channel", "head", "amp_ci95"), 0.1 * head_rms * np.sqrt(2))],
    )
    yield (
        "legs 2.4 samples late",
        inject(rec, "input_delay", ["legs"], samples=2.4),
        "input_delay",
        "legs",
        [(("delay_ci95_ms",), 1e3 * 2.4 / FS)],
    )
    yield (
        "chest clock 120 ppm",
        inject(rec, "clock_drift", ["chest"], rate_ppm=120.0),
        "clock_drift",
        "chest",
        [(("rate_ci95_ppm",), 120.0)],
    )
    yield (
        "pelvis gain 1.1 at 70.5 s",
        inject(rec, "gain_change", ["pelvis"], time_s=70.5, factor=1.1),
        "gain_change",
        "pelvis",
        [(("factor_ci95",), 1.1), (("time_ci95_s",), 70.5)],
    )
    step = 0.15 * head_rms
    yield (
        "head step 0.15 x RMS at 45.25 s",
        inject(rec, "level_shift", ["head"], time_s=45.25, size=step),
        "level_shift",
        "head",
        [(("size_ci95",), step), (("time_ci95_s",), 45.25)],
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=40)
    parser.add_argument("--only", default="", help="the cases whose label holds this text")
    args = parser.parse_args()
    held: dict[str, list[bool]] = {}
    named: dict[str, int] = {}
    t0 = time.perf_counter()
    for seed in range(args.seeds):
        for label, rec, effect, channel, checks in planted_cases(ride(seed)):
            if args.only not in label:
                continue
            e = _effect(diagnose(rec), effect, channel)
            named[label] = named.get(label, 0) + (e is not None)
            if e is None:
                continue
            for path, truth in checks:
                node = e.parameters
                for key in path:
                    node = node[key]
                held.setdefault(f"{label}: {path[-1]}", []).append(node[0] <= truth <= node[1])
        print(f"seed {seed} done ({time.perf_counter() - t0:.0f} s)", flush=True)
    for label, n in named.items():
        print(f"{label}: named {n}/{args.seeds}")
    for key, hits in held.items():
        print(f"{key}: interval holds the truth in {sum(hits)}/{len(hits)} ({100 * np.mean(hits):.0f} %)")


if __name__ == "__main__":
    main()
