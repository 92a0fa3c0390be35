"""What users have, as a :class:`~meshvis.soup.Soup`.

The one coercion every entry point of the library goes through.
"""

from __future__ import annotations

import os
from typing import Any

import numpy as np

from meshvis.errors import ModelError
from meshvis.io.reading import load
from meshvis.io.scene import soup_from_mesh, soup_from_scene
from meshvis.soup import Soup, validate


def as_soup(model: Any, *, name: str | None = None) -> Soup:
    """Coerce what users have into a validated :class:`Soup`.

    Accepts a :class:`Soup`, a ``trimesh.Trimesh``, a ``trimesh.Scene``, a
    ``(vertices, faces)`` pair, or a path (loaded with :func:`meshvis.io.load`).
    """
    if isinstance(model, Soup):
        validate(model.vertices, model.faces, model.path)
        return model
    if isinstance(model, (str, os.PathLike)):
        return load(model)
    import trimesh  # a dependency

    if isinstance(model, trimesh.Scene):
        return soup_from_scene(model, path=name)
    if trimesh is not None and isinstance(model, trimesh.Trimesh):
        return soup_from_mesh(model, path=name)
    if isinstance(model, (tuple, list)) and len(model) == 2:
        v, f = model
        validate(v, f, name)
        v, f = np.asarray(v), np.asarray(f)
        return Soup(v, f.astype(np.int64), path=name)
    raise ModelError(f"cannot use a {type(model).__name__} as a model", name)
