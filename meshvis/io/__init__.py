"""Reading and writing models.

:func:`load` reads OBJ, PLY (ASCII and binary), STL (ASCII and binary), OFF, glTF/GLB and
3MF into a :class:`~meshvis.soup.Soup`; :func:`save` writes OBJ, PLY, STL, OFF and
glTF/GLB, keeping every attribute the format can hold (a repaired soup is written by editing
the file it was read from, see :mod:`meshvis.io.edits`); :func:`as_soup` turns what users
have (a path, a trimesh object, ``(vertices, faces)``) into a soup.

One module per format (:mod:`~meshvis.io.obj`, :mod:`~meshvis.io.ply`, ...), each
declaring its ``READERS`` and ``WRITERS``; :mod:`~meshvis.io.reading` and
:mod:`~meshvis.io.writing` collect them.  Every file is written through
:func:`atomic_write`: an existing file is replaced only once its successor is complete.
"""

from __future__ import annotations

from meshvis.io._common import (
    atomic_write,
    check_output,
    check_outputs,
    ensure_folder,
    one_line,
    staged_outputs,
    unique_names,
    weld_corners,
)
from meshvis.io.convert import as_soup
from meshvis.io.reading import READ_FORMATS, load, sniff
from meshvis.io.scene import soup_from_scene
from meshvis.io.writing import WRITE_FORMATS, rebuild_note, save

__all__ = [
    "READ_FORMATS",
    "WRITE_FORMATS",
    "as_soup",
    "atomic_write",
    "check_output",
    "check_outputs",
    "ensure_folder",
    "load",
    "one_line",
    "rebuild_note",
    "save",
    "sniff",
    "soup_from_scene",
    "staged_outputs",
    "unique_names",
    "weld_corners",
]
