"""What no view cell sees, for inside removal: the ``cells:PVS.npz`` region of ``remove-interior``.

A PVS file names, for every view cell, the faces a viewer in it can see; the faces in no
cell's PVS are what no viewer anywhere in the view space sees (level cleanup).  The union of
the cells' sets is handed to :func:`meshvis.remove_interior` as the from-region search it
would otherwise run (:class:`meshvis.visibility.Visibility`), so every removal mode and
option works with it.

>>> is_cells_region("cells:level.pvs.npz"), is_cells_region("outside")
(True, False)
"""

from __future__ import annotations

import os
import time

import numpy as np

from meshvis.errors import ModelError, ParameterError
from meshvis.io import as_soup
from meshvis.visibility.regions import Region
from meshvis.visibility.visible import Visibility

#: the region text that names a PVS file
PREFIX = "cells:"


def is_cells_region(region) -> bool:
    """Whether ``region`` is the text ``cells:PVS.npz``."""
    return isinstance(region, str) and region.strip().lower().startswith(PREFIX)


def cells_path(region: str) -> str:
    """The PVS file of a ``cells:`` region, checked to exist and to be a PVS file (before any model is read).

    Raises
    ------
    ParameterError
        No file, or a file that is not a PVS file.
    """
    path = region.strip()[len(PREFIX) :]
    if not path or not os.path.isfile(path):
        raise ParameterError(f"{path or '(no file)'}: PVS file not found (cells:PVS.npz, from meshvis pvs)")
    from meshvis.viewcells.result import PVS

    try:
        PVS.load(path)
    except ModelError as exc:
        raise ParameterError(str(exc)) from None
    return path


def cells_visibility(model, region: str) -> Visibility:
    """The faces in the PVS of some cell of the file, as a from-region search's result.

    Parameters
    ----------
    model : Soup or anything :func:`meshvis.io.as_soup` accepts
        The model the PVS was made for.
    region : str
        ``cells:PVS.npz``.

    Returns
    -------
    Visibility
        ``seen_side``: a face in some PVS is seen on the sides the sampling hit (its front
        when none was hit: a face the visibility filter added).

    Raises
    ------
    ParameterError
        The file is missing or not a PVS file.
    ModelError
        The PVS was made for another model.
    """
    from meshvis.viewcells.result import PVS

    t = time.perf_counter()
    soup = as_soup(model)
    path = cells_path(region)
    result = PVS.load(path, soup)
    seen = result.seen
    front = (result.sides & 1) != 0
    back = (result.sides & 2) != 0
    seen_side = np.stack([seen & (front | ~back), seen & back], axis=1)
    m = soup.n_faces
    return Visibility(
        seen_side=seen_side,
        rays_seen=np.zeros((m, 2), np.int64),
        seed_rays=np.zeros(m, np.int64),
        area=soup.areas.copy(),
        first_seen=np.where(seen, 0, -1).astype(np.int64),
        history={"rays": [], "visible_area": [], "faces_seen": [], "seconds": []},
        rays={"total": 0},
        skipped={},
        region=Region(kind=f"{PREFIX}{path}", at_infinity=False),
        method="pvs",
        seed=int(result.summary.get("seed", 0)),
        seconds=time.perf_counter() - t,
        stopped="read from the PVS file",
        extra={"cells": result.cells.n_cells},
    )
