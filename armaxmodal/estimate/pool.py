"""The worker pool of the sweeps: ``parallel_map`` over forked processes when it pays."""

from __future__ import annotations

import multiprocessing
import os
from concurrent.futures import ProcessPoolExecutor

from armaxmodal.estimate.fit import load_kernels


def _single_blas_thread() -> None:
    # Every matrix here is small; BLAS threads in several worker processes only contend.
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")


def parallel_map(func, items, n_jobs, bar=None, cost=None, min_items: int = 4):
    """``map`` over forked worker processes when it pays, else in this process.

    ``bar`` (a tqdm bar) is advanced as results arrive. ``cost(item)``, if given, estimates
    an item's run time: the workers then take the longest first, so no long job starts last
    and leaves a core idle. Fewer than ``min_items`` items run here (forking a pool costs
    about 0.1 s: worth it for two long fits, not for a few short ones). Results come back in
    the order of ``items``.
    """
    n_jobs = n_jobs or os.cpu_count() or 1
    out = []
    if n_jobs <= 1 or len(items) < min_items or "fork" not in multiprocessing.get_all_start_methods():
        for item in items:
            out.append(func(item))
            if bar is not None:
                bar.update()
        return out
    load_kernels()  # once here, not once per forked worker
    order = sorted(range(len(items)), key=lambda i: -cost(items[i])) if cost else list(range(len(items)))
    out = [None] * len(items)
    ctx = multiprocessing.get_context("fork")
    # each worker is forked with the task already in its memory (fork passes initargs
    # without pickling): only the items cross the pipe, not the recording bound into
    # ``func`` (a megabyte pickled per item)
    with ProcessPoolExecutor(n_jobs, mp_context=ctx, initializer=_start_worker, initargs=(func,)) as pool:
        for i, result in zip(order, pool.map(_run_task, [items[i] for i in order]), strict=True):
            out[i] = result
            if bar is not None:
                bar.update()
    return out


_WORKER_TASK = None


def _start_worker(func) -> None:
    global _WORKER_TASK
    _WORKER_TASK = func
    _single_blas_thread()


def _run_task(item):
    return _WORKER_TASK(item)
