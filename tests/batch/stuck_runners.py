"""Runners that never finish, for the time-limit and crash tests of tests/batch/test_batch.py.

They live in their own module, imported by name in the worker processes, so that a worker
needs neither the test module nor the repository folder on its path.
"""

import glob
import os
import signal
import time

_OPEN: list = []  # keeps the unfinished writes alive (a collected one would clean up after itself)


def _partial_write(args) -> None:
    """Start writing the output (a temporary file appears) and never finish."""
    from meshvis.io import atomic_write

    writer = atomic_write(args["output"], "w")
    _OPEN.append(writer)
    fh = writer.__enter__()
    fh.write("partial")
    fh.flush()
    assert glob.glob(os.path.join(os.path.dirname(args["output"]), ".*.tmp"))


def hang(op, soup, args, progress):
    _partial_write(args)
    time.sleep(3600)


def stubborn(op, soup, args, progress):
    signal.signal(signal.SIGTERM, signal.SIG_IGN)  # a hung C call would not see SIGTERM either
    _partial_write(args)
    time.sleep(3600)


def die(op, soup, args, progress):
    _partial_write(args)
    os.kill(os.getpid(), signal.SIGKILL)
