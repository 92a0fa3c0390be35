"""Optional dependencies: which extra installs which module, and one import helper.

The base install covers every repair, ``info``, ``render``, ``label`` and ``demo``; the
benchmarks' baselines, Dask batches and GraphML export need the extras named here.
"""

from __future__ import annotations

import importlib
from types import ModuleType

from meshvis.errors import MissingExtraError

#: module -> the extra of pyproject.toml that installs it
EXTRA_OF = {
    "pymeshlab": "bench",
    "adjustText": "bench",
    "distributed": "dask",
    "networkx": "graphml",
    "anywidget": "notebook",
    "playwright.sync_api": "browser",
}


def import_extra(module: str, feature: str) -> ModuleType:
    """Import an optional dependency, or raise MissingExtraError naming the extra."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtraError(feature, module, EXTRA_OF[module]) from None
