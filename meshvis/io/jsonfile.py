"""Reports as standard JSON.

Numpy values are converted, non-finite floats written as null, files written atomically.
"""

from __future__ import annotations

import json
import math
import os
from typing import Any

import numpy as np

from meshvis.io._common import atomic_write


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


def write_json(path: str | os.PathLike, data: Any) -> None:
    """Write ``data`` as indented standard JSON, atomically (temp file, then rename)."""
    text = json.dumps(to_builtin(data), indent=1, allow_nan=False, default=str)
    with atomic_write(path, "w") as fh:
        fh.write(text + "\n")
