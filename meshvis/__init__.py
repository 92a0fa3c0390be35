"""meshvis: visibility questions about real, broken 3D models.

The package is layered; each subpackage uses only the ones above it in this list:

* :mod:`meshvis.soup`, :mod:`meshvis.errors` -- the in-memory model and the exceptions;
* :mod:`meshvis.io` -- reading and writing files, one module per format;
* :mod:`meshvis.rays` -- the Embree ray caster, random samples, cameras and previews;
* :mod:`meshvis.geometry` -- connectivity, welding, intersection tests, diagnostics;
* :mod:`meshvis.graphcut` -- inside/outside by visibility graph cut (appendix H);
* :mod:`meshvis.visibility` -- from-region visibility by guided sampling (GVS);
* :mod:`meshvis.viewcells` -- the PVS of every view cell (AGVS on a view-cell hierarchy);
* :mod:`meshvis.repair` -- orientation, inside removal and layers built on the cut;
* :mod:`meshvis.batch` -- one repair over many files;
* :mod:`meshvis.labeling` -- external labels (appendix I), on :mod:`meshvis.rays`;
* :mod:`meshvis.eval` -- generated models with known answers, baselines, benchmarks;
* :mod:`meshvis.cli` -- the ``meshvis`` command.

The public API below is imported lazily, so that ``import meshvis`` stays fast (it does not
import numpy).

>>> import meshvis
>>> soup = meshvis.as_soup(([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 1, 2]]))
>>> soup.n_faces
1
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import os
import sys
from typing import Any


def _set_numba_cache() -> None:
    """Keep the compiled kernels in the user's cache folder, not next to the sources.

    numba reads ``NUMBA_CACHE_DIR`` when it is imported (and again before each
    compilation), so it is set here, before any kernel module imports numba.  A cache
    beside the sources would be left behind in site-packages by ``pip uninstall`` and
    shadow a later install.  A value the user set is kept.
    """
    if "NUMBA_CACHE_DIR" not in os.environ:
        import platformdirs

        os.environ["NUMBA_CACHE_DIR"] = os.path.join(platformdirs.user_cache_dir("meshvis"), "numba")


class _SourceFolders(importlib.abc.MetaPathFinder):
    """Find ``meshvis.cli`` and ``meshvis.labeling`` in a source checkout run without installing.

    The repository keeps ``cli/`` and ``labeling/`` beside ``meshvis/``; an install maps
    them into the package (pyproject's ``package-dir``).  Run from the checkout itself
    (``python -m meshvis`` in its root), this finder does the same mapping.  It is asked
    last, so an installed package always wins.
    """

    def __init__(self, root: str):
        self.folders = {f"meshvis.{name}": os.path.join(root, name) for name in ("cli", "labeling")}

    def find_spec(self, name, path=None, target=None):
        folder = self.folders.get(name)
        if folder is None:
            return None
        return importlib.util.spec_from_file_location(
            name, os.path.join(folder, "__init__.py"), submodule_search_locations=[folder]
        )


def _map_source_folders() -> None:
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    is_checkout = os.path.isfile(os.path.join(root, "pyproject.toml")) and os.path.isfile(
        os.path.join(root, "cli", "main.py")
    )
    if is_checkout and not any(isinstance(f, _SourceFolders) for f in sys.meta_path):
        sys.meta_path.append(_SourceFolders(root))


_set_numba_cache()
_map_source_folders()

from meshvis._version import __version__  # noqa: E402
from meshvis.errors import (  # noqa: E402
    MeshvisError,
    ModelError,
    ModelFormatError,
    OutputError,
    ParameterError,
)

#: public name -> module that defines it
_LAZY = {
    "Soup": "meshvis.soup",
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
    "fix_normals": "meshvis.repair.trimesh_style",
    "remove_hidden": "meshvis.repair.trimesh_style",
    "visible_from": "meshvis.visibility.visible",
    "parse_region": "meshvis.visibility.regions",
    "pvs": "meshvis.viewcells.agvs",
    "PVS": "meshvis.viewcells.result",
}

__all__ = [
    "__version__",
    "MeshvisError",
    "ModelError",
    "ModelFormatError",
    "OutputError",
    "ParameterError",
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
