"""A progress display on stderr for long work (rich), silent with --quiet or when not a terminal."""

from __future__ import annotations

import contextlib
import sys


@contextlib.contextmanager
def stage_progress(args):
    """Yield a ``progress(stage, fraction)`` callback, or None when quiet/not interactive."""
    if getattr(args, "quiet", False) or not sys.stderr.isatty():
        yield None
        return
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    with Progress(
        TextColumn("{task.description:<12}"),
        BarColumn(),
        TimeElapsedColumn(),
        transient=True,
        console=__import__("rich.console").console.Console(stderr=True),
    ) as bar:
        task = bar.add_task("start", total=1.0)

        def update(stage: str, fraction: float) -> None:
            bar.update(task, description=stage, completed=min(max(fraction, 0.0), 1.0))

        yield update
