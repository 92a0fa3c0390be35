"""``meshvis batch INPUTS... --op OP --out DIR``: one repair operation over many files.

Exit status: 0 when every file succeeded (or was skipped by ``--resume`` as already
done), 1 when at least one file failed (error, time limit, crashed worker), 2 for a usage
error (bad option, input not found, output folder not writable, no Dask scheduler),
130 when interrupted (Ctrl-C).
"""

from __future__ import annotations

import argparse
import os
import sys
import time

from .common import positive_int, positive_seconds

EPILOG = """\
outputs: DIR/<input path without extension>.<op>.<ext> and DIR/<...>.<op>.report.json,
plus DIR/summary.csv and DIR/summary.json.  Existing outputs are overwritten unless
--resume finds them complete.

exit status: 0 every file ok (or skipped by --resume), 1 some file failed
(error, time limit, crashed worker), 2 usage error, 130 interrupted (Ctrl-C).
"""


def _dests(add_options) -> list[str]:
    """``dest`` names of the options that ``add_options(parser)`` adds."""
    p = argparse.ArgumentParser(add_help=False)
    add_options(p)
    return [a.dest for a in p._actions]


def add_parser(sub) -> None:
    """Add the ``batch`` subcommand to the ``meshvis`` parser.

    Its options are the inputs, ``--op``, ``--out``, ``--jobs``, ``--resume``,
    ``--time-limit``, ``--dask-scheduler``, the graph-cut options of
    :func:`meshvis.cli.cmd_repair.algorithm_options`, the inside-removal options of
    :func:`meshvis.cli.cmd_repair.removal_options` (used with ``--op remove-interior``)
    and ``--quiet``.

    Parameters
    ----------
    sub : argparse._SubParsersAction
        The subcommands of the ``meshvis`` parser; the new parser's ``func`` is :func:`run`.
    """
    from meshvis.batch import OPERATIONS

    from .cmd_repair import algorithm_options, removal_options

    p = sub.add_parser(
        "batch",
        help="run orient / remove-interior / layers over many files (local processes or Dask)",
        description="Run one repair operation over files, folders (recursive) and glob patterns.",
        epilog=EPILOG,
    )
    p.add_argument(
        "inputs",
        nargs="+",
        metavar="INPUT",
        help="model file, folder (searched recursively) or quoted glob pattern ('**' spans folders)",
    )
    p.add_argument("--op", required=True, choices=OPERATIONS, help="operation to run on every file")
    p.add_argument("--out", required=True, metavar="DIR", help="output folder (created if missing)")
    p.add_argument(
        "--jobs",
        "-j",
        type=positive_int,
        metavar="N",
        help="worker processes on this machine (default: one per core)",
    )
    p.add_argument(
        "--resume",
        action="store_true",
        help="skip files whose output and 'ok' report from an earlier run exist",
    )
    p.add_argument(
        "--time-limit",
        type=positive_seconds,
        metavar="SECONDS",
        help="stop a file after this many seconds and report it as 'timeout'",
    )
    p.add_argument(
        "--dask-scheduler",
        metavar="ADDRESS",
        help="run the files on this Dask scheduler (e.g. tcp://10.0.0.5:8786) instead of locally",
    )
    algorithm_options(p)
    removal = p.add_argument_group("with --op remove-interior")
    removal_options(removal)
    p.add_argument("--quiet", "-q", action="store_true", help="print nothing but errors")
    p.set_defaults(func=run)


class _Display:
    """Per-file status lines and a progress bar (on a terminal) on stderr."""

    def __init__(self, tasks, quiet: bool):
        self.tasks = tasks
        self.quiet = quiet
        self.running: dict[int, float] = {}
        self.done = 0
        self.bar = None
        if not quiet and sys.stderr.isatty():
            from rich.console import Console
            from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn

            self.bar = Progress(
                TextColumn("{task.description}"),
                BarColumn(),
                MofNCompleteColumn(),
                TimeElapsedColumn(),
                console=Console(stderr=True),
                transient=True,
            )
            self.task_id = self.bar.add_task("starting", total=len(tasks))

    def __enter__(self):
        if self.bar is not None:
            self.bar.__enter__()
        return self

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.__exit__(*exc)

    def _describe(self) -> str:
        names = [os.path.basename(self.tasks[i].input) for i in self.running]
        shown = ", ".join(names[:3]) + (f" +{len(names) - 3}" if len(names) > 3 else "")
        return f"running {shown}" if names else "waiting"

    def start(self, i: int) -> None:
        self.running[i] = time.monotonic()
        if self.bar is not None:
            self.bar.update(self.task_id, description=self._describe())

    def finish(self, i: int, row: dict) -> None:
        self.running.pop(i, None)
        self.done += 1
        if self.quiet:
            return
        line = _status_line(row)
        if self.bar is not None:
            self.bar.console.print(line, markup=False, highlight=False)
            self.bar.update(self.task_id, completed=self.done, description=self._describe())
        else:
            print(line, file=sys.stderr, flush=True)


def _status_line(row: dict) -> str:
    faces = ""
    if row.get("faces_in") is not None:
        faces = (
            f"  {row['faces_in']} -> {row['faces_out'] if row.get('faces_out') is not None else '?'} faces"
        )
    secs = f"  {row['seconds']:.1f} s" if row.get("seconds") is not None else ""
    text = f"{row['status']:<8} {row['input']}{faces}{secs}"
    if row.get("error"):
        text += f"\n         {row['error']}"
    return text


def _summary_table(result, out_dir: str, limit: int = 60):
    from rich.table import Table

    rows = result.rows
    shown = rows if len(rows) <= limit else [r for r in rows if r["status"] not in ("ok", "skipped")]
    # paths relative to the folder all inputs share keep the table narrow
    base = os.path.commonpath([os.path.dirname(os.path.abspath(r["input"])) for r in rows]) if rows else "."
    table = Table(
        title=f"meshvis batch: {len(rows)} files from {base}, {result.seconds:.1f} s", title_justify="left"
    )
    for col, just in (
        ("file", "left"),
        ("status", "left"),
        ("faces in", "right"),
        ("faces out", "right"),
        ("rays", "right"),
        ("seconds", "right"),
    ):
        table.add_column(col, justify=just, overflow="fold", no_wrap=col != "file")
    for r in shown:
        table.add_row(
            os.path.relpath(os.path.abspath(r["input"]), base),
            r["status"],
            "" if r.get("faces_in") is None else f"{r['faces_in']:,}",
            "" if r.get("faces_out") is None else f"{r['faces_out']:,}",
            "" if r.get("rays") is None else f"{r['rays']:,}",
            "" if r.get("seconds") is None else f"{r['seconds']:.2f}",
        )
    counts = ", ".join(f"{n} {s}" for s, n in sorted(result.counts.items()))
    caption = counts + (
        "" if shown is rows else f" (only failures listed; all files in {out_dir}/summary.csv)"
    )
    table.caption, table.caption_justify = caption, "left"
    return table


def run(args: argparse.Namespace) -> int:
    """Run ``meshvis batch``: one repair operation over many files, locally or on Dask.

    Every file's output and report go into ``--out`` (created when missing), together with
    ``summary.csv`` and ``summary.json``.  Unless ``--quiet``, a status line per file is
    printed on standard error (with a progress bar on a terminal), then a summary table
    and the errors in full on standard output.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed options: ``inputs``, ``op``, ``out``, ``jobs``, ``resume``,
        ``time_limit``, ``dask_scheduler``, the graph-cut options, ``quiet``.

    Returns
    -------
    int
        Exit status: 0 when every file succeeded or was skipped by ``--resume``, 1 when a
        file failed (error, time limit, crashed worker), 130 after Ctrl-C, 143 after SIGTERM.

    Raises
    ------
    ParameterError
        ``--jobs`` with ``--dask-scheduler``, a graph-cut option out of its range, inputs not
        found, an output that would overwrite an input, no Dask or no connection to the
        scheduler.
    OutputError
        ``--out`` is a file or cannot be created or written.
    """
    from meshvis import _validate
    from meshvis.batch import default_jobs, plan, run_batch, write_summary
    from meshvis.errors import ParameterError
    from meshvis.io import ensure_folder
    from meshvis.repair.operation import check_options

    if args.dask_scheduler and args.jobs:
        raise ParameterError("--jobs sets local worker processes; with --dask-scheduler the cluster decides")
    from .cmd_repair import algorithm_options, removal_options

    dests = _dests(algorithm_options)
    if args.op == "remove-interior":  # orient has a --from of its own meaning
        dests += _dests(removal_options)
    options = {dest: getattr(args, dest) for dest in dests}
    # a bad --seed or --from fails here once, before any file is read, not in every file
    _validate.operation_options(options)
    check_options(args.op, options)
    tasks = plan(args.inputs, args.op, args.out, options)
    ensure_folder(args.out)
    jobs = None if args.dask_scheduler else (args.jobs or default_jobs(len(tasks)))
    with _Display(tasks, args.quiet) as display:
        result = run_batch(
            tasks,
            jobs=jobs,
            time_limit=args.time_limit,
            scheduler=args.dask_scheduler,
            resume=args.resume,
            on_start=display.start,
            on_done=display.finish,
        )
    meta = {
        "operation": args.op,
        "options": options,
        "inputs": list(args.inputs),
        "out": args.out,
        "jobs": jobs,
        "dask_scheduler": args.dask_scheduler,
        "time_limit": args.time_limit,
        "resume": args.resume,
    }
    csv_path, json_path = write_summary(result, args.out, meta)
    if not args.quiet:
        from rich.console import Console

        Console(highlight=False).print(_summary_table(result, args.out))
        for r in result.rows:  # errors in full, below the table
            if r["status"] not in ("ok", "skipped") and r.get("error"):
                print(f"{r['status']}: {r['error']}")
        print(f"wrote {csv_path} and {json_path}")
    if result.interrupted:
        from .signals import TERMINATED_STATUS, terminated

        print(f"meshvis: {'terminated' if terminated() else 'interrupted'}", file=sys.stderr)
        return TERMINATED_STATUS if terminated() else 130
    return 0 if result.ok else 1
