"""Batch processing: one repair operation over many model files, on one machine or a Dask cluster.

The unit of work is a :class:`FileTask` (one input file, its output paths, the operation
and its options).  :func:`run_file` performs it — load, classify, orient / remove the
interior / peel layers, write the output and a JSON report — and returns one *summary
row* (a flat dict, see :data:`COLUMNS`).  It never raises for a bad file: the row says
what went wrong.  The operation itself is the same code path as the single-file
commands (:func:`meshvis.repair.operation.run_operation` by default), so a batch output is
byte for byte the output of ``meshvis <op> FILE``.

Where the tasks run
-------------------
* **Locally** (:func:`run_batch` without ``scheduler``): ``jobs`` worker processes
  (``spawn`` start method), each handling one file at a time.  The main process watches
  every worker with a deadline: a worker that exceeds the per-file ``time_limit`` is
  terminated (then killed) and replaced, and its file is reported ``"timeout"``; a worker
  that dies (segfault, out-of-memory kill) is reported ``"crashed"`` and replaced.  Neither
  can stop or hang the batch.  (``concurrent.futures.ProcessPoolExecutor`` cannot cancel a
  running task and breaks entirely when one worker dies, hence the small scheduler here.)
* **On a Dask cluster** (``scheduler="tcp://host:8786"``): the same :func:`run_file`
  is submitted through ``dask.distributed.Client``.  Workers read the inputs and write
  the outputs themselves, so paths must be the same on every machine (shared file
  system).  With a time limit, each file runs in a child process of the Dask worker
  (:func:`run_file_isolated`) that is killed when the limit is reached.

Outputs
-------
``DIR/<input path relative to its folder, without extension>.<op>.<ext>`` and
``DIR/<...>.<op>.report.json`` (see :func:`plan`).  Every file is written through
:func:`meshvis.io.atomic_write` (temporary file, then rename); when a task is stopped
(time limit, crash, Ctrl-C) its temporary files are removed and an output left without
its report is deleted, so ``DIR`` never holds a partial result.  The report of a
successful file has ``"status": "ok"``; ``resume`` skips files whose output exists and
whose report says ``ok`` for the same operation and options and is newer than the input.

Modules: :mod:`.tasks` (the task, its row, the statuses), :mod:`.plan` (discovery and
output names), :mod:`.work` (one file, resume), :mod:`.workers` (local workers, isolated
child processes), :mod:`.cluster` (Dask), :mod:`.run` (the driver), :mod:`.summary`.  The
public names are re-exported here.
"""

from __future__ import annotations

from .cluster import DASK_CONNECT_TIMEOUT
from .plan import default_jobs, discover, output_extension, plan
from .run import largest_first, run_batch
from .summary import write_summary
from .tasks import (
    COLUMNS,
    CRASHED,
    DEFAULT_RUNNER,
    ERROR,
    INTERRUPTED,
    NOT_RUN,
    OK,
    OPERATIONS,
    SKIPPED,
    SUCCESS,
    TIMEOUT,
    BatchResult,
    FileTask,
    empty_row,
)
from .work import completed_row, discard_partial, operation_args, report_status, run_file
from .workers import STARTUP_LIMIT, TERMINATE_GRACE, run_file_isolated, run_file_limited

__all__ = [
    "BatchResult",
    "COLUMNS",
    "CRASHED",
    "DEFAULT_RUNNER",
    "ERROR",
    "FileTask",
    "INTERRUPTED",
    "NOT_RUN",
    "OK",
    "OPERATIONS",
    "SKIPPED",
    "SUCCESS",
    "TIMEOUT",
    "empty_row",
    "default_jobs",
    "discover",
    "output_extension",
    "plan",
    "completed_row",
    "discard_partial",
    "operation_args",
    "report_status",
    "run_file",
    "STARTUP_LIMIT",
    "TERMINATE_GRACE",
    "run_file_isolated",
    "run_file_limited",
    "DASK_CONNECT_TIMEOUT",
    "largest_first",
    "run_batch",
    "write_summary",
]
