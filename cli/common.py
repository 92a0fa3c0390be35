"""Argument helpers shared by the subcommands."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from meshvis.errors import ParameterError
from meshvis.io import check_output, staged_outputs  # noqa: F401  (re-exported for the commands)
from meshvis.io.jsonfile import write_json  # noqa: F401  (re-exported for the commands)


def point(text: str) -> tuple[float, float, float]:
    """Parse ``x,y,z``."""
    try:
        x, y, z = (float(t) for t in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected x,y,z, got {text!r}") from None
    return (x, y, z)


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


__all__ = ["point", "check_output", "staged_outputs", "write_json", "say", "positive_int", "ParameterError"]
