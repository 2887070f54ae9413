"""Where `armaxmodal diagnose` spends its time (issue 10's performance: a 4-sensor, 120 s,
60 Hz ride in under 30 s on 2 cores, every test and one round of fixes included).

Times each stage of one diagnosis in this process, after a warm-up run that compiles and
loads the numba kernels: preparation, the baseline order search (BIC), the baseline fit,
its held-out folds, every effect test of the first round, one fix with its held-out folds,
and the whole `diagnose()` call. The record is the bundled ride, or a copy with an effect
planted (``--plant periodic``), or any recording (``--data FILE [--input COL]``).

    python scripts/bench_diagnose.py [--plant periodic|delay|none] [--data FILE --input COL]
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import armaxmodal as am
from armaxmodal.diagnosis import delays as dl
from armaxmodal.diagnosis import diagnose
from armaxmodal.diagnosis import evidence as ev
from armaxmodal.diagnosis.inject import inject
from armaxmodal.diagnosis.loop import _baseline_orders, _signals, _try_fix
from armaxmodal.diagnosis.model import ModelSpec, fit_model, held_out, usable
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
    k, eps = len(signals.sensors), model.one_step_errors()
    n_tests, mask = len(ev.EFFECT_TESTS) * k, usable(signals.n, spec)
    table = {"whiteness_p": [], "trend_p": [], "line_p": []}  # as run_tests starts it
    found = dl.delay_findings(model, n_tests)
    clock.lap("test: delay (quasi-static phase slope)")
    found += dl.lead_findings(model, n_tests, set())
    clock.lap("test: lead (residual-input cross-correlation)")
    found += ev.mode_findings(model, n_tests, table)
    clock.lap("test: unmodelled mode (FRF misfit)")
    found += ev._trend_findings(model, eps, mask, n_tests, table)
    clock.lap("test: offset and drift (score test)")
    found += ev._line_findings(model, mask, n_tests, table)
    clock.lap("test: periodic disturbance (multitaper)")
    found += ev._whiteness_findings(model, eps, mask, n_tests, table)
    clock.lap("test: coloured noise (Breusch-Godfrey)")
    found += ev._time_findings(model, mask, n_tests, table)
    clock.lap("test: time variation (6 windowed refits)")
    found += ev._nonlinear_findings(model, eps, mask, n_tests, table)
    clock.lap("test: stiffness nonlinearity (score tests)")
    significant = sorted((f for f in found if f.p < 0.01), key=lambda f: f.p)
    if significant:
        from armaxmodal.diagnosis.loop import Stage

        _try_fix(Stage(model, held), significant[0], 0.01)
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
