"""Reports as standard JSON, and the JSON files meshvis reads beside models.

Writing: numpy values are converted, non-finite floats written as null, files written
atomically.  Reading (:func:`read_json`, :func:`parse_json`): any failure is one
``ValueError`` -- never a ``RecursionError`` from ``[[[[...`` nested past Python's limit
or an ``OverflowError`` later from a 400-digit integer, which is read as a float (infinite
when too large, so that the checks on finite numbers refuse it).
"""

from __future__ import annotations

import json
import math
import os
import sys
from typing import Any

import numpy as np

from meshvis.io._common import atomic_write, decode_text, one_line

#: integers with more digits than this are read as floats (numpy cannot hold them as integers)
_MAX_INT_DIGITS = 18


def _number(text: str) -> int | float:
    return int(text) if len(text.lstrip("-")) <= _MAX_INT_DIGITS else float(text)


def parse_json(text: str | bytes) -> Any:
    """The value of a JSON text (bytes: UTF-8, a byte-order mark allowed).

    Raises
    ------
    ValueError
        The text is not JSON, or nests deeper than the parser can follow; the message is
        one line.
    """
    if isinstance(text, (bytes, bytearray)):
        text = decode_text(bytes(text))
    text = text.lstrip("\ufeff")
    try:
        return json.loads(text, parse_int=_number)
    except RecursionError:
        raise ValueError("the JSON nests deeper than can be read") from None
    except ValueError as exc:
        raise ValueError(one_line(exc)) from None


def read_json(path: str | os.PathLike) -> Any:
    """The value of a JSON file (see :func:`parse_json`).

    Raises
    ------
    OSError
        The file cannot be read.
    ValueError
        It is not JSON, or not a regular file (reading a FIFO would wait for a writer).
    """
    path = os.fspath(path)
    if os.path.exists(path) and not os.path.isfile(path):
        raise ValueError("not a regular file (a FIFO, socket or device)")
    with open(path, "rb") as fh:
        return parse_json(fh.read())


def to_builtin(obj: Any) -> Any:
    """A copy of ``obj`` made of plain Python values that standard JSON can hold.

    numpy arrays become lists, numpy scalars Python scalars, NaN and infinities ``None``.
    """
    if isinstance(obj, dict):
        return {str(k): to_builtin(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [to_builtin(v) for v in obj]
    if isinstance(obj, np.ndarray):
        if obj.dtype.kind == "f" and not np.isfinite(obj).all():
            return to_builtin(obj.tolist())
        return obj.tolist()
    if isinstance(obj, np.generic):
        return to_builtin(obj.item())
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    return obj


#: the path that stands for standard output (``--report -``, ``--json -``)
STDOUT = "-"


def write_json(path: str | os.PathLike, data: Any) -> None:
    """Write ``data`` as indented standard JSON, atomically (temp file, then rename).

    The path ``"-"`` writes it to standard output.
    """
    text = json.dumps(to_builtin(data), indent=1, allow_nan=False, default=str)
    if os.fspath(path) == STDOUT:
        sys.stdout.write(text + "\n")
        sys.stdout.flush()
        return
    with atomic_write(path, "w") as fh:
        fh.write(text + "\n")
