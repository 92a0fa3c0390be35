"""One file of a batch: load, repair, write the output and its report, and the resume check.

:func:`run_file` never raises for a bad file: the row it returns says what went wrong.
"""

from __future__ import annotations

import contextlib
import glob
import importlib
import json
import os
import time
import traceback
import warnings
from collections.abc import Callable
from dataclasses import replace
from typing import Any

from meshvis.errors import MeshvisError, OutputError
from meshvis.io import one_line
from meshvis.io._common import temp_prefix

from .tasks import ERROR, OK, SKIPPED, FileTask, empty_row


def _resolve(runner: str) -> Callable:
    module, _, name = runner.partition(":")
    return getattr(importlib.import_module(module), name)


def operation_args(task: FileTask) -> dict:
    """Every option of the task's operation, with its input and output paths.

    The library defaults (:func:`meshvis.repair.operation.default_options`, which the
    single-file command uses too) are updated with the task's options.
    """
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
    """Every ray the operation's report counts (None when it counts none).

    The cut's, the search by sight's, the rescue pass's and the self-check's.
    """
    counts: list[int] = []
    c = report.get("classification", report)
    if isinstance(c, dict) and isinstance(c.get("rays"), (int, float)):
        counts += [int(c["rays"]), int(c.get("reverse_rays", 0)), int(c.get("hint_rays", 0))]
    searches = [report.get("view"), *report.get("searches", [])]
    counts += [
        int(v["rays"]["total"]) for v in searches if isinstance(v, dict) and isinstance(v.get("rays"), dict)
    ]
    checks = [report.get("rescue"), report.get("self_check")]
    counts += [
        int(v["rays"]) for v in checks if isinstance(v, dict) and isinstance(v.get("rays"), (int, float))
    ]
    return sum(counts) if counts else None


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
    from meshvis.io.jsonfile import read_json

    try:
        data = read_json(path)
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
    stem = os.path.splitext(os.path.basename(task.output))[0]
    # a long name is cut to the same length in every temporary name of the folder
    kept = len(temp_prefix(task.output)) - 2
    if len(stem) >= kept:
        patterns = [f".{glob.escape(stem[:kept])}.*.tmp"]
    else:
        patterns = [f".{glob.escape(stem)}.*.tmp", f".{glob.escape(stem)}_*.tmp"]
    for pattern in patterns:
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
        The file, its operation and its options.

    Returns
    -------
    dict
        The summary row, with the keys :data:`COLUMNS`.
    """
    from meshvis.io import check_output, load
    from meshvis.io.writing import check_not_read

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
            for path in (task.output, task.report):  # never over a texture of the input
                check_not_read(path, soup)
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
    prev = rep.get("batch")
    if not isinstance(prev, dict) or not isinstance(prev.get("options"), dict):
        return None
    if _effective(task, prev["options"]) != _effective(task, task.options):
        return None
    row = empty_row(task, SKIPPED)
    # a report edited by hand must not carry text into a number column (or the reverse)
    for key, kinds in _RESUMED.items():
        value = prev.get(key)
        if isinstance(value, kinds) and not isinstance(value, bool):
            row[key] = value
    return row


#: the columns a resumed row takes from the earlier report, with their types
_RESUMED = {"faces_in": int, "faces_out": int, "rays": int, "seconds": (int, float), "warnings": str}
