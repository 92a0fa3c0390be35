"""Argument helpers shared by the subcommands."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from meshvis.errors import ParameterError


# the library's file helpers, imported when a command uses them (a parser needs none of them)
def check_output(path: str, inputs: list[str], force: bool) -> None:
    """:func:`meshvis.io.check_output`."""
    from meshvis.io import check_output as check

    check(path, inputs, force)


def check_outputs(paths: list[str], inputs: list[str], force: bool) -> None:
    """:func:`meshvis.io.check_outputs`."""
    from meshvis.io import check_outputs as check

    check(paths, inputs, force)


def staged_outputs():
    """:func:`meshvis.io.staged_outputs`."""
    from meshvis.io import staged_outputs as staged

    return staged()


def write_json(path: str, data: Any) -> None:
    """:func:`meshvis.io.jsonfile.write_json`."""
    from meshvis.io.jsonfile import write_json as write

    write(path, data)


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


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter, argparse.RawDescriptionHelpFormatter):
    """Help that ends every option's text with its default.

    Flags (a True/False default), required options and help that speaks of its default
    already say nothing more; an option without a default value says ``(default: none)``.
    Descriptions and epilogs keep their line breaks.
    """

    def _get_help_string(self, action: argparse.Action) -> str:
        text = action.help or ""
        default = action.default
        if (
            "default" in text.lower()  # said in words already
            or not action.option_strings
            or action.required
            or default is argparse.SUPPRESS
            or isinstance(default, bool)
            or action.nargs == 0  # a flag
        ):
            return text
        if default is None or default == []:
            return text + " (default: none)"
        if isinstance(default, (tuple, list)):
            return text + f" (default: {' '.join(map(str, default))})"
        return text + " (default: %(default)s)"


class Parser(argparse.ArgumentParser):
    """An argument parser with :class:`HelpFormatter` unless told otherwise (so its subcommands too)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("formatter_class", HelpFormatter)
        super().__init__(*args, **kwargs)


def verbosity_options(p: argparse.ArgumentParser) -> None:
    """Add ``--quiet`` (errors only) and ``--verbose`` (the internals too)."""
    group = p.add_mutually_exclusive_group()
    group.add_argument("--quiet", "-q", action="store_true", help="print nothing but errors")
    group.add_argument(
        "--verbose",
        "-v",
        action="store_true",
        help="also print the internals: the graph's nodes, edges and rays, each stage's time, "
        "the faces per status or reason",
    )


def detail(args: argparse.Namespace, *text: Any) -> None:
    """Print to standard output with ``--verbose`` only.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments; a namespace without ``verbose`` counts as not verbose.
    *text : object
        What to print, separated by spaces as :func:`print` does.
    """
    if getattr(args, "verbose", False) and not getattr(args, "quiet", False):
        print(*text)


def library_default(function: str, keyword: str) -> Any:
    """The default of ``keyword`` in the signature of ``function`` (``"module:name"``).

    The command line's defaults are read from the library here, so each is written once.
    """
    from meshvis._defaults import signature_default

    return signature_default(function, keyword)


def up_option(p: argparse.ArgumentParser, what: str) -> None:
    """Add ``--up auto|x|y|z``; ``auto`` is the model's own up axis (the library's ``up=None``)."""
    from meshvis.io.up_axis import UP_CHOICES

    p.add_argument(
        "--up",
        choices=UP_CHOICES,
        default="auto",
        help=f"the model's up axis, for {what}; auto: the convention of its file format "
        "(y for glTF/GLB and OBJ, z for STL, PLY, OFF and 3MF)",
    )


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


def non_negative_float(text: str) -> float:
    """Parse a number of at least 0 (an argparse ``type``).

    Raises
    ------
    ValueError
        ``text`` is not a number (argparse reports it as an invalid value).
    argparse.ArgumentTypeError
        The number is below 0 (or NaN).
    """
    v = float(text)
    if not v >= 0:
        raise argparse.ArgumentTypeError("must be at least 0")
    return v


def positive_seconds(text: str) -> float:
    """Parse a finite number of seconds above 0 (an argparse ``type``).

    Raises
    ------
    argparse.ArgumentTypeError
        ``text`` is not a number, or the number is not finite and above 0.
    """
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not v > 0 or v == float("inf"):
        raise argparse.ArgumentTypeError("must be a positive number of seconds")
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
    "detail",
    "positive_int",
    "ParameterError",
    "HelpFormatter",
    "Parser",
    "verbosity_options",
    "up_option",
    "library_default",
]
