"""How many threads meshvis' threaded stages use: ``MESHVIS_THREADS`` or the core count."""

from __future__ import annotations

import os


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
