"""Local worker processes with a per-file deadline, and a file run in a killable child process.

The main process watches every worker: one that exceeds the time limit is terminated (then
killed) and replaced, one that dies is reported ``"crashed"`` and replaced.
(``concurrent.futures.ProcessPoolExecutor`` cannot cancel a running task and breaks entirely
when one worker dies, hence this small scheduler.)
"""

from __future__ import annotations

import contextlib
import json
import multiprocessing
import multiprocessing.connection
import os
import select
import signal
import subprocess
import sys
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import asdict
from typing import Any

from .plan import default_jobs
from .tasks import CRASHED, DEFAULT_RUNNER, INTERRUPTED, OK, TIMEOUT, FileTask, empty_row
from .work import _fail, _resolve, completed_row, discard_partial, run_file

#: seconds a fresh worker process may take to import meshvis before it counts as crashed
STARTUP_LIMIT = 300.0
#: seconds a terminated worker gets to clean up before it is killed
TERMINATE_GRACE = 3.0


class _Terminated(SystemExit):
    """Raised in a worker by SIGTERM so that ``finally`` blocks (temp file removal) run."""


def _on_sigterm(signum, frame):  # pragma: no cover - runs in the worker
    raise _Terminated(143)


def _preload(runner: str = DEFAULT_RUNNER) -> None:
    """Import the heavy modules once, before the first deadline starts."""
    with contextlib.suppress(Exception):
        _resolve(runner)
    import meshvis.graphcut.classify  # noqa: F401
    import meshvis.io  # noqa: F401


def _worker_main(conn, threads: int | None, runner: str) -> None:  # pragma: no cover - child process
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the main process decides what Ctrl-C stops
    signal.signal(signal.SIGTERM, _on_sigterm)
    if threads:
        os.environ.setdefault("MESHVIS_THREADS", str(threads))
    try:
        _preload(runner)
        conn.send(("ready", None))
        while True:
            task = conn.recv()
            if task is None:
                break
            conn.send(("done", run_file(task)))
    except (EOFError, OSError, _Terminated, KeyboardInterrupt):
        pass


@contextlib.contextmanager
def _sigint_ignored():
    """Ignore Ctrl-C in this block (main thread only): children started here inherit it."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


class _Worker:
    """One worker process with a pipe, its state and its current task."""

    def __init__(self, ctx, threads: int | None, runner: str):
        self.conn, child = ctx.Pipe()
        self.proc = ctx.Process(
            target=_worker_main, args=(child, threads, runner), daemon=True, name="meshvis-batch-worker"
        )
        with _sigint_ignored():  # a Ctrl-C during the child's start-up must not print a traceback there
            self.proc.start()
        child.close()
        self.state = "starting"
        self.since = time.monotonic()
        self.index: int | None = None

    def deadline(self, time_limit: float | None) -> float | None:
        if self.state == "starting":
            return self.since + STARTUP_LIMIT
        if self.state == "busy" and time_limit is not None:
            return self.since + time_limit
        return None

    def stop(self) -> None:
        """Terminate (SIGTERM, so it can remove its temporary files), then kill."""
        if self.proc.is_alive():
            self.proc.terminate()
            self.proc.join(TERMINATE_GRACE)
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join(5.0)
        self.conn.close()

    def close(self) -> None:
        with contextlib.suppress(OSError):
            self.conn.send(None)
        self.proc.join(5.0)
        self.stop()


def _exit_text(code: int | None) -> str:
    if code is None:
        return "did not stop"
    if code < 0:
        with contextlib.suppress(ValueError):
            return f"killed by {signal.Signals(-code).name}"
    return f"exit code {code}"


#: worker processes that may fail to start in a row before the batch gives up
_START_ATTEMPTS = 3


def _start_tasks(workers: list[_Worker], queue: deque, tasks: list[FileTask], on_start: Callable) -> None:
    """Hand the next queued tasks to the idle workers."""
    for w in workers:
        if w.state == "idle" and queue:
            i = queue.popleft()
            w.conn.send(tasks[i])
            w.state, w.index, w.since = "busy", i, time.monotonic()
            on_start(i)


def _wait(workers: list[_Worker], time_limit: float | None) -> None:
    """Sleep until a worker says something or dies, or the next deadline passes."""
    deadlines = [d for d in (w.deadline(time_limit) for w in workers) if d is not None]
    timeout = max(0.0, min(deadlines) - time.monotonic()) if deadlines else None
    multiprocessing.connection.wait([w.conn for w in workers] + [w.proc.sentinel for w in workers], timeout)


def _news(w: _Worker, time_limit: float | None, now: float) -> tuple[str | None, Any]:
    """What happened to worker ``w``.

    Returns ``("ready" | "done", payload)``, ``("dead" | "timeout", None)``, or
    ``(None, None)`` while it works within its deadline.
    """
    kind = payload = None
    try:
        if w.conn.poll():
            kind, payload = w.conn.recv()
    except (EOFError, OSError):
        kind = "dead"
    if kind is None:
        if not w.proc.is_alive():
            kind = "dead"
        elif (d := w.deadline(time_limit)) is not None and now >= d:
            kind = "timeout"
    return kind, payload


def _lost_row(w: _Worker, task: FileTask, kind: str, time_limit: float | None, now: float) -> dict:
    """The row of a task whose (stopped) worker timed out or died."""
    row = empty_row(task)
    row["seconds"] = round(now - w.since, 3)
    if kind == "timeout":
        _fail(task, row, TIMEOUT, f"{task.input}: stopped after the time limit of {time_limit:g} s")
    else:
        _fail(task, row, CRASHED, f"{task.input}: the worker process died ({_exit_text(w.proc.exitcode)})")
    return row


def _stopped(task: FileTask, index: int, rows: list[dict], on_done: Callable) -> None:
    """Row of a task whose worker was stopped.

    ``ok`` when its output and ``ok`` report were complete (it finished before its message
    was read), else ``interrupted``, with the partial files removed.
    """
    row = completed_row(task)
    if row is not None:
        row["status"] = OK
        rows[index] = row
        on_done(index, row)
        return
    discard_partial(task)
    rows[index] = empty_row(task, INTERRUPTED, f"{task.input}: interrupted")


def _interrupt(workers: list[_Worker], tasks: list[FileTask], rows: list[dict], on_done: Callable) -> None:
    """Ctrl-C or SIGTERM: stop every worker; their tasks are done or interrupted (:func:`_stopped`)."""
    with _sigint_ignored():
        for w in workers:
            w.stop()
            if w.index is not None:
                _stopped(tasks[w.index], w.index, rows, on_done)
        workers.clear()


def _run_local(
    tasks: list[FileTask],
    todo: list[int],
    rows: list[dict],
    jobs: int,
    time_limit: float | None,
    on_start: Callable,
    on_done: Callable,
) -> bool:
    """Run the tasks ``todo`` on ``jobs`` worker processes; return True if interrupted."""
    ctx = multiprocessing.get_context("spawn")
    cores = default_jobs(10**6)
    threads = max(1, cores // jobs)
    runner = tasks[todo[0]].runner if todo else DEFAULT_RUNNER
    queue = deque(todo)
    workers: list[_Worker] = []
    failed_starts = 0
    try:
        while queue or any(w.state == "busy" for w in workers):
            n_busy = sum(w.state == "busy" for w in workers)
            while len(workers) < min(jobs, len(queue) + n_busy):
                workers.append(_Worker(ctx, threads, runner))
            _start_tasks(workers, queue, tasks, on_start)
            _wait(workers, time_limit)
            now = time.monotonic()
            for w in list(workers):
                kind, payload = _news(w, time_limit, now)
                if kind is None:
                    continue
                if kind == "ready":
                    w.state = "idle"
                    failed_starts = 0
                elif kind == "done":
                    rows[w.index] = payload
                    on_done(w.index, payload)
                    w.state, w.index = "idle", None
                else:
                    was_starting = w.state == "starting"
                    w.stop()
                    workers.remove(w)
                    if w.index is not None:
                        rows[w.index] = row = _lost_row(w, tasks[w.index], kind, time_limit, now)
                        on_done(w.index, row)
                    elif was_starting:
                        failed_starts += 1
                        if failed_starts >= _START_ATTEMPTS:
                            raise RuntimeError(
                                f"batch worker processes fail to start ({_exit_text(w.proc.exitcode)})"
                            )
        return False
    except KeyboardInterrupt:
        _interrupt(workers, tasks, rows, on_done)
        return True
    finally:
        with _sigint_ignored():
            for w in workers:
                w.close()


def run_file_limited(task: FileTask, time_limit: float | None = None, threads: int | None = None) -> dict:
    """:func:`run_file`, in a child process killed after ``time_limit`` seconds when one is given."""
    if time_limit is None:
        return run_file(task)
    return run_file_isolated(task, time_limit, threads)


def run_file_isolated(task: FileTask, time_limit: float, threads: int | None = None) -> dict:
    """Run :func:`run_file` in a fresh Python process and kill it after ``time_limit`` seconds.

    The limit starts once the child has imported meshvis (it says ``ready``), as for the
    local workers.  Usable where ``multiprocessing`` is not (daemonic Dask workers).
    """
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([p for p in sys.path if p] + [env.get("PYTHONPATH", "")]).rstrip(
        os.pathsep
    )
    if threads:
        env.setdefault("MESHVIS_THREADS", str(threads))
    # the child drops the working folder ('') from sys.path first: a meshvis/ folder there
    # (a source checkout) must not shadow the installed package
    code = "import sys; sys.path[:] = [p for p in sys.path if p]; from meshvis.batch.workers import _task_main; _task_main()"
    cmd = [sys.executable, "-c", code]
    proc = subprocess.Popen(
        cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, env=env, bufsize=0
    )
    row = empty_row(task)
    t0 = time.monotonic()
    try:
        proc.stdin.write(json.dumps(asdict(task)).encode())
        proc.stdin.close()
        proc.stdin = None
        ready, _, _ = select.select([proc.stdout], [], [], STARTUP_LIMIT)
        if not ready or proc.stdout.readline() != b"ready\n":
            proc.kill()
            proc.wait()
            return _fail(
                task,
                row,
                CRASHED,
                f"{task.input}: the worker process did not start ({_exit_text(proc.returncode)})",
            )
        t0 = time.monotonic()
        try:
            out, _ = proc.communicate(timeout=time_limit)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.communicate()
            row["seconds"] = round(time.monotonic() - t0, 3)
            return _fail(
                task, row, TIMEOUT, f"{task.input}: stopped after the time limit of {time_limit:g} s"
            )
    except BaseException:
        proc.kill()
        proc.wait()
        discard_partial(task)
        raise
    lines = out.decode("utf-8", "replace").strip().splitlines()
    try:
        return json.loads(lines[-1])
    except (IndexError, ValueError):
        row["seconds"] = round(time.monotonic() - t0, 3)
        return _fail(
            task, row, CRASHED, f"{task.input}: the worker process died ({_exit_text(proc.returncode)})"
        )


def _task_main() -> None:  # pragma: no cover - child process of run_file_isolated
    signal.signal(signal.SIGTERM, _on_sigterm)
    task = FileTask(**json.loads(sys.stdin.read()))
    _preload(task.runner)
    sys.stdout.write("ready\n")
    sys.stdout.flush()
    row = run_file(task)
    sys.stdout.write(json.dumps(row) + "\n")
    sys.stdout.flush()
