"""False-alarm rate and detection of `diagnose` on simulated rides (issue 10, item 7).

Clean rides: the supine human (60 Hz, 120 s, 5 % sensor noise, band-limited input) and the
Chapter 2 system at 100 Hz, one ride per seed; a recording counts as a false alarm when any
effect is accepted. Planted effects: each at a clear size and at a size near the detection
threshold, on the seed's ride; a detection counts when the first accepted effect is the
planted one on the planted channel.

    python scripts/diagnose_rates.py --seeds 20
"""

from __future__ import annotations

import argparse
import time

import armaxmodal as am
from armaxmodal.diagnosis import diagnose
from armaxmodal.diagnosis.inject import inject

SYSTEMS = {
    "supine 60 Hz": (am.supine_human, 60.0, 28.0),
    "chapter2 100 Hz": (am.chapter2_system, 100.0, 45.0),
}
PLANTED = {
    "periodic clear": ("periodic_disturbance", ["head"], {"freq_hz": 11.3, "amp": 0.1}),
    "periodic near threshold": ("periodic_disturbance", ["head"], {"freq_hz": 11.3, "amp": 0.03}),
    "offset+drift clear": ("offset_drift", ["chest"], {"offset": 0.3, "drift_per_s": 0.004}),
    "drift near threshold": ("offset_drift", ["chest"], {"offset": 0.0, "drift_per_s": 0.0003}),
    "sensor late 2.4 samples": ("input_delay", ["legs"], {"samples": 2.4}),
    "sensor late 1 sample": ("input_delay", ["legs"], {"samples": 1.0}),
    "clipping clear": ("clipping", ["chest"], {"fraction": 0.6}),
    "clipping near threshold": ("clipping", ["chest"], {"fraction": 0.9}),
    "glitches clear": ("sensor_fault", ["pelvis"], {"spikes": 10}),
    "glitches near threshold": ("sensor_fault", ["pelvis"], {"spikes": 5, "spike_size": 0.3}),
    "stuck clear": ("sensor_fault", ["pelvis"], {"stuck_s": 1.0}),
    "stuck near threshold": ("sensor_fault", ["pelvis"], {"stuck_s": 0.05}),
    "second input clear": ("second_input", ["chest"], {"level": 0.1}),
    "second input near threshold": ("second_input", ["chest"], {"level": 0.004}),
}


def ride(system: str, seed: int) -> am.Recording:
    make, fs, f_hi = SYSTEMS[system]
    u = am.random_vibration(fs, 120.0, band=(0.5, f_hi), seed=seed)
    return am.simulate_recording(make(), u, fs, noise=0.05, seed=seed + 1000, hold="bandlimited")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--planted", action="store_true", help="also run the planted effects (supine)")
    parser.add_argument("--planted-only", action="store_true", help="only the planted effects")
    parser.add_argument("--only", default="", help="planted cases whose label contains this text")
    args = parser.parse_args()
    for system in () if args.planted_only else SYSTEMS:
        alarms, t0 = [], time.perf_counter()
        for seed in range(args.seeds):
            d = diagnose(ride(system, seed))
            if d.effects:
                alarms.append((seed, [(e.finding.effect, e.finding.channels) for e in d.effects]))
        dt = (time.perf_counter() - t0) / args.seeds
        print(f"{system}: false alarms {len(alarms)}/{args.seeds} recordings ({dt:.1f} s each) {alarms}")
    if not (args.planted or args.planted_only):
        return
    for label, (effect, channels, params) in PLANTED.items():
        if args.only not in label:
            continue
        hits = 0
        for seed in range(args.seeds):
            rec = inject(ride("supine 60 Hz", seed), effect, channels, seed=seed, structure=am.supine_human(), **params)
            d = diagnose(rec)
            first = d.effects[0].finding if d.effects else None
            named = "force" if effect == "second_input" else channels[0]  # the recorded force, not where it acts
            hits += first is not None and first.effect == effect and named in first.channels
        print(f"{label}: named first {hits}/{args.seeds}", flush=True)


if __name__ == "__main__":
    main()
