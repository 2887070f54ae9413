"""The modal model's efficiency: the spread and bias of each mode's frequency and damping over many
records of one body, against the Cramér-Rao bound of the same records.

The thesis's Chapter 5 body (``supine_with_feet``, five segments), 120 s rides at 60 Hz band-passed
0.5-24 Hz, 3 % sensor noise, simulated band-limited (as an anti-aliased logger records). Each
record is fitted as the selection's refit fits it (the record's DFT lines over the band it
chooses, each sensor weighted by its noise, the band-limited inter-sample form), started from the
exact modes, so that only the estimator is judged and not the count. The bound is the model's
information at the exact poles on that record (``count_battery.bound``). Per mode: the RMS error
and the bias, in bounds (1 is efficient), for the variants named on the command line:

* ``as_fitted``: as above;
* ``inner_band``: the band's lowest and highest 10 % left out (do the edges, where the input's
  filter rolls off, cost efficiency?);
* ``zoh``: the zero-order-hold form fitted to the band-limited record (the wrong inter-sample model).

    python scripts/mc_crb_modal.py [--records 40] [--variants as_fitted inner_band zoh]
        [--results benchmarks/results/validation/efficiency.json]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

import armaxmodal as am
from armaxmodal.estimate.dft_model import DftLines
from armaxmodal.modes.state import refit_band

sys.path.insert(0, str(Path(__file__).resolve().parent))
from count_battery import bound, fit_modal_model, ride  # noqa: E402

VARIANTS = ("as_fitted", "inner_band", "zoh")


def one_record(body, truth, seed: int, variants) -> dict:
    rng = np.random.default_rng(90000 + seed)
    rec = am.simulate_recording(body, ride(rng, 60.0), 60.0, noise=0.03, seed=91000 + seed, hold="bandlimited")
    band = refit_band(rec, None)
    crb_f, crb_x = bound(rec, truth, band, "bandlimited")
    out = {}
    for variant in variants:
        lo, hi = band
        if variant == "inner_band":
            lo, hi = lo + 0.1 * (hi - lo), hi - 0.1 * (hi - lo)
        hold = "zoh" if variant == "zoh" else "bandlimited"
        data = DftLines.from_recording(rec, (lo, hi))
        start = fit_modal_model(data, truth.freq_hz, truth.damping, hold, max_nfev=1)
        data = data.noise_weighted(start)
        fit = fit_modal_model(data, truth.freq_hz, truth.damping, hold, max_nfev=60)
        order = np.argsort(fit.freq_hz)
        out[variant] = {
            "freq_bounds": ((fit.freq_hz[order] / truth.freq_hz - 1) / crb_f).tolist(),
            "damping_bounds": ((fit.damping[order] / truth.damping - 1) / crb_x).tolist(),
        }
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=40)
    parser.add_argument("--variants", nargs="+", choices=VARIANTS, default=list(VARIANTS))
    parser.add_argument("--results", help="write the table to this JSON file")
    args = parser.parse_args()
    body = am.supine_with_feet()
    truth = body.modes()
    runs = []
    for seed in range(args.records):
        runs.append(one_record(body, truth, seed, args.variants))
        print(f"record {seed + 1}/{args.records}", end="\r", flush=True)
    table = []
    for variant in args.variants:
        f = np.array([r[variant]["freq_bounds"] for r in runs])
        x = np.array([r[variant]["damping_bounds"] for r in runs])
        for k, (fk, xk) in enumerate(zip(truth.freq_hz, truth.damping, strict=True)):
            table.append({"variant": variant, "freq_hz": float(fk), "damping": float(xk),
                          "freq_rms": float(np.sqrt(np.mean(f[:, k] ** 2))), "freq_bias": float(np.mean(f[:, k])),
                          "damping_rms": float(np.sqrt(np.mean(x[:, k] ** 2))),
                          "damping_bias": float(np.mean(x[:, k]))})  # fmt: skip
    print(f"\n{args.records} records of the five-segment body; errors in Cramér-Rao bounds (1: efficient)")
    print("| variant | mode (Hz) | f RMS | f bias | damping RMS | damping bias |")
    print("|---|---|---|---|---|---|")
    for row in table:
        print(f"| {row['variant']} | {row['freq_hz']:.2f} | {row['freq_rms']:.2f} | {row['freq_bias']:+.2f} | "
              f"{row['damping_rms']:.2f} | {row['damping_bias']:+.2f} |")  # fmt: skip
    if args.results:
        summary = {"records": args.records, "rows": table, "armaxmodal_version": am.__version__}
        Path(args.results).write_text(json.dumps(summary, indent=1, allow_nan=False) + "\n")


if __name__ == "__main__":
    main()
