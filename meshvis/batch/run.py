"""The batch driver: resume, largest files first, local workers or a Dask cluster."""

from __future__ import annotations

import os
import time
from collections.abc import Callable, Sequence

from meshvis.errors import ParameterError

from .cluster import _run_dask
from .plan import default_jobs
from .tasks import BatchResult, FileTask, empty_row
from .work import completed_row
from .workers import _run_local


def largest_first(tasks: Sequence[FileTask], todo: list[int]) -> list[int]:
    """``todo`` ordered by input file size, largest first (ties: task order).

    Starting the longest files first keeps one big model from finishing alone at the
    end (longest-processing-time-first scheduling); file size stands in for time.
    """

    def size(i: int) -> int:
        try:
            return os.path.getsize(tasks[i].input)
        except OSError:
            return 0

    return sorted(todo, key=lambda i: (-size(i), i))


def run_batch(
    tasks: Sequence[FileTask],
    *,
    jobs: int | None = None,
    time_limit: float | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    on_start: Callable[[int], None] | None = None,
    on_done: Callable[[int, dict], None] | None = None,
) -> BatchResult:
    """Run every task, locally or on a Dask cluster.

    Parameters
    ----------
    tasks : sequence of FileTask
        The files, from :func:`plan`.
    jobs : int, optional
        Local worker processes (default :func:`default_jobs`); ignored with ``scheduler``.
    time_limit : float, optional
        Seconds per file (None: no limit); a file that exceeds it is ``"timeout"``.
    scheduler : str, optional
        Address of a Dask scheduler (``tcp://host:8786``), or None to run locally.
    resume : bool
        Skip tasks that are complete from an earlier run (see :func:`completed_row`).
    on_start : callable, optional
        Called as ``on_start(index)`` when a task is handed to a worker.
    on_done : callable, optional
        Called as ``on_done(index, row)`` when a task ends (also for skipped tasks).

    Returns
    -------
    BatchResult
        One row per task in task order (the tasks themselves start largest input file
        first, see :func:`largest_first`).  Ctrl-C stops the batch cleanly: running tasks are
        stopped, their partial files removed, ``interrupted`` is set, and unfinished rows
        have status ``"interrupted"`` or ``"not run"``.

    Raises
    ------
    ParameterError
        Bad ``jobs`` / ``time_limit``, no Dask, or no connection to the scheduler.
    """
    if jobs is not None and jobs < 1:
        raise ParameterError(f"jobs must be at least 1, got {jobs}")
    if time_limit is not None and not time_limit > 0:
        raise ParameterError(f"the time limit must be positive, got {time_limit}")
    tasks = list(tasks)
    on_start = on_start or (lambda i: None)
    on_done = on_done or (lambda i, row: None)
    t0 = time.perf_counter()
    rows = [empty_row(t) for t in tasks]
    todo = []
    interrupted = False
    try:
        for i, task in enumerate(tasks):
            prev = completed_row(task) if resume else None
            if prev is not None:
                rows[i] = prev
                on_done(i, prev)
            else:
                todo.append(i)
    except KeyboardInterrupt:
        return BatchResult(rows=rows, seconds=time.perf_counter() - t0, interrupted=True)
    if todo:
        todo = largest_first(tasks, todo)
        if scheduler:
            interrupted = _run_dask(tasks, todo, rows, scheduler, time_limit, on_start, on_done)
        else:
            interrupted = _run_local(
                tasks, todo, rows, jobs or default_jobs(len(todo)), time_limit, on_start, on_done
            )
    return BatchResult(rows=rows, seconds=time.perf_counter() - t0, interrupted=interrupted)
