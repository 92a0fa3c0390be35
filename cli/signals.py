"""SIGTERM as a clean stop: the command unwinds like Ctrl-C and exits with status 143.

Temporary files are removed on the way out, and a batch stops its workers and writes its
summary, as after Ctrl-C.
"""

from __future__ import annotations

import contextlib
import signal
import threading
from collections.abc import Iterator


class Terminated(KeyboardInterrupt):
    """Raised in the main thread by SIGTERM; a KeyboardInterrupt, so every Ctrl-C path runs."""


#: exit status of a command stopped by SIGTERM (128 + 15, as the shell reports it)
TERMINATED_STATUS = 128 + signal.SIGTERM


_FIRED = [False]  # set by the handler; read by a command that reports the stop itself (batch)


def _raise_terminated(signum, frame) -> None:
    signal.signal(signal.SIGTERM, signal.SIG_IGN)  # one stop is enough: let the clean-up finish
    _FIRED[0] = True
    raise Terminated()


@contextlib.contextmanager
def sigterm_stops() -> Iterator[None]:
    """Turn SIGTERM into :class:`Terminated` inside the block (a context manager).

    Signal handlers can only be set from the main thread: in any other thread the block runs
    with SIGTERM handling unchanged.  The previous handler is restored when the block ends.
    The first SIGTERM makes the process ignore further ones, so that the clean-up finishes.

    Yields
    ------
    None

    Raises
    ------
    Terminated
        Where the block is running when SIGTERM arrives (main thread only).
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    old = signal.signal(signal.SIGTERM, _raise_terminated)
    _FIRED[0] = False
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)


def terminated() -> bool:
    """Tell whether a SIGTERM has stopped the command running in this process.

    Returns
    -------
    bool
        True when SIGTERM arrived since the last :func:`sigterm_stops` block began in the
        main thread.
    """
    return _FIRED[0]
