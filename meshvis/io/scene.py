"""trimesh objects as soups.

A ``trimesh.Scene`` (instancing applied) or one mesh with its visual (UVs, colours,
material).  Used by the glTF and 3MF readers and by :func:`meshvis.io.as_soup`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from meshvis.errors import ModelError
from meshvis.io.edits import face_edits
from meshvis.soup import Material, Soup, SourceRecord, validate


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
    rows: list[tuple[Any, str, int]] = []  # node, geometry, mirrored
    for node in scene.graph.nodes_geometry:
        matrix, geom_name = scene.graph[node]
        geom = scene.geometry.get(geom_name)
        if geom is None or not hasattr(geom, "faces") or len(geom.faces) == 0:
            continue
        part = soup_from_trimesh(geom, str(node), mats, materials)
        parts.append(part.transformed(matrix) if not np.allclose(matrix, np.eye(4)) else part)
        rows.append((node, geom_name, int(np.linalg.det(np.asarray(matrix)[:3, :3]) < 0)))
    if not parts:
        raise ModelError("the model has no faces", path)
    soup = Soup.concatenate(parts)
    soup.materials = mats
    soup.path = path
    validate(soup.vertices, soup.faces, path)
    n_v = np.array([p.n_vertices for p in parts], np.int64)
    n_f = np.array([p.n_faces for p in parts], np.int64)
    offsets = np.column_stack([np.cumsum(n_v) - n_v, np.cumsum(n_f) - n_f, [r[2] for r in rows]])
    record = TrimeshSource(scene, [r[0] for r in rows], [r[1] for r in rows], offsets)
    soup.source = SourceRecord("trimesh", soup.vertices, soup.faces.copy(), record)
    return soup


def soup_from_mesh(mesh, path: str | None = None) -> Soup:
    """One ``trimesh.Trimesh`` as a soup with its visual (UVs, colours, material).

    :meth:`Soup.to_trimesh` of the soup (or of a repair of it) gives a ``Trimesh`` back
    with the input's visual.
    """
    validate(np.asarray(mesh.vertices), np.asarray(mesh.faces), path)
    mats: list = []
    soup = soup_from_trimesh(mesh, "mesh", mats, {})
    soup.materials = mats
    soup.path = path
    offsets = np.zeros((1, 3), np.int64)
    soup.source = SourceRecord(
        "trimesh", soup.vertices, soup.faces.copy(), TrimeshSource(mesh, [None], [None], offsets)
    )
    return soup


@dataclass(eq=False)
class TrimeshSource:
    """The trimesh object a soup came from.

    :meth:`Soup.to_trimesh` uses it to give the same kind back with its visuals.

    Parameters
    ----------
    obj : trimesh.Trimesh or trimesh.Scene
        The trimesh object the soup was made from.
    nodes, geometries : list
        Per piece (a geometry node of the scene; the mesh itself for a ``Trimesh``): the
        node and geometry names (None for a ``Trimesh``).
    offsets : (k, 3) int64
        Per piece: first vertex and first face in the soup as read, and 1 when the node's
        transform mirrors (the soup's faces are then the geometry's turned over).
    """

    obj: Any
    nodes: list
    geometries: list
    offsets: np.ndarray

    def to_trimesh(self, soup: Soup):
        """The input object with the soup's faces, or None when the soup is not an edit of it.

        A ``Trimesh`` comes back as a ``Trimesh`` (visual, UVs, colours, material and
        vertex normals kept); a ``Scene`` as a ``Scene`` with its graph, transforms and
        visuals, a geometry shared by nodes that need different faces copied for them.
        """
        edits = face_edits(soup, ("trimesh",))
        if edits is None:
            return None
        first_face = self.offsets[:, 1]
        piece_of = np.searchsorted(first_face, edits.origin, side="right") - 1
        local = []
        for p in range(len(self.offsets)):
            sel = np.flatnonzero(piece_of == p)
            faces = soup.faces[sel] - self.offsets[p, 0]
            local.append(
                (faces[:, [0, 2, 1]] if self.offsets[p, 2] else faces, edits.origin[sel] - first_face[p])
            )
        if self.nodes == [None]:
            return _edited(self.obj, *local[0])
        return self._scene(local)

    def _scene(self, local: list):
        out = self.obj.copy()
        variants: dict = {}
        for p, (faces, origin) in enumerate(local):
            key = (self.geometries[p], faces.tobytes(), origin.tobytes())
            variants.setdefault(self.geometries[p], {}).setdefault(key, []).append(p)
        for geom_name, keyed in variants.items():
            source = self.obj.geometry[geom_name]
            for k, (key, pieces) in enumerate(keyed.items()):
                faces, origin = local[pieces[0]]
                edited = _edited(source, faces, origin)
                if k == 0:
                    out.geometry[geom_name] = edited
                    continue
                name = f"{geom_name}_{k}"  # nodes that need other faces than the first: a copy
                out.geometry[name] = edited
                for p in pieces:
                    _repoint(out.graph, self.nodes[p], name)
        return out


def _repoint(graph, node, geometry: str) -> None:
    """Let ``node`` draw ``geometry``, keeping its parent and local transform."""
    parent = graph.transforms.parents.get(node)
    edge = graph.transforms.edge_data.get((parent, node), {})
    matrix = edge.get("matrix", np.eye(4))
    graph.update(frame_from=parent, frame_to=node, matrix=matrix, geometry=geometry)


def _edited(mesh, faces: np.ndarray, origin: np.ndarray):
    """A copy of ``mesh`` with ``faces`` (its per-face colours following ``origin``)."""
    out = mesh.copy()
    normals = mesh.vertex_normals if "vertex_normals" in mesh._cache else None
    kind = getattr(mesh.visual, "kind", None)
    face_colors = np.asarray(mesh.visual.face_colors)[origin] if kind == "face" else None
    out.faces = np.asarray(faces, np.int64)
    if face_colors is not None:
        out.visual.face_colors = face_colors
    if normals is not None and len(normals) == len(out.vertices):
        out.vertex_normals = normals
    return out


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
