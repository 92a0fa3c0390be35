"""trimesh objects as soups.

A ``trimesh.Scene`` (instancing applied) or one mesh with its visual (UVs, colours,
material).  Used by the glTF and 3MF readers and by :func:`meshvis.io.as_soup`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from meshvis.errors import ModelError
from meshvis.soup import Material, Soup, validate


def soup_from_scene(scene, path: str | None = None) -> Soup:
    """Flatten a ``trimesh.Scene`` into a :class:`~meshvis.soup.Soup`, instancing applied.

    Every geometry node of the scene graph becomes its own part, named after the node;
    the node's world transform is
    applied (a mirroring transform turns the faces back, see
    :meth:`Soup.transformed`).  UVs, vertex or face colours and materials are kept where
    the geometry's visual exposes them.  Non-mesh geometry (paths, point clouds) is
    skipped.

    Parameters
    ----------
    scene : trimesh.Scene
        The scene to flatten.
    path : str, optional
        Name for messages.

    Returns
    -------
    Soup
        One part per geometry node.
    """
    parts: list[Soup] = []
    materials: dict[int, int] = {}
    mats: list = []
    for node in scene.graph.nodes_geometry:
        matrix, geom_name = scene.graph[node]
        geom = scene.geometry.get(geom_name)
        if geom is None or not hasattr(geom, "faces") or len(geom.faces) == 0:
            continue
        part = soup_from_trimesh(geom, str(node), mats, materials)
        parts.append(part.transformed(matrix) if not np.allclose(matrix, np.eye(4)) else part)
    if not parts:
        raise ModelError("the model has no faces", path)
    soup = Soup.concatenate(parts)
    soup.materials = mats
    soup.path = path
    validate(soup.vertices, soup.faces, path)
    return soup


def mesh_soup(geom: Any, name: str, material_index: int) -> Soup:
    """One trimesh mesh as a single-part soup with per-corner UVs / colours."""
    faces = np.asarray(geom.faces, np.int64)
    vis: Any = getattr(geom, "visual", None)
    uv = colors = None
    kind = getattr(vis, "kind", None)
    if kind == "texture" and getattr(vis, "uv", None) is not None and len(vis.uv) == len(geom.vertices):
        uv = np.asarray(vis.uv, np.float64)[faces]
    if kind == "vertex":
        colors = np.asarray(vis.vertex_colors, np.uint8)[faces]
    elif kind == "face":
        colors = np.repeat(np.asarray(vis.face_colors, np.uint8)[:, None, :], 3, axis=1)
    elif kind == "texture":
        attr = getattr(vis, "vertex_attributes", None) or {}
        col = attr.get("color")
        if col is not None and len(col) == len(geom.vertices):
            col = np.asarray(col)
            if col.dtype.kind == "f":
                col = np.clip(np.round(col * 255), 0, 255)
            rgba = np.full((len(col), 4), 255, np.uint8)
            rgba[:, : col.shape[1]] = col.astype(np.uint8)
            colors = rgba[faces]
    return Soup(
        np.asarray(geom.vertices, np.float64),
        faces,
        part_names=[name],
        material_id=np.full(len(faces), material_index, np.int64),
        uv=uv,
        colors=colors,
    )


def soup_from_trimesh(geom, name: str, materials: list, index: dict) -> Soup:
    """A trimesh mesh as a one-part soup; its material is added to ``materials`` once.

    ``index`` maps ``id(trimesh material)`` to its position in ``materials``.
    """
    mat = getattr(getattr(geom, "visual", None), "material", None)
    mid = -1
    if mat is not None:
        key = id(mat)
        if key not in index:
            index[key] = len(materials)
            materials.append(Material(str(getattr(mat, "name", None) or f"material{len(materials)}"), mat))
        mid = index[key]
    return mesh_soup(geom, name, mid)
