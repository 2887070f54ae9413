"""One BLAS thread while armaxmodal computes.

Every matrix in a fit is small (at most a few hundred columns) and the long loops are numba
kernels, so BLAS threads do not speed anything up here; on a 2-core machine they slowed a
serial 20,000-sample sweep 3.6x (26.6 s against 7.3 s; the threads spin between the many
short BLAS calls and take the core from the kernel). Parallel work runs on worker threads
(``pool.parallel_map``) instead, each with one BLAS thread. The limit holds only while a
decorated function runs: a user's own numpy keeps its threads.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from typing import TypeVar

_F = TypeVar("_F", bound=Callable)
_controller = None


@contextmanager
def one_blas_thread() -> Iterator[None]:
    """Limit every loaded BLAS (numpy's and scipy's, which numba's ``np.dot`` calls) to one
    thread inside the ``with`` block."""
    global _controller
    if _controller is None:
        import scipy.linalg  # noqa: F401  -- scipy's BLAS must be loaded before the controller looks
        from threadpoolctl import ThreadpoolController

        _controller = ThreadpoolController()  # finding the libraries costs 0.2 ms: do it once
    with _controller.limit(limits=1, user_api="blas"):
        yield


def single_blas_thread(func: _F) -> _F:
    """Decorator: run ``func`` under :func:`one_blas_thread`."""

    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        with one_blas_thread():
            return func(*args, **kwargs)

    return wrapper  # type: ignore[return-value]
