"""Argument helpers shared by the subcommands."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from meshvis.errors import ParameterError
from meshvis.io import check_output, check_outputs, staged_outputs  # noqa: F401  (re-exported for the commands)
from meshvis.io.jsonfile import write_json  # noqa: F401  (re-exported for the commands)


def point(text: str) -> tuple[float, float, float]:
    """Parse ``x,y,z`` into a point (an argparse ``type``).

    Parameters
    ----------
    text : str
        Three comma-separated numbers.

    Returns
    -------
    tuple of 3 float
        The point.

    Raises
    ------
    argparse.ArgumentTypeError
        ``text`` is not three comma-separated numbers.
    """
    try:
        x, y, z = (float(t) for t in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected x,y,z, got {text!r}") from None
    return (x, y, z)


def say(args: argparse.Namespace, *text: Any) -> None:
    """Print to standard output unless ``--quiet`` was given.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments; a namespace without ``quiet`` counts as not quiet.
    *text : object
        What to print, separated by spaces as :func:`print` does.
    """
    if not getattr(args, "quiet", False):
        print(*text)


def positive_int(text: str) -> int:
    """Parse an integer of at least 1 (an argparse ``type``).

    Parameters
    ----------
    text : str
        The option's value.

    Returns
    -------
    int
        The number.

    Raises
    ------
    ValueError
        ``text`` is not an integer (argparse reports it as an invalid value).
    argparse.ArgumentTypeError
        The number is below 1.
    """
    v = int(text)
    if v < 1:
        raise argparse.ArgumentTypeError("must be at least 1")
    return v


def stderr(*text: Any) -> None:
    """Print to standard error.

    Parameters
    ----------
    *text : object
        What to print, separated by spaces as :func:`print` does.
    """
    print(*text, file=sys.stderr)


__all__ = [
    "point",
    "check_output",
    "check_outputs",
    "staged_outputs",
    "write_json",
    "say",
    "positive_int",
    "ParameterError",
]
