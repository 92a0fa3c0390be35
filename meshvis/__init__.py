"""meshvis: visibility questions about real, broken 3D models.

The package is layered; each subpackage uses only the ones above it in this list:

* :mod:`meshvis.soup`, :mod:`meshvis.errors` -- the in-memory model and the exceptions;
* :mod:`meshvis.io` -- reading and writing files, one module per format;
* :mod:`meshvis.rays` -- the Embree ray caster, random samples, cameras and previews;
* :mod:`meshvis.geometry` -- connectivity, welding, intersection tests, diagnostics;
* :mod:`meshvis.graphcut` -- inside/outside by visibility graph cut (appendix H);
* :mod:`meshvis.visibility` -- from-region visibility by guided sampling (GVS);
* :mod:`meshvis.repair` -- orientation, inside removal and layers built on the cut;
* :mod:`meshvis.batch` -- one repair over many files;
* :mod:`meshvis.labeling` -- external labels (appendix I), on :mod:`meshvis.rays`;
* :mod:`meshvis.eval` -- generated models with known answers, baselines, benchmarks;
* :mod:`meshvis.cli` -- the ``meshvis`` command.

The public API below is imported lazily, so that ``import meshvis`` stays fast.

>>> import meshvis
>>> soup = meshvis.as_soup(([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]))
>>> soup.n_faces
1
"""

from __future__ import annotations

import importlib
from typing import Any

from meshvis._version import __version__  # noqa: E402
from meshvis.errors import (  # noqa: E402
    MeshvisError,
    ModelError,
    ModelFormatError,
    OutputError,
    ParameterError,
)
from meshvis.soup import Soup  # noqa: E402

#: public name -> module that defines it
_LAZY = {
    "load": "meshvis.io",
    "save": "meshvis.io",
    "as_soup": "meshvis.io",
    "RayCaster": "meshvis.rays.caster",
    "Hits": "meshvis.rays.caster",
    "Camera": "meshvis.rays.camera",
    "render": "meshvis.rays.render",
    "diagnose": "meshvis.geometry.diagnostics",
    "classify": "meshvis.graphcut.classify",
    "Classification": "meshvis.graphcut.classify",
    "Hints": "meshvis.graphcut.hints",
    "orient": "meshvis.repair.orient",
    "orient_from": "meshvis.repair.orient",
    "remove_interior": "meshvis.repair.remove",
    "layers": "meshvis.repair.layers",
    "visible_from": "meshvis.visibility.visible",
    "parse_region": "meshvis.visibility.regions",
}

__all__ = [
    "__version__",
    "MeshvisError",
    "ModelError",
    "ModelFormatError",
    "OutputError",
    "ParameterError",
    "Soup",
    *_LAZY,
]


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'meshvis' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
