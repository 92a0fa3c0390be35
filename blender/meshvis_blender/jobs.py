# SPDX-License-Identifier: GPL-3.0-or-later
"""A computation in a background thread, with its progress and a way to stop it.

Blender's data may only be touched from its main thread, so an operator snapshots what it
needs as arrays, runs the library on them here, and applies the result when the job is
done.  The library reports progress through its ``progress(stage, fraction)`` callbacks;
cancelling makes the next callback raise :class:`Cancelled`, which unwinds the library.
"""

from __future__ import annotations

import threading
import traceback
from collections.abc import Callable
from typing import Any

#: where each stage of :func:`meshvis.classify` starts and ends in the job's progress; what
#: follows the classification (the repair, a search for views) fills the rest
STAGES = {"scene": (0.0, 0.02), "preprocess": (0.02, 0.3), "sampling": (0.3, 0.85), "done": (0.85, 0.85)}
#: the faces given a layer so far, of :func:`meshvis.layers` (the whole job)
STAGES["layers"] = (0.0, 1.0)


class Cancelled(Exception):
    """Raised inside the worker when the user cancelled the job."""


class Job:
    """Run ``work(progress)`` in a daemon thread; poll :attr:`done` and :attr:`fraction`.

    Parameters
    ----------
    work : callable
        ``work(progress) -> result``; ``progress(stage, fraction)`` is the library's
        callback (``stage`` a name of :data:`STAGES` or any other word).

    Examples
    --------
    >>> job = Job(lambda progress: progress("sampling", 0.5) or 42)
    >>> job.run()
    42
    >>> job.fraction
    0.575
    """

    def __init__(self, work: Callable[[Callable[[str, float], None]], Any]):
        self.work = work
        self.fraction = 0.0
        self.stage = ""
        self.result: Any = None
        self.error: BaseException | None = None
        self.details = ""
        self._cancel = threading.Event()
        self._finished = threading.Event()
        self._thread: threading.Thread | None = None

    def progress(self, stage: str, fraction: float) -> None:
        """The library's callback: record the progress, or stop if cancelled."""
        if self._cancel.is_set():
            raise Cancelled
        lo, hi = STAGES.get(stage, (STAGES["done"][1], 1.0))
        self.stage = stage
        self.fraction = max(self.fraction, lo + (hi - lo) * min(max(float(fraction), 0.0), 1.0))

    def _run(self) -> None:
        try:
            self.result = self.work(self.progress)
            self.fraction = 1.0
        except BaseException as exc:  # handed to the main thread, which reports it
            self.error = exc
            self.details = traceback.format_exc()
        finally:
            self._finished.set()

    def start(self) -> Job:
        """Start the work in a daemon thread (Blender may quit while it runs)."""
        self._thread = threading.Thread(target=self._run, name="meshvis", daemon=True)
        self._thread.start()
        return self

    def run(self) -> Any:
        """Do the work in the calling thread and return its result (or raise its error)."""
        self._run()
        if self.error is not None:
            raise self.error
        return self.result

    def cancel(self) -> None:
        """Ask the work to stop at the library's next progress callback."""
        self._cancel.set()

    @property
    def cancelled(self) -> bool:
        """Whether :meth:`cancel` was called."""
        return self._cancel.is_set()

    @property
    def done(self) -> bool:
        """Whether the work returned or raised."""
        return self._finished.is_set()

    def wait(self, timeout: float | None = None) -> bool:
        """Block until the work is done (or ``timeout`` seconds); True when it is."""
        return self._finished.wait(timeout)
