"""Batch processing: one repair operation over many model files, on one machine or a Dask cluster.

The unit of work is a :class:`FileTask` (one input file, its output paths, the operation
and its options).  :func:`run_file` performs it — load, classify, orient / remove the
interior / peel layers, write the output and a JSON report — and returns one *summary
row* (a flat dict, see :data:`COLUMNS`).  It never raises for a bad file: the row says
what went wrong.  The operation itself is the same code path as the single-file
commands (:func:`meshvis.repair.operation.run_operation` by default), so a batch output is byte for byte the
output of ``meshvis <op> FILE``.

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
"""

from __future__ import annotations

import contextlib
import csv
import glob
import importlib
import io
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
import traceback
import uuid
import warnings
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass, field, replace
from typing import Any

from meshvis.errors import MeshvisError, OutputError, ParameterError
from meshvis.io import READ_FORMATS, WRITE_FORMATS, atomic_write, one_line

#: operations a batch can run
OPERATIONS = ("orient", "remove-interior", "layers")
#: the per-file operation: ``module:function`` called as ``f(op, soup, options, progress) -> report``
DEFAULT_RUNNER = "meshvis.repair.operation:run_operation"
#: columns of a summary row, in the order of ``summary.csv``
COLUMNS = (
    "input",
    "status",
    "error",
    "faces_in",
    "faces_out",
    "rays",
    "seconds",
    "output",
    "report",
    "warnings",
)
#: statuses of a summary row; the first two count as success
OK, SKIPPED, ERROR, TIMEOUT, CRASHED, INTERRUPTED, NOT_RUN = (
    "ok",
    "skipped",
    "error",
    "timeout",
    "crashed",
    "interrupted",
    "not run",
)
SUCCESS = (OK, SKIPPED)
#: seconds a fresh worker process may take to import meshvis before it counts as crashed
STARTUP_LIMIT = 300.0
#: seconds a terminated worker gets to clean up before it is killed
TERMINATE_GRACE = 3.0
#: how long to try reaching a Dask scheduler
DASK_CONNECT_TIMEOUT = "15s"


# ------------------------------------------------------------------------------- tasks
@dataclass
class FileTask:
    """One file of a batch.

    Attributes
    ----------
    input : path of the model file
    name : output name without operation and extension (relative to the output folder)
    output, report : paths of the output model and of its JSON report
    op : one of :data:`OPERATIONS`
    options : algorithm options (``seed``, ``rays_per_node``, ...: the ``dest`` names of
        the command-line options); the others keep the defaults of ``meshvis <op>``
    runner : ``module:function`` performing the operation (see :data:`DEFAULT_RUNNER`)
    """

    input: str
    name: str
    output: str
    report: str
    op: str
    options: dict = field(default_factory=dict)
    runner: str = DEFAULT_RUNNER


@dataclass
class BatchResult:
    """Rows of a batch in task order, its wall time, and whether it was interrupted."""

    rows: list[dict]
    seconds: float
    interrupted: bool = False

    @property
    def counts(self) -> dict[str, int]:
        out: dict[str, int] = {}
        for r in self.rows:
            out[r["status"]] = out.get(r["status"], 0) + 1
        return out

    @property
    def ok(self) -> bool:
        """True when every file succeeded (or was skipped as already done)."""
        return not self.interrupted and all(r["status"] in SUCCESS for r in self.rows)


def empty_row(task: FileTask, status: str = NOT_RUN, error: str = "") -> dict:
    """A summary row for ``task`` with nothing measured yet."""
    return {
        "input": task.input,
        "status": status,
        "error": error,
        "faces_in": None,
        "faces_out": None,
        "rays": None,
        "seconds": None,
        "output": task.output,
        "report": task.report,
        "warnings": "",
    }


# --------------------------------------------------------------------------- discovery
def _is_output_name(filename: str) -> bool:
    """True for files a batch writes (``x.<op>.<ext>``): never picked up as inputs."""
    stem = os.path.splitext(filename)[0]
    return any(stem.endswith("." + op) or stem.endswith(f".{op}.report") for op in OPERATIONS)


def _is_model_name(filename: str) -> bool:
    return (
        not filename.startswith(".")
        and os.path.splitext(filename)[1].lower() in READ_FORMATS
        and not _is_output_name(filename)
    )


def _walk(folder: str) -> list[str]:
    """Model files below ``folder``, sorted, hidden files and folders skipped."""
    found = []
    for root, dirs, files in os.walk(folder):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        found += [os.path.join(root, f) for f in sorted(files) if _is_model_name(f)]
    return found


def _glob_base(pattern: str) -> str:
    """The leading folders of a glob pattern that hold no wildcard."""
    parts = pattern.split(os.sep)
    keep = []
    for p in parts[:-1]:
        if glob.has_magic(p):
            break
        keep.append(p)
    return os.sep.join(keep) if keep else "."


def discover(inputs: Sequence[str]) -> list[tuple[str, str]]:
    """Expand files, folders and glob patterns into model files.

    Parameters
    ----------
    inputs : paths of files (taken as they are, whatever their extension), folders
        (searched recursively for files with a known model extension) and glob patterns
        (``*``, ``?``, ``[...]``; ``**`` spans folders).  Hidden files and folders, and
        files named like batch outputs (``*.orient.*``, ``*.remove-interior.*``,
        ``*.layers.*``), are skipped in folders and patterns.

    Returns
    -------
    list of (path, relative path)
        In input order, each folder's files sorted, duplicates (same real file) dropped.
        The relative path is the file name for a file, the path below the folder for a
        folder, and the path below the pattern's fixed leading folders for a pattern.

    Raises
    ------
    ParameterError
        An input that is neither a file nor a folder nor a pattern matching a model file.
    """
    out: list[tuple[str, str]] = []
    seen: set[str] = set()

    def add(path: str, rel: str) -> None:
        key = os.path.realpath(path)
        if key not in seen:
            seen.add(key)
            out.append((path, rel))

    for spec in inputs:
        spec = os.fspath(spec)
        if os.path.isdir(spec):
            files = _walk(spec)
            if not files:
                raise ParameterError(
                    f"{spec}: no model files in this folder "
                    f"(known extensions: {', '.join(sorted(READ_FORMATS))})"
                )
            for f in files:
                add(f, os.path.relpath(f, spec))
        elif os.path.lexists(spec):
            add(spec, os.path.basename(spec))
        elif glob.has_magic(spec):
            base = _glob_base(spec)
            matched = False
            for m in sorted(glob.glob(spec, recursive=True)):
                files = _walk(m) if os.path.isdir(m) else [m] if _is_model_name(os.path.basename(m)) else []
                for f in files:
                    add(f, os.path.relpath(f, base))
                matched = matched or bool(files)
            if not matched:
                raise ParameterError(f"{spec}: the pattern matches no model file")
        else:
            raise ParameterError(f"{spec}: no such file or folder")
    return out


def output_extension(path: str, op: str) -> str:
    """Extension of the output of ``op`` for input ``path``: the input's, unless it cannot hold the result.

    3MF (no writer) becomes ``.glb``, which keeps parts and materials; layers of an STL
    or OFF file become ``.ply``, whose face properties hold the layer of every face.
    """
    ext = os.path.splitext(path)[1]
    low = ext.lower()
    if low in READ_FORMATS and low not in WRITE_FORMATS:
        return ".glb"
    if op == "layers" and low in (".stl", ".off"):
        return ".ply"
    return ext


def plan(
    inputs: Sequence[str], op: str, out_dir: str, options: dict | None = None, runner: str = DEFAULT_RUNNER
) -> list[FileTask]:
    """Make the tasks of a batch: which file goes where.

    Output names are ``<relative path without extension>.<op>.<ext>`` (see
    :func:`discover`, :func:`output_extension`).  When two inputs would share an output
    name only because their extensions differ (``x.obj`` and ``x.stl``), both keep their
    extension in the name (``x.obj.<op>.obj``); any other clash (``a/y.obj`` and ``b/y.obj``
    given as files) gets ``-2``, ``-3``, ... in input order.

    Raises
    ------
    ParameterError
        Unknown operation, inputs not found (see :func:`discover`), or an output that
        would overwrite one of the inputs.
    """
    if op not in OPERATIONS:
        raise ParameterError(f"unknown operation {op!r}; choose one of {', '.join(OPERATIONS)}")
    found = discover(inputs)
    names = [os.path.splitext(rel)[0] for _, rel in found]
    count: dict[str, int] = {}
    for key in [n.casefold() for n in names] + [rel.casefold() for _, rel in found]:
        count[key] = count.get(key, 0) + 1
    # x.obj next to x.stl: keep the extensions in the names; the same name twice: numbered below
    names = [
        rel if count[n.casefold()] > 1 and count[rel.casefold()] == 1 else n
        for n, (_, rel) in zip(names, found)
    ]
    used: set[str] = set()
    tasks = []
    in_paths = {os.path.realpath(p) for p, _ in found}
    for (path, _), name in zip(found, names):
        base, k = name, 1
        while name.casefold() in used:
            k += 1
            name = f"{base}-{k}"
        used.add(name.casefold())
        stem = os.path.join(out_dir, f"{name}.{op}")
        task = FileTask(
            path,
            name,
            stem + output_extension(path, op),
            stem + ".report.json",
            op,
            dict(options or {}),
            runner,
        )
        for p in (task.output, task.report):
            if os.path.realpath(p) in in_paths:
                raise ParameterError(
                    f"{p}: the output of {path} would overwrite an input file; choose another --out"
                )
        tasks.append(task)
    return tasks


def default_jobs(n_tasks: int) -> int:
    """Worker processes by default: one per core, no more than there are files."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return max(1, min(cores, n_tasks))


# ----------------------------------------------------------------------- one file
def _resolve(runner: str) -> Callable:
    module, _, name = runner.partition(":")
    return getattr(importlib.import_module(module), name)


def operation_args(task: FileTask) -> dict:
    """Every option of the task's operation: the library defaults
    (:func:`meshvis.repair.operation.default_options`, which the single-file command uses too)
    updated with the task's options, plus its input and output paths."""
    from meshvis.repair.operation import default_options

    ns = {**default_options(task.op), **task.options}
    ns.update(
        input=task.input,
        output=task.output,
        op=task.op,
        report=None,
        preview=None,
        removed=None,
        graphml=None,
    )
    return ns


def _effective(task: FileTask, options: dict) -> dict:
    """Every option of the operation, defaults filled in, as JSON would store them."""
    return operation_args(replace(task, options=json.loads(json.dumps(options))))


def _rays(report: dict) -> int | None:
    c = report.get("classification", report)
    try:
        return int(c["rays"]) + int(c.get("reverse_rays", 0)) + int(c.get("hint_rays", 0))
    except (KeyError, TypeError, ValueError):
        return None


def _faces_out(report: dict, faces_in: int) -> int:
    for key in ("output_faces", "kept_faces"):
        if key in report:
            return int(report[key])
    return faces_in  # layers: every face is written


def _write_json(path: str, data: Any) -> None:
    from meshvis.io.jsonfile import write_json

    write_json(path, data)


def _remove(path: str) -> None:
    with contextlib.suppress(OSError):
        os.unlink(path)


def report_status(path: str) -> dict | None:
    """The report at ``path`` if it is complete JSON, else None."""
    try:
        with open(path, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def discard_partial(task: FileTask) -> None:
    """Remove what a stopped task may have left: temporary files, an output without its report.

    Temporary files of :func:`meshvis.io.atomic_write` are named ``.<file>.<random>.tmp``;
    those of the task's output, report, MTL and textures all start with
    ``.<name>.<op>`` in the output's folder.
    """
    folder = os.path.dirname(task.output) or "."
    stem = glob.escape(os.path.splitext(os.path.basename(task.output))[0])
    for pattern in (f".{stem}.*.tmp", f".{stem}_*.tmp"):
        for p in glob.glob(os.path.join(folder, pattern)):
            _remove(p)
    rep = report_status(task.report)
    if rep is None or rep.get("status") != OK:
        _remove(task.output)


def _fail(task: FileTask, row: dict, status: str, error: str, detail: str | None = None) -> dict:
    """Mark ``row`` failed, write an error report, remove the task's output."""
    row.update(status=status, error=error)
    discard_partial(task)
    _remove(task.output)
    data = {
        "status": status,
        "error": error,
        "input": task.input,
        "operation": task.op,
        "batch": {**row, "options": task.options},
    }
    if detail:
        data["traceback"] = detail
    with contextlib.suppress(Exception):
        _write_json(task.report, data)
    return row


def run_file(task: FileTask) -> dict:
    """Process one file; never raises for a bad file.

    Loads ``task.input``, runs the operation (``task.runner``), writes ``task.output``
    and ``task.report`` (the operation's report plus ``"status": "ok"`` and the summary
    row under ``"batch"``), and returns the summary row.  On failure the row has
    ``status="error"`` and a one-line ``error`` naming the file; the report then holds
    the error (and the traceback of an unexpected exception) and no output is left.
    Warnings (skipped records, ...) are collected into the row's ``warnings``.

    Parameters
    ----------
    task : FileTask

    Returns
    -------
    dict with the keys :data:`COLUMNS`
    """
    from meshvis.io import check_output, load

    row = empty_row(task, ERROR)
    t0 = time.perf_counter()
    caught: list = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            for path in (task.output, task.report):
                folder = os.path.dirname(path)
                if folder:
                    try:
                        os.makedirs(folder, exist_ok=True)
                    except OSError as exc:
                        raise OutputError(
                            f"cannot create the folder: {one_line(exc.strerror or exc)}", folder
                        ) from None
                check_output(path, [task.input], True)
            soup = load(task.input)
            row["faces_in"] = soup.n_faces
            report = _resolve(task.runner)(task.op, soup, operation_args(task), None)
            row["faces_out"] = _faces_out(report, soup.n_faces)
            row["rays"] = _rays(report)
            row["status"] = OK
            row["seconds"] = round(time.perf_counter() - t0, 3)
            row["warnings"] = _warning_text(caught)
            report.update(
                status=OK,
                input=task.input,
                seconds_total=time.perf_counter() - t0,
                batch={**row, "options": task.options},
            )
            _write_json(task.report, report)
        return row
    except MeshvisError as exc:
        error, detail = one_line(exc), None
    except MemoryError:
        error, detail = f"{task.input}: out of memory", None
    except OSError as exc:  # the system refused a file operation (I/O error, ...): not a bug
        error, detail = f"{exc.filename or task.input}: {one_line(exc.strerror or exc)}", None
    except Exception as exc:  # a bug: keep the batch going, keep the traceback in the report
        error = f"{task.input}: internal error: {type(exc).__name__}: {one_line(exc)}"
        detail = traceback.format_exc()
    if not error.startswith(task.input):
        error = f"{task.input}: {error}"
    row["seconds"] = round(time.perf_counter() - t0, 3)
    row["warnings"] = _warning_text(caught)
    return _fail(task, row, ERROR, error, detail)


def _warning_text(caught: list) -> str:
    return "; ".join(dict.fromkeys(one_line(w.message) for w in caught or []))


# ------------------------------------------------------------------------ resume
def completed_row(task: FileTask) -> dict | None:
    """The row of a previous run if the task is complete, else None.

    Complete means: output and report exist, the report says ``ok`` for the same
    operation and the same options (defaults filled in), and it is not older than the input.
    """
    try:
        if not (os.path.isfile(task.output) and os.path.isfile(task.report)):
            return None
        if os.path.getmtime(task.input) > os.path.getmtime(task.report):
            return None
    except OSError:
        return None
    rep = report_status(task.report)
    if rep is None or rep.get("status") != OK or rep.get("operation") != task.op:
        return None
    prev = rep.get("batch") or {}
    if not isinstance(prev.get("options"), dict) or _effective(task, prev["options"]) != _effective(
        task, task.options
    ):
        return None
    row = empty_row(task, SKIPPED)
    for key in ("faces_in", "faces_out", "rays", "seconds", "warnings"):
        if key in prev:
            row[key] = prev[key]
    return row


# ---------------------------------------------------------------- local workers
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


def _stopped(task: FileTask, index: int, rows: list[dict], on_done: Callable) -> None:
    """Row of a task whose worker was stopped: ``ok`` when its output and ``ok`` report were
    complete (it finished before its message was read), else ``interrupted``, partial files removed."""
    row = completed_row(task)
    if row is not None:
        row["status"] = OK
        rows[index] = row
        on_done(index, row)
        return
    discard_partial(task)
    rows[index] = empty_row(task, INTERRUPTED, f"{task.input}: interrupted")


def _exit_text(code: int | None) -> str:
    if code is None:
        return "did not stop"
    if code < 0:
        with contextlib.suppress(ValueError):
            return f"killed by {signal.Signals(-code).name}"
    return f"exit code {code}"


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
            for w in workers:
                if w.state == "idle" and queue:
                    i = queue.popleft()
                    w.conn.send(tasks[i])
                    w.state, w.index, w.since = "busy", i, time.monotonic()
                    on_start(i)
            deadlines = [d for d in (w.deadline(time_limit) for w in workers) if d is not None]
            timeout = max(0.0, min(deadlines) - time.monotonic()) if deadlines else None
            multiprocessing.connection.wait(
                [w.conn for w in workers] + [w.proc.sentinel for w in workers], timeout
            )
            now = time.monotonic()
            for w in list(workers):
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
                    else:
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
                        task = tasks[w.index]
                        row = empty_row(task)
                        row["seconds"] = round(now - w.since, 3)
                        if kind == "timeout":
                            _fail(
                                task,
                                row,
                                TIMEOUT,
                                f"{task.input}: stopped after the time limit of {time_limit:g} s",
                            )
                        else:
                            _fail(
                                task,
                                row,
                                CRASHED,
                                f"{task.input}: the worker process died ({_exit_text(w.proc.exitcode)})",
                            )
                        rows[w.index] = row
                        on_done(w.index, row)
                    elif was_starting:
                        failed_starts += 1
                        if failed_starts >= 3:
                            raise RuntimeError(
                                f"batch worker processes fail to start ({_exit_text(w.proc.exitcode)})"
                            )
        return False
    except KeyboardInterrupt:
        with _sigint_ignored():
            for w in workers:
                w.stop()
                if w.index is not None:
                    _stopped(tasks[w.index], w.index, rows, on_done)
            workers.clear()
        return True
    finally:
        with _sigint_ignored():
            for w in workers:
                w.close()


# ---------------------------------------------------------------------- Dask
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
    cmd = [sys.executable, "-c", "from meshvis.batch.runner import _task_main; _task_main()"]
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
    try:
        from distributed import Client, as_completed
    except ImportError:
        raise ParameterError("--dask-scheduler needs dask.distributed: pip install 'meshvis[dask]'") from None
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


# ----------------------------------------------------------------------- driver
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
    tasks : from :func:`plan`
    jobs : local worker processes (default :func:`default_jobs`); ignored with ``scheduler``
    time_limit : seconds per file (None: no limit); an exceeding file is ``"timeout"``
    scheduler : address of a Dask scheduler (``tcp://host:8786``), or None to run locally
    resume : skip tasks that are complete from an earlier run (see :func:`completed_row`)
    on_start : ``on_start(index)`` when a task is handed to a worker
    on_done : ``on_done(index, row)`` when a task ends (also for skipped tasks)

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
        return BatchResult(rows, time.perf_counter() - t0, True)
    if todo:
        todo = largest_first(tasks, todo)
        if scheduler:
            interrupted = _run_dask(tasks, todo, rows, scheduler, time_limit, on_start, on_done)
        else:
            interrupted = _run_local(
                tasks, todo, rows, jobs or default_jobs(len(todo)), time_limit, on_start, on_done
            )
    return BatchResult(rows, time.perf_counter() - t0, interrupted)


def write_summary(result: BatchResult, out_dir: str, meta: dict | None = None) -> tuple[str, str]:
    """Write ``summary.csv`` and ``summary.json`` into ``out_dir`` (atomically); return their paths.

    The CSV has one line per file with the columns :data:`COLUMNS`; the JSON has the same
    rows under ``"files"``, plus ``meta`` (operation, options, ...), the counts per status,
    the wall time and whether the batch was interrupted.
    """
    from meshvis._version import __version__

    csv_path = os.path.join(out_dir, "summary.csv")
    json_path = os.path.join(out_dir, "summary.json")
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(COLUMNS), extrasaction="ignore", lineterminator="\n")
    writer.writeheader()
    for r in result.rows:
        writer.writerow({k: "" if r.get(k) is None else r.get(k) for k in COLUMNS})
    with atomic_write(csv_path, "w") as fh:
        fh.write(buf.getvalue())
    data = {
        "meshvis": __version__,
        **(meta or {}),
        "seconds_total": round(result.seconds, 3),
        "interrupted": result.interrupted,
        "counts": result.counts,
        "files": [{k: r.get(k) for k in COLUMNS} for r in result.rows],
    }
    _write_json(json_path, data)
    return csv_path, json_path
