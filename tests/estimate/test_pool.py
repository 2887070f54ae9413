"""The sweeps' worker pool (``parallel_map`` over threads): results in the items' order, the
longest items first, one BLAS thread in every worker, and an exception that cancels the rest."""

import threading
import time

import pytest
from threadpoolctl import threadpool_info

from armaxmodal.estimate.pool import parallel_map


class _Bar:
    def __init__(self):
        self.n = 0

    def update(self):
        self.n += 1


def _blas_threads() -> set[int]:
    return {lib["num_threads"] for lib in threadpool_info() if lib["user_api"] == "blas"}


def test_results_come_back_in_the_items_order_from_two_threads():
    items = list(range(12))
    seen = set()

    def square(x):
        seen.add(threading.current_thread().name)
        time.sleep(0.01 * (x % 3))  # items end out of order
        return x * x

    bar = _Bar()
    assert parallel_map(square, items, 2, bar=bar) == [x * x for x in items]
    assert bar.n == len(items)
    assert len(seen) == 2 and all(name.startswith("armaxmodal") for name in seen)


def test_the_costliest_items_start_first():
    started = []
    lock = threading.Lock()

    def record(x):
        with lock:
            started.append(x)
        return x

    items = [3, 9, 1, 7, 5]
    assert parallel_map(record, items, 1 + 1, cost=lambda x: x) == items
    # each of the two workers takes the costliest item left when it is free
    assert sorted(started[:2], reverse=True) == [9, 7] and set(started) == set(items)


def test_few_items_or_one_job_run_in_this_thread():
    main = threading.current_thread().name
    assert parallel_map(lambda x: threading.current_thread().name, [1, 2, 3], 2) == [main] * 3
    assert parallel_map(lambda x: threading.current_thread().name, list(range(6)), 1) == [main] * 6


@pytest.mark.skipif(not _blas_threads(), reason="no BLAS library that threadpoolctl can see")
def test_every_worker_runs_with_one_blas_thread_and_the_callers_count_comes_back():
    before = _blas_threads()
    barrier = threading.Barrier(2)

    def count(_):
        barrier.wait(timeout=10)  # both workers inside at once
        return _blas_threads()

    assert parallel_map(count, list(range(4)), 2) == [{1}] * 4
    assert _blas_threads() == before


def test_an_exception_cancels_the_items_not_started_and_is_raised_here():
    ran = []

    def fail_on_first(x):
        ran.append(x)
        if x == 0:
            raise ValueError("item 0 is bad")
        time.sleep(0.05)
        return x

    with pytest.raises(ValueError, match="item 0 is bad"):
        parallel_map(fail_on_first, list(range(40)), 2)
    assert len(ran) < 10  # the pool stopped instead of running all 40
