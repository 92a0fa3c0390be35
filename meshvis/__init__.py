"""meshvis: visibility questions about real, broken 3D models.

The public API is imported lazily so that ``import meshvis`` stays fast for the CLI.
"""
from __future__ import annotations

import importlib

__version__ = "0.1.0"

from .errors import MeshvisError, ModelError, ModelFormatError, OutputError, ParameterError  # noqa: E402
from .soup import Soup, as_soup  # noqa: E402
from .render import render  # noqa: E402  (eager: the function shadows its module's name)

# name -> module that defines it
_LAZY = {
    "load": "meshvis.io",
    "save": "meshvis.io",
    "RayCaster": "meshvis.rays",
    "Hits": "meshvis.rays",
    "diagnose": "meshvis.diagnostics",
    "classify": "meshvis.classification",
    "orient": "meshvis.orientation",
    "remove_interior": "meshvis.removal",
    "layers": "meshvis.layering",
    "Camera": "meshvis.camera",
    "Hints": "meshvis.hints",
}

__all__ = [
    "__version__", "render", "MeshvisError", "ModelError", "ModelFormatError", "OutputError",
    "ParameterError", "Soup", "as_soup", *_LAZY,
]


def __getattr__(name: str):
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'meshvis' has no attribute {name!r}")
