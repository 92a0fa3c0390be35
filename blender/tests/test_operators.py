"""The operators in Blender give the command line's faces, keep what they keep, and undo."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest
from blender_helpers import cli, polygons, same_winding, shared_model, triangles

#: share of faces turned over in the flipped copy
FLIPPED_SHARE = 0.3


def _select(bpy, objects):
    for ob in bpy.context.scene.objects:
        ob.select_set(ob in objects)
    bpy.context.view_layer.objects.active = objects[0]


def _flipped_soup_file(meshvis, name: str, path: str):
    """A shared model unwelded, 30 % of its faces flipped, written as binary STL (float32)."""
    soup = meshvis.load(shared_model(name))
    corners = soup.triangles.astype(np.float32).reshape(-1, 3)
    faces = np.arange(len(corners)).reshape(-1, 3)
    flip = np.random.default_rng(1).random(len(faces)) < FLIPPED_SHARE
    faces[flip] = faces[flip][:, ::-1]
    meshvis.save(meshvis.Soup(corners.astype(np.float64), faces), path)
    return corners, faces


def test_orient_gives_the_faces_and_windings_of_meshvis_orient(bpy, installed, empty_scene, tmp_path):
    import meshvis

    given, out = str(tmp_path / "spot_flipped.stl"), str(tmp_path / "oriented.stl")
    corners, faces = _flipped_soup_file(meshvis, "spot.obj", given)
    subprocess.run([*cli(), "orient", given, "-o", out, "-q"], check=True)
    expected = meshvis.load(out).triangles

    ob = installed.convert.new_mesh_object("spot", corners, faces)
    _select(bpy, [ob])
    assert bpy.ops.meshvis.orient() == {"FINISHED"}
    got = triangles(ob)
    assert got.shape == expected.shape
    assert same_winding(got, expected).all()
    before = corners[faces].astype(np.float64)
    assert not same_winding(got, before).all()  # it did turn faces


def _box_around_ball(installed, bpy):
    """An outer box with a UV map and a material, and a ball inside it, as two objects."""
    bpy.ops.mesh.primitive_cube_add(size=2.0)
    box = bpy.context.active_object
    box.name = "case"
    box.data.materials.append(bpy.data.materials.new("paint"))
    bpy.ops.mesh.primitive_ico_sphere_add(subdivisions=2, radius=0.4, location=(0.2, 0.0, 0.0))
    ball = bpy.context.active_object
    ball.name = "core"
    return box, ball


def _world_soup_file(meshvis, objects, path):
    """The objects' triangles in world space as one STL file, in the add-on's face order."""
    tris = []
    for ob in objects:
        m = np.array(ob.matrix_world)
        ob.data.calc_loop_triangles()
        t = np.empty(3 * len(ob.data.loop_triangles), np.int32)
        ob.data.loop_triangles.foreach_get("vertices", t)
        co = np.empty(3 * len(ob.data.vertices), np.float32)
        ob.data.vertices.foreach_get("co", co)
        world = co.reshape(-1, 3).astype(np.float64) @ m[:3, :3].T + m[:3, 3]
        tris.append(world[t.reshape(-1, 3)])
    corners = np.concatenate(tris).reshape(-1, 3)
    meshvis.save(meshvis.Soup(corners, np.arange(len(corners)).reshape(-1, 3)), path)


@pytest.mark.parametrize("action", ["DELETE", "SELECT", "SEPARATE"])
def test_remove_hidden_takes_out_the_inner_part_as_meshvis_remove_interior_does(
    bpy, installed, empty_scene, tmp_path, action
):
    import meshvis

    box, ball = _box_around_ball(installed, bpy)
    given, out = str(tmp_path / "both.stl"), str(tmp_path / "kept.stl")
    _world_soup_file(meshvis, [box, ball], given)
    report = tmp_path / "report.json"
    subprocess.run([*cli(), "remove-interior", given, "-o", out, "--report", str(report), "-q"], check=True)
    import json

    keep = np.array(json.loads(report.read_text())["per_face"]["keep"], bool)
    n_box = 2 * len(box.data.polygons)  # the cube's quads are two triangles each
    assert keep[:n_box].all() and not keep[n_box:].any()  # the command line's answer

    uv_before = np.empty(2 * len(box.data.loops), np.float32)
    box.data.uv_layers.active.data.foreach_get("uv", uv_before)
    balls = len(ball.data.polygons)
    _select(bpy, [box, ball])
    assert bpy.ops.meshvis.remove_hidden(action=action) == {"FINISHED"}
    if action == "SELECT":
        sel = np.empty(balls, bool)
        ball.data.polygons.foreach_get("select", sel)
        assert sel.all() and not any(p.select for p in box.data.polygons)
    else:
        assert "core" not in bpy.data.objects or len(bpy.data.objects["core"].data.polygons) == 0
        if action == "SEPARATE":
            moved = [ob for ob in bpy.data.objects if ob.name.endswith("hidden")]
            assert [len(ob.data.polygons) for ob in moved] == [balls]
    assert len(box.data.polygons) == 6 and box.data.materials[0].name == "paint"
    uv_after = np.empty(2 * len(box.data.loops), np.float32)
    box.data.uv_layers.active.data.foreach_get("uv", uv_after)
    assert np.array_equal(uv_before, uv_after)


@pytest.mark.parametrize("see_through", [True, False])
def test_a_glass_case_lets_the_part_inside_be_seen(bpy, installed, empty_scene, capfd, see_through):
    box, ball = _box_around_ball(installed, bpy)
    glass = box.data.materials[0]
    glass.surface_render_method = "BLENDED"  # Blender 4.2's transparent material
    balls = len(ball.data.polygons)
    _select(bpy, [box, ball])
    assert bpy.ops.meshvis.remove_hidden(action="SELECT", see_through=see_through) == {"FINISHED"}
    sel = np.empty(balls, bool)
    ball.data.polygons.foreach_get("select", sel)
    # through the glass the ball is seen and stays; behind an opaque case it is hidden
    assert not sel.any() if see_through else sel.all()
    # the removal's self-check is the operator's report
    assert "self-check: " in capfd.readouterr().out


def test_undo_gives_back_the_faces_before_orient(bpy, installed, empty_scene):
    bpy.ops.ed.undo_push(message="empty")  # undo needs a step before the one undone
    bpy.ops.mesh.primitive_uv_sphere_add(segments=16, ring_count=8)
    ob = bpy.context.active_object
    name = ob.name  # undo replaces the object's Python wrapper
    flip = np.zeros(len(ob.data.polygons), bool)
    flip[::3] = True
    installed.convert.flip_polygons(ob.data, flip)
    before = [p.copy() for p in polygons(ob)]
    bpy.ops.ed.undo_push(message="flipped")
    # undo=True: the call pushes the operator's undo step as a click in the panel does
    assert bpy.ops.meshvis.orient("EXEC_DEFAULT", True) == {"FINISHED"}
    ob = bpy.data.objects[name]
    oriented = polygons(ob)
    assert sum(not np.array_equal(a, b) for a, b in zip(before, oriented)) == flip.sum()
    bpy.ops.ed.undo()
    ob = bpy.data.objects[name]
    assert all(np.array_equal(a, b) for a, b in zip(before, polygons(ob)))
    bpy.ops.ed.redo()
    ob = bpy.data.objects[name]
    assert all(np.array_equal(a, b) for a, b in zip(oriented, polygons(ob)))


def test_layers_make_a_collection_per_layer_and_hide_the_originals(bpy, installed, empty_scene):
    box, ball = _box_around_ball(installed, bpy)
    _select(bpy, [box, ball])
    assert bpy.ops.meshvis.layers() == {"FINISHED"}
    parent = bpy.data.collections["meshvis layers"]
    names = {c.name: sorted(o.name for o in c.objects) for c in parent.children}
    assert names == {"Layer 1": ["case layer 1"], "Layer 2": ["core layer 2"]}
    assert len(bpy.data.objects["core layer 2"].data.polygons) == len(ball.data.polygons)
    assert box.hide_get() and ball.hide_get()


def test_label_parts_puts_each_label_where_the_layout_put_its_box(bpy, installed, empty_scene):
    import meshvis.labeling

    bpy.ops.mesh.primitive_cube_add(location=(-1.2, 0, 0))
    left = bpy.context.active_object
    left.name = "left block"
    bpy.ops.mesh.primitive_ico_sphere_add(location=(1.2, 0, 0))
    right = bpy.context.active_object
    right.name = "right ball"
    bpy.ops.object.camera_add(location=(0, -9, 2))
    cam = bpy.context.active_object
    cam.rotation_euler = (np.radians(80), 0, 0)
    bpy.context.scene.camera = cam
    _select(bpy, [left, right])
    assert bpy.ops.meshvis.label_parts(resolution=400) == {"FINISHED"}
    texts = [o for o in bpy.data.collections["meshvis labels"].objects if o.type == "FONT"]
    assert sorted(o.data.body for o in texts) == ["left block", "right ball"]
    # seen through the camera, each text stands in the box the library's layout gave it
    size = installed.labels.image_size(bpy.context.scene, 400)
    camera = installed.labels.camera(cam, size)
    soup = installed.convert.read_scene([left, right]).soup()
    boxes = {lab.text: lab.box for lab in meshvis.labeling.layout(soup, camera, size=size).labels}
    for ob in texts:
        x, y = camera.project(np.array(ob.matrix_world.translation)[None], *size)[0][0]
        x0, y0, x1, y1 = boxes[ob.data.body]
        assert x0 - 0.5 <= x <= x1 + 0.5 and y0 <= y <= y1
    assert len([o for o in bpy.data.collections["meshvis labels"].objects if o.type == "CURVE"]) == 2
    # again: the labels are replaced, not added
    assert bpy.ops.meshvis.label_parts(resolution=400) == {"FINISHED"}
    assert len(bpy.data.collections["meshvis labels"].objects) == 4
