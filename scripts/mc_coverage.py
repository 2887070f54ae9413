"""Monte Carlo coverage of the reported 95 % intervals, after the whole selection (issue 13,
item 4): ride, stabilisation sweep, automatic selection, frequency-domain refit and the
segment-spread rule that widens intervals where the thirds of the record disagree.

For each seed a new ride and new sensor noise on the supine-human chain (truth: its exact
modes); the record is simulated with a zero-order hold (the exact ARMAX class) or
band-limited (the refit's class). A mode counts as covered when the reported interval holds
the exact value; a mode the selection missed counts as missed, not as uncovered. Also
reports how often a mode was flagged ``model_error_dominates`` (a time-invariant ride should
rarely be) and the spread of the estimates against the mean reported standard error.

    python scripts/mc_coverage.py [--seeds 40] [--hold zoh|bandlimited] [--duration 120]
"""

from __future__ import annotations

import argparse
import time

import numpy as np

import armaxmodal as am
from armaxmodal.modes.diagram import stabilisation_diagram
from armaxmodal.modes.pipeline import select_modes


def one_ride(structure, truth, seed: int, hold: str, duration: float) -> np.ndarray:
    """Per true mode: [found, freq covered, damping covered, flagged, freq est, damping est,
    freq sd, damping sd]; NaN where the mode was not found."""
    ride = am.random_vibration(60.0, duration, (0.5, 28.0), seed=7000 + seed)
    rec = am.simulate_recording(structure, ride, 60.0, noise=0.05, hold=hold, seed=8000 + seed)
    modes = select_modes(stabilisation_diagram(rec, range(2, 31, 2), n_jobs=2)).modes
    out = np.full((len(truth), 8), np.nan)
    for k, (f, x) in enumerate(zip(truth.freq_hz, truth.damping, strict=True)):
        gap = np.abs(modes.freq_hz.to_numpy() / f - 1)
        if gap.size == 0 or gap.min() > 0.1:
            out[k, 0] = 0
            continue
        m = modes.iloc[int(np.argmin(gap))]
        out[k] = [
            1,
            m.freq_ci95_lo <= f <= m.freq_ci95_hi,
            m.damping_ci95_lo <= x <= m.damping_ci95_hi,
            bool(m.get("model_error_dominates", False)),
            m.freq_hz,
            m.damping,
            (m.freq_ci95_hi - m.freq_ci95_lo) / (2 * 1.96),
            (m.damping_ci95_hi - m.damping_ci95_lo) / (2 * 1.96),
        ]
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=40)
    parser.add_argument("--hold", choices=["zoh", "bandlimited"], default="zoh")
    parser.add_argument("--duration", type=float, default=120.0)
    parser.add_argument("--results", help="write each mode's coverage to this JSON file (the validation page is "
                        "drawn from benchmarks/results/validation/mc_coverage_<hold>.json)")  # fmt: skip
    args = parser.parse_args()
    structure = am.supine_human()
    truth = structure.modes().to_frame()
    start = time.perf_counter()
    runs = []
    for seed in range(args.seeds):
        runs.append(one_ride(structure, truth, seed, args.hold, args.duration))
        print(f"seed {seed + 1}/{args.seeds} ({time.perf_counter() - start:.0f} s)", end="\r", flush=True)
    r = np.array(runs)  # seeds x modes x 8
    print(f"\n{args.seeds} rides, supine human, {args.hold}, {args.duration:g} s at 60 Hz, 5 % noise")
    print("| mode | truth Hz / xi | found | freq covered | damping covered | flagged | freq SD / SE | xi SD / SE |")
    print("|---|---|---|---|---|---|---|---|")
    for k, (f, x) in enumerate(zip(truth.freq_hz, truth.damping, strict=True)):
        found = r[:, k, 0] == 1
        got = r[found, k]
        ratio_f = np.std(got[:, 4], ddof=1) / np.mean(got[:, 6]) if len(got) > 2 else np.nan
        ratio_x = np.std(got[:, 5], ddof=1) / np.mean(got[:, 7]) if len(got) > 2 else np.nan
        print(
            f"| {k + 1} | {f:.2f} / {x:.3f} | {found.sum()}/{len(r)} | {np.mean(got[:, 1]):.0%} | "
            f"{np.mean(got[:, 2]):.0%} | {np.mean(got[:, 3]):.0%} | {ratio_f:.2f} | {ratio_x:.2f} |"
        )
    if args.results:
        _write_results(args, truth, r)
    all_found = r[r[:, :, 0] == 1]
    print(
        f"overall: frequency coverage {np.mean(all_found[:, 1]):.1%}, damping coverage "
        f"{np.mean(all_found[:, 2]):.1%} over {len(all_found)} found modes; {time.perf_counter() - start:.0f} s"
    )


def _write_results(args, truth, r) -> None:
    import json
    from pathlib import Path

    from armaxmodal.io.write import strict_json

    modes = []
    for k, (f, x) in enumerate(zip(truth.freq_hz, truth.damping, strict=True)):
        got = r[r[:, k, 0] == 1, k]
        modes.append({"freq_hz": float(f), "damping": float(x), "found": int(len(got)), "rides": int(len(r)),
                      "freq_covered": float(np.mean(got[:, 1])), "damping_covered": float(np.mean(got[:, 2])),
                      "freq_sd_over_se": float(np.std(got[:, 4], ddof=1) / np.mean(got[:, 6])),
                      "damping_sd_over_se": float(np.std(got[:, 5], ddof=1) / np.mean(got[:, 7]))})  # fmt: skip
    summary = {"hold": args.hold, "seeds": args.seeds, "duration_s": args.duration, "modes": modes,
               "armaxmodal_version": am.__version__}  # fmt: skip
    Path(args.results).write_text(json.dumps(strict_json(summary), indent=1, allow_nan=False) + "\n")


if __name__ == "__main__":
    main()
