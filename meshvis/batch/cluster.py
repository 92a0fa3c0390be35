"""Running the files of a batch on a Dask cluster."""

from __future__ import annotations

import contextlib
import uuid
from collections.abc import Callable

from meshvis.errors import ParameterError
from meshvis.io import one_line

from .tasks import CRASHED, INTERRUPTED, FileTask, empty_row
from .work import _fail
from .workers import _sigint_ignored, run_file_limited

#: how long to try reaching a Dask scheduler
DASK_CONNECT_TIMEOUT = "15s"


def _run_dask(
    tasks: list[FileTask],
    todo: list[int],
    rows: list[dict],
    address: str,
    time_limit: float | None,
    on_start: Callable,
    on_done: Callable,
) -> bool:
    """Submit the tasks to the Dask scheduler at ``address``; return True if interrupted."""
    from meshvis._extras import import_extra

    distributed = import_extra("distributed", "meshvis batch --dask-scheduler")
    Client, as_completed = distributed.Client, distributed.as_completed
    try:
        client = Client(address, timeout=DASK_CONNECT_TIMEOUT, set_as_default=False)
    except (OSError, TimeoutError, ValueError) as exc:
        raise ParameterError(f"cannot connect to the Dask scheduler at {address}: {one_line(exc)}") from None
    futures = {}
    try:
        with client:
            token = uuid.uuid4().hex[:8]
            for i in todo:
                fut = client.submit(
                    run_file_limited, tasks[i], time_limit, key=f"meshvis-batch-{token}-{i}", pure=False
                )
                futures[fut] = i
                on_start(i)
            try:
                for fut in as_completed(list(futures), loop=client.loop):
                    i = futures.pop(fut)
                    try:
                        row = fut.result()
                    except Exception as exc:  # the worker died (KilledWorker) or the task was lost
                        task = tasks[i]
                        row = _fail(
                            task,
                            empty_row(task),
                            CRASHED,
                            f"{task.input}: the task failed on the cluster: {type(exc).__name__}: {one_line(exc)}",
                        )
                    rows[i] = row
                    on_done(i, row)
            except KeyboardInterrupt:
                with _sigint_ignored():
                    with contextlib.suppress(Exception):
                        client.cancel(list(futures))
                    for i in futures.values():
                        rows[i] = empty_row(tasks[i], INTERRUPTED, f"{tasks[i].input}: interrupted")
                return True
    except KeyboardInterrupt:
        return True
    return False
