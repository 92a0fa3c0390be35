"""Threads of meshvis' threaded stages: how many (``MESHVIS_THREADS`` or the cores), and slices run in them."""

from __future__ import annotations

import os
import threading
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

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


#: the pools of :func:`pool`, by process and thread count
_POOLS: dict[tuple[int, int], ThreadPoolExecutor] = {}
_POOLS_LOCK = threading.Lock()
#: set in the threads of those pools: work they run makes no slices of its own
_IN_POOL = threading.local()


def _mark_pool_thread() -> None:
    _IN_POOL.active = True


def pool(threads: int) -> ThreadPoolExecutor | None:
    """A thread pool of ``threads`` threads, kept for the next call; None inside one.

    Starting threads costs about 0.1 ms each, as much as slicing a batch of 64 k rows
    saves, so the pool lives as long as the process.  A process forked from this one
    gets its own pool (the parent's threads do not exist in it).  Work running in a pool
    thread gets None: waiting there for the same pool could leave no thread to run it.

    Examples
    --------
    >>> pool(2) is pool(2)
    True
    """
    if getattr(_IN_POOL, "active", False):
        return None
    key = (os.getpid(), threads)
    with _POOLS_LOCK:
        if key not in _POOLS:
            _POOLS[key] = ThreadPoolExecutor(threads, "meshvis", initializer=_mark_pool_thread)
        return _POOLS[key]


def in_threads(
    work: Callable[[int, int], Any],
    n: int,
    rows_per_item: int = 1,
    *,
    threads: int | None = None,
    rows: int = THREAD_ROWS,
) -> list:
    """Call ``work(start, stop)`` on slices of ``range(n)``, in threads when ``n`` is large.

    For compiled kernels and Embree calls that release the GIL and handle each row of their
    slice on their own: the results are those of ``work(0, n)``, cut at the slices.  Below
    ``2 * rows`` rows there is one call; above, at most :data:`THREAD_PARTS` slices per
    thread, run in the kept pool (:func:`pool`).

    Parameters
    ----------
    work : callable
        ``work(start, stop)`` handles rows ``start .. stop - 1``.
    n : int
        Number of rows (items).
    rows_per_item : int
        Rows each item stands for when the slices are sized (an item that is a face
        casting 32 rays is 32 rows of work).
    threads : int, optional
        Threads to use (default :func:`default_threads`: ``MESHVIS_THREADS`` or the cores).
    rows : int
        The fewest rows worth a slice of their own.

    Returns
    -------
    list
        What ``work`` returned for each slice, in order (one entry when it ran unsliced).

    Examples
    --------
    >>> import numpy as np
    >>> x = np.arange(100_000.0)
    >>> y = np.empty_like(x)
    >>> _ = in_threads(lambda a, b: np.multiply(x[a:b], 2.0, out=y[a:b]), len(x))
    >>> bool((y == 2 * x).all())
    True
    >>> parts = in_threads(lambda a, b: x[a:b].sum(), len(x), threads=2)
    >>> len(parts) > 1, float(sum(parts)) == float(x.sum())
    (True, True)
    """
    threads = default_threads() if threads is None else threads
    k = min(THREAD_PARTS * threads, n * rows_per_item // rows, n)
    workers = pool(threads) if threads > 1 and k > 1 else None
    if workers is None:
        return [work(0, n)]
    # a few slices per thread even out the rows that cost more than others
    bounds = np.linspace(0, n, k + 1).astype(np.int64)
    return list(workers.map(work, bounds[:-1], bounds[1:]))
