"""The up axis of a model: the convention of its file format, or the axis the user names.

:func:`meshvis.load` records the format's up axis on the soup (``Soup.up``); every
function that needs an up direction (the upper-hemisphere region, the fitted camera, a
preview) takes ``up=None`` to mean that one, so a model gives the same answer from Python
and from the command line.

>>> up_vector("y").tolist(), format_up("scene.glb"), format_up("part.stl")
([0.0, 1.0, 0.0], (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from meshvis.errors import ParameterError

#: unit vectors of the axis names accepted as "up"
AXES = {"x": (1.0, 0.0, 0.0), "y": (0.0, 1.0, 0.0), "z": (0.0, 0.0, 1.0)}

#: the up axis of each file format: glTF is y-up by its specification and 3MF z-up by its;
#: OBJ files are y-up by the convention of the tools that write them; STL, PLY and OFF (CAD,
#: scanners) are z-up, as is a model made in memory
FORMAT_UP = {".glb": "y", ".gltf": "y", ".obj": "y", ".3mf": "z", ".stl": "z", ".ply": "z", ".off": "z"}
FALLBACK_UP = "z"

#: what the command line's ``--up`` accepts; ``auto`` is the model's own (``up=None``)
UP_CHOICES = ("auto", *AXES)


def format_up(path: str | os.PathLike | None) -> tuple[float, float, float]:
    """The up vector of a file's format (:data:`FORMAT_UP`; :data:`FALLBACK_UP` without a file).

    Parameters
    ----------
    path : str, path-like or None
        The model file; only its extension is read.

    Returns
    -------
    tuple of 3 float
        The unit up vector.
    """
    ext = os.path.splitext(os.fspath(path))[1].lower() if path else ""
    return AXES[FORMAT_UP.get(ext, FALLBACK_UP)]


def up_vector(up: Any = None, model: Any = None) -> np.ndarray:
    """The unit up vector that ``up`` names, for ``model``.

    Parameters
    ----------
    up : None, "auto", "x", "y", "z" or (3,) float
        None and ``"auto"`` give the model's own up axis (``Soup.up``, the convention of
        the format it was read from); an axis name or a vector give that direction.
    model : Soup, str or None
        The model (or its file) whose up axis ``None`` stands for; without one, z.

    Returns
    -------
    (3,) float64 array
        The normalised direction.

    Raises
    ------
    ParameterError
        An unknown axis name, or a vector that is not three finite numbers, not all zero.

    Examples
    --------
    >>> up_vector("x").tolist(), up_vector((0, 0, 2)).tolist(), up_vector(None, "a.obj").tolist()
    ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0])
    """
    if up is None or (isinstance(up, str) and up == "auto"):
        if isinstance(model, (str, os.PathLike)):
            return np.array(format_up(model))
        return np.array(getattr(model, "up", AXES[FALLBACK_UP]), np.float64)
    if isinstance(up, str):
        if up not in AXES:
            raise ParameterError(f"up must be auto, x, y, z or a vector; got {up!r}")
        return np.array(AXES[up])
    try:
        v = np.asarray(up, np.float64).reshape(3)
    except (TypeError, ValueError):
        raise ParameterError(f"up must be auto, x, y, z or three numbers; got {up!r}") from None
    norm = float(np.linalg.norm(v))
    if not np.isfinite(norm) or norm == 0:
        raise ParameterError(f"the up direction must be a finite non-zero vector, got {v.tolist()}")
    return v / norm
