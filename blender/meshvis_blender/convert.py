# SPDX-License-Identifier: GPL-3.0-or-later
"""Blender meshes as one triangle soup in world space, and the library's answers written back.

Every array crosses with ``foreach_get`` / ``foreach_set``; nothing loops over faces in
Python.  Polygons are cut into Blender's own loop triangles, and each triangle remembers
its object and polygon, so that an answer per triangle becomes an answer per polygon.
What is written back is the mesh the object's modifiers take as input (its own data):
modifiers stay, and turned polygons keep every corner attribute (UV maps, colours, custom
normals) at the vertex it belonged to.
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np

#: foreach key, NumPy type and values per element of each attribute type
ATTRIBUTE_LAYOUT = {
    "FLOAT": ("value", np.float32, 1),
    "INT": ("value", np.int32, 1),
    "INT8": ("value", np.int32, 1),
    "BOOLEAN": ("value", bool, 1),
    "FLOAT2": ("vector", np.float32, 2),
    "INT32_2D": ("value", np.int32, 2),
    "INT16_2D": ("value", np.int32, 2),
    "FLOAT_VECTOR": ("vector", np.float32, 3),
    "FLOAT_COLOR": ("color", np.float32, 4),
    "BYTE_COLOR": ("color_srgb", np.float32, 4),
    "QUATERNION": ("value", np.float32, 4),
    "FLOAT4X4": ("value", np.float32, 16),
}
#: corner attributes that the loops themselves hold (written through ``mesh.loops``)
CORNER_TOPOLOGY = (".corner_vert", ".corner_edge")


def _get(collection, key: str, n: int, dtype, width: int = 1) -> np.ndarray:
    out = np.empty(n * width, dtype)
    collection.foreach_get(key, out)
    return out.reshape(n, width) if width > 1 else out


@dataclass
class Scene:
    """Selected mesh objects as one soup in world space.

    Attributes
    ----------
    objects : list of bpy.types.Object
    vertices : (n, 3) float64, world coordinates of every object's vertices, stacked
    faces : (m, 3) int64, loop triangles into ``vertices``, counter-clockwise seen from the
        side Blender shows as the front (reversed for objects with a mirroring transform)
    triangle_object : (m,) int64, index into ``objects`` of each triangle
    triangle_polygon : (m,) int64, index of each triangle's polygon in its object's mesh
    polygon_counts : (k,) int64, polygons of each object
    transparent : (m,) bool, triangles whose material lets light through
    """

    objects: list
    vertices: np.ndarray
    faces: np.ndarray
    triangle_object: np.ndarray
    triangle_polygon: np.ndarray
    polygon_counts: np.ndarray
    transparent: np.ndarray

    def soup(self):
        """The :class:`meshvis.Soup`: one part per object (named for it), z up as in Blender.

        Its two materials tell the library which faces are see-through (:attr:`transparent`).
        """
        from meshvis.soup import Material, Soup

        return Soup(
            self.vertices,
            self.faces,
            part_id=self.triangle_object,
            part_names=[ob.name for ob in self.objects],
            material_id=self.transparent.astype(np.int64),
            materials=[Material("opaque"), Material("see-through", see_through=True)],
            up=(0.0, 0.0, 1.0),
        )

    def per_polygon(self, values: np.ndarray, how: str = "any") -> list[np.ndarray]:
        """A per-triangle array as one per-polygon array per object.

        ``how``: ``"any"`` (a bool polygon is True when one of its triangles is),
        ``"all"``, ``"min"`` (the smallest value of its triangles) or ``"area"`` (a bool
        polygon takes the value of the larger area of its triangles).
        """
        values = np.asarray(values)
        out = []
        for k, n in enumerate(self.polygon_counts):
            rows = self.triangle_object == k
            poly = self.triangle_polygon[rows]
            v = values[rows]
            if how == "any":
                out.append(np.bincount(poly, weights=v.astype(np.float64), minlength=n) > 0)
            elif how == "all":
                out.append(np.bincount(poly, weights=(~v.astype(bool)).astype(np.float64), minlength=n) == 0)
            elif how == "min":
                best = np.full(n, np.iinfo(np.int64).max)
                np.minimum.at(best, poly, v.astype(np.int64))
                out.append(best)
            elif how == "area":
                area = _areas(self.vertices, self.faces[rows])
                yes = np.bincount(poly, weights=area * v, minlength=n)
                no = np.bincount(poly, weights=area * ~v.astype(bool), minlength=n)
                out.append(yes > no)
            else:
                raise ValueError(how)
        return out


def _areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    t = vertices[faces]
    return 0.5 * np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)


def read_scene(objects) -> Scene:
    """The mesh objects ``objects`` (their own meshes, before modifiers) in world space."""
    objects = [ob for ob in objects if ob.type == "MESH"]
    verts, faces, tri_ob, tri_poly, counts, see_through = [], [], [], [], [], []
    offset = 0
    for k, ob in enumerate(objects):
        me = ob.data
        me.calc_loop_triangles()
        nv, nt = len(me.vertices), len(me.loop_triangles)
        co = _get(me.vertices, "co", nv, np.float32, 3).astype(np.float64)
        m = np.array(ob.matrix_world, np.float64)
        world = co @ m[:3, :3].T + m[:3, 3]
        tris = _get(me.loop_triangles, "vertices", nt, np.int32, 3).astype(np.int64)
        if np.linalg.det(m[:3, :3]) < 0:  # a mirroring transform turns the winding over
            tris = tris[:, ::-1]
        poly = _get(me.loop_triangles, "polygon_index", nt, np.int32).astype(np.int64)
        verts.append(world)
        faces.append(tris + offset)
        tri_ob.append(np.full(nt, k, np.int64))
        tri_poly.append(poly)
        counts.append(len(me.polygons))
        see_through.append(transparent_polygons(ob)[poly])
        offset += nv
    if not objects:
        raise ValueError("no mesh object selected")
    return Scene(
        objects,
        np.concatenate(verts),
        np.concatenate(faces),
        np.concatenate(tri_ob),
        np.concatenate(tri_poly),
        np.array(counts, np.int64),
        np.concatenate(see_through),
    )


def is_transparent(material) -> bool:
    """Whether a material lets one see through it.

    Blended (its render method), or a Principled BSDF whose alpha is below 1 or driven by a
    texture, or a Transparent BSDF in its nodes.
    """
    if material is None:
        return False
    # Blender 4.2 reads the older blend_method from this: every new material is "HASHED" there
    if material.surface_render_method == "BLENDED":
        return True
    if material.use_nodes and material.node_tree is not None:
        for node in material.node_tree.nodes:
            alpha = node.inputs.get("Alpha") if node.type == "BSDF_PRINCIPLED" else None
            if alpha is not None and (alpha.is_linked or alpha.default_value < 1.0):
                return True
            if node.type == "BSDF_TRANSPARENT":
                return True
    return False


def transparent_polygons(ob) -> np.ndarray:
    """(polygons,) bool: the polygon's material slot holds a transparent material."""
    me = ob.data
    n = len(me.polygons)
    slots = [is_transparent(s.material) for s in ob.material_slots]
    if not any(slots):
        return np.zeros(n, bool)
    index = _get(me.polygons, "material_index", n, np.int32)
    table = np.array(slots + [False], bool)
    return table[np.clip(index, 0, len(slots))]


def _corners(me) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per polygon its first corner and corner count; per corner its polygon."""
    n = len(me.polygons)
    start = _get(me.polygons, "loop_start", n, np.int32).astype(np.int64)
    total = _get(me.polygons, "loop_total", n, np.int32).astype(np.int64)
    return start, total, np.repeat(np.arange(n), total)


def flip_polygons(me, flip: np.ndarray) -> int:
    """Turn the polygons ``flip`` over: each lists its corners the other way round.

    A turned polygon keeps its first corner; corner ``j`` takes what corner ``n - j`` held
    (vertex and every corner attribute), and the edge between them.  Custom normals turn
    with their polygons.  Returns the number of polygons turned.
    """
    flip = np.asarray(flip, bool)
    if not flip.any():
        return 0
    start, total, poly = _corners(me)
    nl = len(me.loops)
    corner = np.arange(nl) - start[poly]
    n = total[poly]
    turned = flip[poly]
    src = np.where(turned, start[poly] + (n - corner) % n, np.arange(nl))
    edge_src = np.where(turned, start[poly] + (n - corner - 1) % n, np.arange(nl))
    normals = None
    if me.has_custom_normals:
        normals = _corner_normals(me, nl)[src]
        normals[turned] *= -1
    vert = _get(me.loops, "vertex_index", nl, np.int32)
    edge = _get(me.loops, "edge_index", nl, np.int32)
    me.loops.foreach_set("vertex_index", vert[src])
    me.loops.foreach_set("edge_index", edge[edge_src])
    for attr in list(me.attributes):
        if attr.domain == "CORNER" and attr.name not in CORNER_TOPOLOGY:
            _permute(attr, nl, src)
    me.update()  # the new winding's face normals, which the custom normals are stored against
    if normals is not None:
        me.normals_split_custom_set(normals)
        me.update()
    return int(flip.sum())


def _corner_normals(me, nl: int) -> np.ndarray:
    if hasattr(me, "corner_normals"):  # Blender 4.1 and later
        return _get(me.corner_normals, "vector", nl, np.float32, 3).astype(np.float64)
    me.calc_normals_split()
    return _get(me.loops, "normal", nl, np.float32, 3).astype(np.float64)


def _permute(attr, n: int, order: np.ndarray) -> None:
    layout = ATTRIBUTE_LAYOUT.get(attr.data_type)
    if layout is None:  # strings: no corner data of a mesh holds them
        return
    key, dtype, width = layout
    values = _get(attr.data, key, n, dtype, width)
    attr.data.foreach_set(key, values[order].ravel())


def select_polygons(me, select: np.ndarray) -> None:
    """Select exactly the polygons ``select``, with their edges and vertices."""
    select = np.asarray(select, bool)
    start, total, poly = _corners(me)
    nl = len(me.loops)
    corner_on = select[poly]
    verts = np.zeros(len(me.vertices), bool)
    edges = np.zeros(len(me.edges), bool)
    verts[_get(me.loops, "vertex_index", nl, np.int32)[corner_on]] = True
    edges[_get(me.loops, "edge_index", nl, np.int32)[corner_on]] = True
    me.polygons.foreach_set("select", select)
    me.edges.foreach_set("select", edges)
    me.vertices.foreach_set("select", verts)
    me.update()


def delete_polygons(context, targets: list[tuple[object, np.ndarray]], separate: bool = False) -> list:
    """Delete (or move to new objects) the polygons given per object, in one edit-mode pass.

    Blender's own edit-mode operators do the deletion, so every kind of mesh data (vertex
    groups, shape keys, UVs, attributes) stays consistent.  Returns the objects that
    ``separate`` made.  Objects whose mask is empty are left alone.
    """
    targets = [(ob, np.asarray(mask, bool)) for ob, mask in targets if np.asarray(mask, bool).any()]
    if not targets:
        return []
    view_layer = context.view_layer
    before_active = view_layer.objects.active
    before_selected = [ob for ob in context.scene.objects if ob.select_get()]
    before = set(bpy.data.objects)
    for ob in before_selected:
        ob.select_set(False)
    for ob, mask in targets:
        select_polygons(ob.data, mask)
        ob.select_set(True)
    view_layer.objects.active = targets[0][0]
    tool = context.scene.tool_settings
    mode = tuple(tool.mesh_select_mode)
    tool.mesh_select_mode = (False, False, True)
    bpy.ops.object.mode_set(mode="EDIT")
    try:
        if separate:
            bpy.ops.mesh.separate(type="SELECTED")
        else:
            bpy.ops.mesh.delete(type="FACE")
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
        tool.mesh_select_mode = mode
    made = [ob for ob in bpy.data.objects if ob not in before]
    for ob in context.scene.objects:
        ob.select_set(ob in before_selected)
    view_layer.objects.active = before_active
    return made


def new_mesh_object(name: str, vertices: np.ndarray, faces: np.ndarray, collection=None):
    """A mesh object from arrays (triangles), linked into ``collection`` (the scene's by default)."""
    me = bpy.data.meshes.new(name)
    vertices = np.asarray(vertices, np.float32).reshape(-1, 3)
    faces = np.asarray(faces, np.int32).reshape(-1, 3)
    me.vertices.add(len(vertices))
    me.vertices.foreach_set("co", vertices.ravel())
    me.loops.add(faces.size)
    me.loops.foreach_set("vertex_index", faces.ravel())
    me.polygons.add(len(faces))
    me.polygons.foreach_set("loop_start", np.arange(0, faces.size, 3, dtype=np.int32))
    me.update(calc_edges=True)
    ob = bpy.data.objects.new(name, me)
    (collection or bpy.context.scene.collection).objects.link(ob)
    return ob
