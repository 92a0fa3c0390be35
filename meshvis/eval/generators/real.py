"""Truth of real models read from a folder: the dm_control dog skin with its rib cage."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from meshvis.errors import ModelError
from meshvis.geometry.adjacency import weld
from meshvis.soup import Soup

from .closed import from_closed_mesh
from .truth import GroundTruth


def _load_mesh(path: Path) -> Soup:
    if not path.exists():
        raise FileNotFoundError(f"{path}: real test model not found")
    import trimesh

    try:
        from meshvis.io import load  # the project's reader
    except ImportError:  # pragma: no cover - io is part of the package
        load = None
    if load is not None:
        try:
            return load(path)
        except ModelError as exc:
            first: Exception = exc
    else:
        first = None
    try:  # plain trimesh read, vertex order and count untouched
        m = trimesh.load(os.fspath(path), process=False, force="mesh")
    except Exception:
        if first is not None:
            raise first from None
        raise
    return Soup(np.asarray(m.vertices, np.float64), np.asarray(m.faces, np.int64), path=os.fspath(path))


def skin_and_ribcage(folder: str | os.PathLike) -> GroundTruth:
    """Build the truth of the dm_control dog skin with its rib cage inside: real hidden geometry.

    Parameters
    ----------
    folder : str or os.PathLike
        Where ``dm_control__SKINbody.stl`` and ``dm_control__BONERibcage.stl`` are.

    Returns
    -------
    GroundTruth
        The truth of :func:`from_closed_mesh` for skin and bones together: the skin is
        layer 1, a bone inside the skin is layer 2, and the parts of a bone that sink into
        another bone lie one layer deeper (the rib cage's bones interpenetrate).  Where two
        bones touch, the file holds the same triangle twice, once per bone: such coincident
        copies are ``ambiguous`` — an STL has no connectivity, so which bone owns which
        copy (and so which way it faces) cannot be observed from the geometry; so are faces
        that cross another face.

    Raises
    ------
    FileNotFoundError
        When either file is missing.
    ModelError
        When a file can be read neither by :func:`meshvis.load` nor by trimesh, or the two
        together are not closed with consistent winding.
    """
    from meshvis.geometry.adjacency import duplicate_faces

    folder = Path(folder)
    skin = _load_mesh(folder / "dm_control__SKINbody.stl")
    ribs = _load_mesh(folder / "dm_control__BONERibcage.stl")
    both = Soup.concatenate([skin, ribs])
    both = Soup(both.vertices, both.faces, part_id=both.part_id, part_names=["skin", "ribcage"])
    t = from_closed_mesh(both, name="skin_and_ribcage")
    first = duplicate_faces(weld(both.vertices, both.faces)[1])
    t.ambiguous |= np.bincount(first, minlength=len(first))[first] > 1  # every member of a copy group
    t.notes = "real closed skin with the rib cage inside: inside removal and layers on real data"
    return t
