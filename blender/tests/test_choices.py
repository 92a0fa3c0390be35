"""The panel's choices reach the library: Orient's viewers and Remove Hidden's levels."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest
from blender_helpers import cli, same_winding, triangles
from test_operators import _box_around_ball, _flipped_soup_file, _select


def test_the_viewers_are_the_camera_the_box_of_an_empty_or_the_upper_hemisphere(bpy, installed, empty_scene):
    import meshvis

    region_text = installed.operators.region_text
    bpy.ops.object.camera_add(location=(3.0, -1.0, 2.0))
    empty_scene.camera = bpy.context.active_object
    assert region_text(bpy.context, "CAMERA", "") == "points:3.0,-1.0,2.0"
    bpy.ops.object.empty_add(type="CUBE", location=(0.0, 0.0, 5.0))
    box = bpy.context.active_object
    box.name, box.scale = "viewers", (2.0, 1.0, 1.0)
    bpy.context.view_layer.update()
    text = region_text(bpy.context, "BOX", "viewers")
    corners = np.array([float(v) for v in text.removeprefix("box:").split(",")])
    np.testing.assert_allclose(corners, [-2, -1, 4, 2, 1, 6])  # the empty's display size is 1
    for choice in ("OUTSIDE", "UPPER", "CAMERA", "BOX"):
        meshvis.parse_region(region_text(bpy.context, choice, "viewers"))  # the library reads each
    with pytest.raises(ValueError, match="no empty named"):
        region_text(bpy.context, "BOX", "nowhere")


def test_orient_toward_the_active_camera_gives_meshvis_orient_from_its_point(
    bpy, installed, empty_scene, tmp_path
):
    import meshvis

    given, out = str(tmp_path / "spot_flipped.stl"), str(tmp_path / "oriented.stl")
    corners, faces = _flipped_soup_file(meshvis, "spot.obj", given)
    ob = installed.convert.new_mesh_object("spot", corners, faces)
    bpy.ops.object.camera_add(location=(3.0, 0.5, 1.0))
    empty_scene.camera = bpy.context.active_object
    _select(bpy, [ob])
    assert bpy.ops.meshvis.orient(region="CAMERA") == {"FINISHED"}
    subprocess.run([*cli(), "orient", given, "-o", out, "--from", "points:3.0,0.5,1.0", "-q"], check=True)
    expected = meshvis.load(out).triangles
    got = triangles(ob)
    assert got.shape == expected.shape and same_winding(got, expected).all()
    assert not same_winding(got, corners[faces].astype(np.float64)).all()  # it did turn faces


@pytest.mark.parametrize("level, removed", [("FACE", "some"), ("PATCH", "none"), ("PART", "none")])
def test_a_ball_through_the_case_loses_its_inner_faces_only_at_face_level(
    bpy, installed, empty_scene, level, removed
):
    """The ball pokes out of the closed case: its faces inside are hidden, but as a patch
    (closed) and as an object it shows, and is kept whole."""
    box, ball = _box_around_ball(installed, bpy)
    ball.location = (0.9, 0.0, 0.0)  # through the case's +x side
    bpy.context.view_layer.update()
    _select(bpy, [box, ball])
    assert bpy.ops.meshvis.remove_hidden(action="SELECT", level=level) == {"FINISHED"}
    picked = np.empty(len(ball.data.polygons), bool)
    ball.data.polygons.foreach_get("select", picked)
    assert (0 < picked.sum() < len(picked)) if removed == "some" else not picked.any()
    assert not any(p.select for p in box.data.polygons)
