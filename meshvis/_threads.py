"""Threads of meshvis' threaded stages: how many (``MESHVIS_THREADS`` or the cores), and slices run in them."""

from __future__ import annotations

import os
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor

import numpy as np

#: rows per slice below which :func:`in_threads` cuts fewer slices or makes one call, and
#: slices per thread
THREAD_ROWS = 1 << 14
THREAD_PARTS = 4


def default_threads() -> int:
    """Threads for large batches: the ``MESHVIS_THREADS`` variable or the core count.

    ``meshvis batch`` sets the variable in its workers, so that several workers on one
    machine share its cores instead of each taking all of them.

    Examples
    --------
    >>> default_threads() >= 1
    True
    """
    env = os.environ.get("MESHVIS_THREADS")
    if env:
        return max(1, int(env))
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)


def in_threads(work: Callable[[int, int], object], n: int, rows_per_item: int = 1) -> None:
    """Call ``work(start, stop)`` on slices of ``range(n)``, in threads when ``n`` is large.

    For compiled kernels that release the GIL and write each row of their slice into
    output arrays on their own: the result is the one of ``work(0, n)``.  The threads
    are :func:`default_threads` (``MESHVIS_THREADS`` or the cores), as for the ray
    batches; below ``2 * THREAD_ROWS`` rows there is one call.

    Parameters
    ----------
    work : callable
        ``work(start, stop)`` handles rows ``start .. stop - 1``; its return value is ignored.
    n : int
        Number of rows (items).
    rows_per_item : int
        Rows each item stands for when the slices are sized (an item that is a face
        casting 32 rays is 32 rows of work).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.arange(100_000.0)
    >>> y = np.empty_like(x)
    >>> in_threads(lambda a, b: np.multiply(x[a:b], 2.0, out=y[a:b]), len(x))
    >>> bool((y == 2 * x).all())
    True
    """
    threads = default_threads()
    k = min(THREAD_PARTS * threads, n * rows_per_item // THREAD_ROWS, n)
    if threads < 2 or k < 2:
        work(0, n)
        return
    # a few slices per thread even out the rows that cost more than others
    bounds = np.linspace(0, n, k + 1).astype(np.int64)
    with ThreadPoolExecutor(threads) as pool:
        list(pool.map(work, bounds[:-1], bounds[1:]))
