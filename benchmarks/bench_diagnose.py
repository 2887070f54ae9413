"""Where `armaxmodal diagnose` spends its time (issue 10's performance: a 4-sensor, 120 s,
60 Hz ride in under 30 s on 2 cores, every test and one round of fixes included).

Times each stage of one diagnosis in this process, after a warm-up run that compiles and
loads the numba kernels: preparation, the baseline order search (BIC), the baseline fit,
its held-out folds, every effect test of the first round, one fix with its held-out folds,
and the whole `diagnose()` call. The record is the bundled ride, or a copy with an effect
planted (``--plant periodic``), or any recording (``--data FILE [--input COL]``).

    python benchmarks/bench_diagnose.py [--plant periodic|delay|none] [--data FILE --input COL]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import armaxmodal as am
from armaxmodal.diagnosis import diagnose
from armaxmodal.diagnosis.acceptance import try_fix
from armaxmodal.diagnosis.effects import REGISTRY, Evidence, entry_of
from armaxmodal.diagnosis.inject import inject
from armaxmodal.diagnosis.loop import _baseline_orders, _signals
from armaxmodal.diagnosis.model import ModelSpec, counted, fit_model, held_out
from armaxmodal.diagnosis.result import Stage
from armaxmodal.estimate.fit import load_kernels

ROOT = Path(__file__).resolve().parents[1]
PLANTS = {
    "none": None,
    "periodic": ("periodic_disturbance", ["head", "pelvis"], {"freq_hz": 11.7, "amp": 0.1}),
    "delay": ("input_delay", ["legs"], {"samples": 2.4}),
}


class Clock:
    def __init__(self) -> None:
        self.t = time.perf_counter()

    def lap(self, name: str) -> None:
        now = time.perf_counter()
        print(f"| {name} | {now - self.t:.2f} |", flush=True)
        self.t = now


def stages(rec: am.Recording) -> None:
    clock = Clock()
    signals, prepared, _ = _signals(rec, None)
    clock.lap("preparation (resampling check, warnings)")
    orders = _baseline_orders(prepared, None)
    clock.lap(f"baseline order search (BIC): {orders}")
    spec = ModelSpec(tuple(int(v) for v in orders))
    model = fit_model(spec, signals)
    clock.lap("baseline fit")
    held = held_out(spec, signals, model)
    clock.lap("held-out folds (two refits)")
    tests = [e.test for e in REGISTRY]
    tests = [t for i, t in enumerate(tests) if t not in tests[:i]]
    ev = Evidence(model, model.one_step_errors(), counted(model), len(tests) * len(signals.sensors))
    for test in tests:  # each of the registry's tests once, as run_tests runs them
        ev.found += test(ev)
        names = ", ".join(e.name for e in REGISTRY if e.test is test)
        clock.lap(f"test: {names}")
    significant = sorted((f for f in ev.found if f.p < 0.01), key=lambda f: f.p)
    if significant:
        try_fix(Stage(model, held), significant[0], 0.01, entry_of(significant[0].effect))
        clock.lap(f"one fix with its held-out folds: {significant[0].effect}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--plant", choices=sorted(PLANTS), default="periodic")
    parser.add_argument("--data")
    parser.add_argument("--input", default="base")
    args = parser.parse_args()
    load_kernels()
    if args.data:
        rec = am.read_recording(args.data, input=args.input)
    else:
        rec = am.read_recording(ROOT / "fixtures" / "supine_random.csv")
        if PLANTS[args.plant] is not None:
            effect, channels, params = PLANTS[args.plant]
            rec = inject(rec, effect, channels, **params)
    diagnose(rec, max_rounds=1)  # warm-up: numba's cache, first-call imports
    print(f"{rec.n_samples} samples x {len(rec.sensors)} sensors at {rec.fs:g} Hz\n")
    print("| stage | s |\n|---|---|")
    stages(rec)
    start = time.perf_counter()
    result = diagnose(rec)
    total = time.perf_counter() - start
    named = ", ".join(f"{e.finding.effect} {list(e.finding.channels)}" for e in result.effects) or "none"
    print(f"| whole diagnose() (up to 3 rounds; named: {named}) | {total:.2f} |")


if __name__ == "__main__":
    main()
