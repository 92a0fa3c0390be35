"""A progress display on stderr for long work (rich), silent with --quiet or when not a terminal."""

from __future__ import annotations

import contextlib
import sys
import time

#: a stage shows its time estimate once it has run this long (seconds)
ESTIMATE_AFTER = 2.0


def remaining_seconds(elapsed: float, fraction: float) -> float | None:
    """Seconds left in a stage that took ``elapsed`` seconds to reach ``fraction``, or None.

    The stage's own rate so far, extrapolated: ``elapsed * (1 - fraction) / fraction``; None
    before :data:`ESTIMATE_AFTER` seconds or any progress (too early to tell).

    Examples
    --------
    >>> remaining_seconds(10.0, 0.25)
    30.0
    >>> remaining_seconds(1.0, 0.5) is None
    True
    """
    if elapsed < ESTIMATE_AFTER or fraction <= 0:
        return None
    return elapsed * (1 - min(fraction, 1.0)) / fraction


@contextlib.contextmanager
def stage_progress(args):
    """Show a progress bar on standard error while the block runs (a context manager).

    The bar shows the current stage's name, how far it is, the time the command has run and,
    once a stage has run :data:`ESTIMATE_AFTER` seconds, the time that stage still needs at
    its rate so far (:func:`remaining_seconds`); it disappears when the block ends.

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
    from rich.progress import BarColumn, Progress, ProgressColumn, TextColumn, TimeElapsedColumn
    from rich.text import Text

    state = {"stage": None, "start": time.monotonic()}

    class StageRemaining(ProgressColumn):
        """``~12 s left`` for the current stage (blank while too early to tell)."""

        def render(self, task) -> Text:
            left = remaining_seconds(time.monotonic() - state["start"], task.completed)
            return Text("" if left is None else f"~{left:,.0f} s left", style="progress.remaining")

    with Progress(
        TextColumn("{task.description:<12}"),
        BarColumn(),
        TimeElapsedColumn(),
        StageRemaining(),
        transient=True,
        console=__import__("rich.console").console.Console(stderr=True),
    ) as bar:
        task = bar.add_task("start", total=1.0)

        def update(stage: str, fraction: float) -> None:
            if stage != state["stage"]:
                state["stage"], state["start"] = stage, time.monotonic()
            bar.update(task, description=stage, completed=min(max(fraction, 0.0), 1.0))

        yield update
