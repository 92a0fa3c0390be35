"""MkDocs hook: let mkdocstrings see the installed layout of the package.

``labeling/`` and ``cli/`` are installed as ``meshvis.labeling`` and ``meshvis.cli``
(pyproject's package-dir), but griffe reads packages from folders and finds
``meshvis/labeling`` in neither the source tree nor an editable install.  Before the build
this hook puts a folder of symbolic links shaped like the installed package at the front
of ``sys.path``: ``meshvis/*`` from the source tree, plus ``meshvis/labeling`` and
``meshvis/cli``.
"""

from __future__ import annotations

import atexit
import os
import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent
MAPPED = {"labeling": ROOT / "labeling", "cli": ROOT / "cli"}


def on_startup(command: str, dirty: bool) -> None:
    """Build the link tree once per mkdocs run."""
    tree = Path(tempfile.mkdtemp(prefix="meshvis-docs-"))
    atexit.register(shutil.rmtree, tree, ignore_errors=True)
    package = tree / "meshvis"
    package.mkdir()
    for entry in (ROOT / "meshvis").iterdir():
        if entry.name != "__pycache__":
            os.symlink(entry, package / entry.name)
    for name, folder in MAPPED.items():
        os.symlink(folder, package / name)
    sys.path.insert(0, str(tree))
