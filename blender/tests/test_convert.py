"""Blender meshes to arrays and back: turned polygons keep their corners' data."""

from __future__ import annotations

import numpy as np
from blender_helpers import polygons


def _corner(me, key, width, layer=None):
    data = layer.data if layer is not None else me.loops
    out = np.empty(width * len(me.loops), np.float32)
    data.foreach_get(key, out)
    return out.reshape(-1, width)


def _custom(me):
    out = np.empty(3 * len(me.loops), np.float32)
    me.corner_normals.foreach_get("vector", out)  # Blender 4.1 and later
    return out.reshape(-1, 3)


def test_turned_polygons_keep_uvs_colours_and_custom_normals_at_their_vertices(bpy, installed, empty_scene):
    bpy.ops.mesh.primitive_cylinder_add(vertices=7)  # quads and two 7-gons
    ob = bpy.context.active_object
    me = ob.data
    colour = me.color_attributes.new("tint", "BYTE_COLOR", "CORNER")
    rng = np.random.default_rng(0)
    colour.data.foreach_set("color_srgb", (rng.integers(0, 256, 4 * len(me.loops)) / 255).astype(np.float32))
    me.shade_smooth()
    me.edges.foreach_set("use_edge_sharp", np.ones(len(me.edges), bool))  # a normal per corner
    normals = rng.normal(size=(len(me.loops), 3))
    me.normals_split_custom_set(normals / np.linalg.norm(normals, axis=1, keepdims=True))
    me.polygons.foreach_get("normal", face_before := np.empty(3 * len(me.polygons), np.float32))
    before = polygons(ob)
    uv = _corner(me, "uv", 2, me.uv_layers.active)
    tint = _corner(me, "color_srgb", 4, colour)
    custom = _custom(me)
    flip = np.zeros(len(me.polygons), bool)
    flip[[0, 3, len(flip) - 1]] = True

    assert installed.convert.flip_polygons(me, flip) == 3
    after = polygons(ob)
    me.polygons.foreach_get("normal", face_after := np.empty(3 * len(me.polygons), np.float32))
    sign = np.einsum("ij,ij->i", face_before.reshape(-1, 3), face_after.reshape(-1, 3))
    assert np.array_equal(sign < 0, flip)
    uv2, tint2 = _corner(me, "uv", 2, me.uv_layers.active), _corner(me, "color_srgb", 4, colour)
    start = np.empty(len(me.polygons), np.int32)
    me.polygons.foreach_get("loop_start", start)
    custom2 = _custom(me)
    for p, (a, b) in enumerate(zip(before, after)):
        assert np.array_equal(np.sort(a), np.sort(b))
        assert np.array_equal(b, np.r_[a[:1], a[:0:-1]] if flip[p] else a)
        old = {v: start[p] + k for k, v in enumerate(a)}
        new = {v: start[p] + k for k, v in enumerate(b)}
        for v in a:  # every corner's data stayed with its vertex
            assert np.array_equal(uv[old[v]], uv2[new[v]])
            assert np.array_equal(tint[old[v]], tint2[new[v]])
            sign = -1 if flip[p] else 1
            assert np.allclose(custom[old[v]], sign * custom2[new[v]], atol=2e-3)
    assert me.validate() is False  # nothing to repair


def test_a_mirrored_object_is_wound_as_blender_shows_it(bpy, installed, empty_scene):
    bpy.ops.mesh.primitive_cube_add()
    ob = bpy.context.active_object
    ob.scale = (-1, 1, 1)
    bpy.context.view_layer.update()
    scene = installed.convert.read_scene([ob])
    soup = scene.soup()
    centre = soup.vertices.mean(axis=0)
    outward = np.einsum("ij,ij->i", soup.normals, soup.triangles.mean(axis=1) - centre)
    assert (outward > 0).all()


def test_polygons_take_the_answer_of_their_triangles(bpy, installed, empty_scene):
    bpy.ops.mesh.primitive_cube_add()
    ob = bpy.context.active_object
    scene = installed.convert.read_scene([ob])
    tri_poly = scene.triangle_polygon
    assert len(tri_poly) == 12 and np.array_equal(np.bincount(tri_poly), [2] * 6)
    one = np.zeros(12, bool)
    one[np.flatnonzero(tri_poly == 2)[0]] = True
    assert np.flatnonzero(scene.per_polygon(one, "any")[0]).tolist() == [2]
    assert not scene.per_polygon(one, "all")[0].any()
    layer = np.where(tri_poly == 4, 1, 2)
    layer[np.flatnonzero(tri_poly == 5)[0]] = 1
    assert scene.per_polygon(layer, "min")[0].tolist() == [2, 2, 2, 2, 1, 1]


def test_which_materials_are_see_through(bpy, installed, empty_scene):
    is_transparent = installed.convert.is_transparent
    plain = bpy.data.materials.new("plain")
    assert not is_transparent(plain) and not is_transparent(None)
    blended = bpy.data.materials.new("blended")
    blended.surface_render_method = "BLENDED"
    faded = bpy.data.materials.new("faded")
    faded.use_nodes = True
    faded.node_tree.nodes["Principled BSDF"].inputs["Alpha"].default_value = 0.5
    solid = bpy.data.materials.new("solid")
    solid.use_nodes = True
    assert is_transparent(blended) and is_transparent(faded) and not is_transparent(solid)
