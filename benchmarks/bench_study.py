"""Study throughput: the synthetic 30-recording study (15 subjects x 2 rides, 4-5 sensors,
120 s at 60 Hz) run serially (the loop a user writes around ``stabilise``), on local worker
processes, and on a dask LocalCluster of 1 and 2 workers, in one run on the same files.

    python benchmarks/bench_study.py [--subjects 15] [--workdir /tmp/bench_study]

Prints wall times, the speed-up over serial and recordings per core-minute; every run
starts from an empty cache and its Table 3.3 is checked equal to the serial one.
"""

from __future__ import annotations

import argparse
import os
import shutil
import time
from pathlib import Path

import pandas as pd
from results import save  # benchmarks/results.py, beside this script

from armaxmodal.study import StudySettings, make_study, run_study


def timed(label, source, out, **kwargs):
    shutil.rmtree(out, ignore_errors=True)
    start = time.perf_counter()
    study = run_study(source, out, StudySettings(lump=("legs", "feet")), **kwargs)
    return label, time.perf_counter() - start, study


def main() -> None:  # a dask LocalCluster spawns its workers: this module must keep its __main__ guard
    parser = argparse.ArgumentParser()
    parser.add_argument("--subjects", type=int, default=15)
    parser.add_argument("--workdir", default="/tmp/bench_study")
    args = parser.parse_args()
    work = Path(args.workdir)
    if not (work / "data" / "manifest.csv").is_file():
        make_study(work / "data", args.subjects)
    source = work / "data" / "manifest.csv"
    cores = os.cpu_count() or 1
    runs = [timed("serial (jobs=1)", source, work / "serial", jobs=1)]
    runs.append(timed(f"local processes (jobs={cores})", source, work / "local", jobs=cores))
    import dask
    from distributed import LocalCluster

    for n in (1, 2):
        # the workers' statistical profiler samples every task's stack each 10 ms: 15-20 % here
        with (
            dask.config.set({"distributed.worker.profile.enabled": False}),
            LocalCluster(n_workers=n, threads_per_worker=1, dashboard_address=None) as cluster,
        ):
            runs.append(
                timed(
                    f"dask LocalCluster, {n} worker(s)", source, work / f"dask{n}", scheduler=cluster.scheduler_address
                )
            )
    base_time, base = runs[0][1], runs[0][2]
    rows = []
    for label, seconds, study in runs:
        pd.testing.assert_frame_equal(base.tables.summary, study.tables.summary)
        workers = 1 if "jobs=1" in label or "1 worker" in label else cores
        n = len(study.recordings)
        rows.append(
            {
                "run": label,
                "recordings": n,
                "wall_s": round(seconds, 1),
                "speed_up": round(base_time / seconds, 2),
                "recordings_per_core_minute": round(n / (seconds / 60) / workers, 1),
            }
        )
    print(pd.DataFrame(rows).to_string(index=False))
    print("Table 3.3 identical in every run.")
    one, two = (next(r for r in rows if r["run"] == f"dask LocalCluster, {n} worker(s)") for n in (1, 2))
    speed = one["wall_s"] / two["wall_s"]
    save("study", [{
        "what": f"a dask LocalCluster with 2 workers against 1, the {rows[0]['recordings']}-recording synthetic "
                "study (its summary table identical in every run)",
        "goal": ">= 1.8", "measured": f"{speed:.2f} ({two['wall_s']} s against {one['wall_s']} s; serial "
                                      f"{rows[0]['wall_s']} s)", "met": speed >= 1.8, "values": rows,
    }])  # fmt: skip


if __name__ == "__main__":
    main()
