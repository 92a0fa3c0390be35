"""meshvis: visibility questions about real, broken 3D models.

The public API is imported lazily so that ``import meshvis`` stays fast for the CLI.
"""
from __future__ import annotations

import importlib

__version__ = "0.1.0"

from .errors import MeshvisError, ModelError, ModelFormatError, OutputError, ParameterError  # noqa: E402
from .soup import Soup, as_soup  # noqa: E402

# name -> module that defines it
_LAZY = {
    "load": "meshvis.io",
    "save": "meshvis.io",
    "RayCaster": "meshvis.rays",
    "Hits": "meshvis.rays",
    "diagnose": "meshvis.diagnostics",
    "render": "meshvis.render",
    "classify": "meshvis.classify",
    "orient": "meshvis.orient",
    "remove_interior": "meshvis.removal",
    "layers": "meshvis.layers",
    "Camera": "meshvis.camera",
    "Hints": "meshvis.hints",
}

__all__ = [
    "__version__", "MeshvisError", "ModelError", "ModelFormatError", "OutputError",
    "ParameterError", "Soup", "as_soup", *_LAZY,
]


def __getattr__(name: str):
    if name in _LAZY:
        return getattr(importlib.import_module(_LAZY[name]), name)
    raise AttributeError(f"module 'meshvis' has no attribute {name!r}")
