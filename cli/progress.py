"""A progress display on stderr for long work (rich), silent with --quiet or when not a terminal."""

from __future__ import annotations

import contextlib
import sys


@contextlib.contextmanager
def stage_progress(args):
    """Show a progress bar on standard error while the block runs (a context manager).

    The bar shows the current stage's name and how far it is; it disappears when the block
    ends.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments; ``quiet`` (when present and True) switches the bar off.

    Yields
    ------
    callable or None
        ``progress(stage, fraction)``, which names the stage and sets the bar to
        ``fraction`` (clipped to [0, 1]); None with ``--quiet`` or when standard error is not
        a terminal.
    """
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
