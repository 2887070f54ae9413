"""The delay choice against its slow reference: every (na, nk) of the search fitted to
convergence and scored by BIC per sample of its own window (so that the data's unit cancels),
on the real-data table's runs and the damaged fixture copies.

For each run it prints the delay the product chose, the reference's best delay, and the
delays whose best BIC lies within ``--flat`` BIC units of the reference's minimum: where that
set is wide, the record does not determine the delay and any delay in it is equally right.

Run:  python scripts/delay_choice_reference.py [--shared ../shared] [--only NAME ...]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from realdata_snapshot import _runs  # noqa: E402
from realdata_table import _damaged  # noqa: E402

from armaxmodal._threads import one_blas_thread  # noqa: E402
from armaxmodal.cli.common import load_recording  # noqa: E402
from armaxmodal.cli.main import build_parser  # noqa: E402
from armaxmodal.estimate.fit import load_kernels  # noqa: E402
from armaxmodal.estimate.orders import default_nb, default_nc, fit_or_none, information_criterion  # noqa: E402
from armaxmodal.modes.diagram import NK_EXTENSION, NK_SEARCH, choose_nk  # noqa: E402
from armaxmodal.prepare.preparation import prepare  # noqa: E402

NA_VALUES = (8, 10, 12)


def reference_scores(rec) -> dict[int, float]:
    """Per delay, the lowest BIC over NA_VALUES of fits run to fit_armax's default criterion,
    in BIC units at the widest window's length (per-sample BIC times that length)."""
    nk_values = range(max(NK_SEARCH), min(NK_SEARCH) - NK_EXTENSION - 1, -1)
    per_sample, n_ref = {}, None
    for na in NA_VALUES:
        for nk in nk_values:
            fit = fit_or_none(rec, (na, default_nb(na, nk), default_nc(na), nk), shared_poles=True)
            if fit is None:
                continue
            score = information_criterion(fit) / fit.n_samples
            per_sample[nk] = min(per_sample.get(nk, np.inf), score)
            n_ref = fit.n_samples if n_ref is None else min(n_ref, fit.n_samples)
    return {nk: s * n_ref for nk, s in per_sample.items()}


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--shared", default=str(Path(__file__).resolve().parents[2] / "shared"))
    parser.add_argument("--only", nargs="*")
    parser.add_argument("--flat", type=float, default=10.0, help="BIC units within which delays tie")
    args = parser.parse_args()
    load_kernels()
    with tempfile.TemporaryDirectory() as tmp:
        runs = _runs(Path(args.shared) / "realdata")
        runs.update(_damaged(Path(tmp)))
        for name, run in runs.items():
            if args.only and name not in args.only:
                continue
            rec = prepare(load_recording(build_parser().parse_args(["stabilise", *run]))).recording
            t0 = time.process_time()
            with one_blas_thread():
                chosen = choose_nk(rec, n_jobs=1)
                t1 = time.process_time()
                scores = reference_scores(rec)
            t2 = time.process_time()
            best = min(scores, key=scores.get)
            flat = sorted(nk for nk, s in scores.items() if s - scores[best] <= args.flat)
            gap = scores[chosen] - scores[best]
            print(
                f"{name[:40]:40s} chosen {chosen:3d} ({t1 - t0:5.2f} CPU-s) | reference {best:3d} "
                f"({t2 - t1:6.1f} CPU-s), "
                f"within {args.flat:g}: {flat}, chosen is {gap:8.1f} BIC above",
                flush=True,
            )


if __name__ == "__main__":
    main()
