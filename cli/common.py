"""Argument helpers shared by the subcommands."""
from __future__ import annotations

import argparse
import os
import sys
from typing import Any

from meshvis.errors import OutputError, ParameterError
from meshvis.jsonfile import write_json  # noqa: F401  (re-exported for the commands)


def point(text: str) -> tuple[float, float, float]:
    """Parse ``x,y,z``."""
    try:
        x, y, z = (float(t) for t in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected x,y,z, got {text!r}") from None
    return (x, y, z)


def check_output(path: str, inputs: list[str], force: bool) -> None:
    """Refuse an output that is an input, or that exists without ``--force``."""
    for inp in inputs:
        if os.path.exists(path) and os.path.exists(inp) and os.path.samefile(path, inp):
            raise OutputError("output path is the input file; choose another path", path)
        if os.path.abspath(path) == os.path.abspath(inp):
            raise OutputError("output path is the input file; choose another path", path)
    if os.path.isdir(path):
        raise OutputError("output path is a folder", path)
    if os.path.exists(path) and not force:
        raise OutputError("exists; use --force to overwrite", path)
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise OutputError("output folder does not exist", folder)
    if not os.access(folder, os.W_OK):
        raise OutputError("output folder is not writable", folder)


def say(args: argparse.Namespace, *text: Any) -> None:
    """Print unless ``--quiet``."""
    if not getattr(args, "quiet", False):
        print(*text)


def positive_int(text: str) -> int:
    v = int(text)
    if v < 1:
        raise argparse.ArgumentTypeError("must be at least 1")
    return v


def stderr(*text: Any) -> None:
    print(*text, file=sys.stderr)


__all__ = ["point", "check_output", "write_json", "say", "positive_int", "ParameterError"]
