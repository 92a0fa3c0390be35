"""One up-axis rule for everything that draws: glTF y (its specification), OBJ y, others z."""

import numpy as np
import pytest
from helpers import real_model

import meshvis
from meshvis.cli.main import main
from meshvis.labeling import layout
from meshvis.labeling.pipeline import fit_camera
from meshvis.rays.camera import Camera, model_up, up_axis


@pytest.mark.parametrize(
    ("name", "up"),
    [
        ("a.glb", "y"),
        ("a.gltf", "y"),
        ("a.obj", "y"),
        ("a.STL", "z"),
        ("a.ply", "z"),
        ("a.off", "z"),
        ("a.3mf", "z"),
    ],
)
def test_the_rule_by_format(name, up):
    assert up_axis("auto", [name]) == {"x": (1.0, 0, 0), "y": (0, 1.0, 0), "z": (0, 0, 1.0)}[up]


def test_disagreeing_files_and_no_file_fall_back_to_z():
    assert up_axis("auto", ["a.glb", "b.stl"]) == (0.0, 0.0, 1.0)
    assert up_axis("auto", []) == (0.0, 0.0, 1.0)
    assert up_axis("x", ["a.glb"]) == (1.0, 0.0, 0.0)


def test_library_and_cli_agree_on_the_truck():
    path = real_model("CesiumMilkTruck.glb")
    soup = meshvis.load(path)
    assert model_up(soup) == model_up(path) == (0.0, 1.0, 0.0)
    assert np.allclose(Camera.fit(soup).up, [0, 1, 0])
    assert np.allclose(fit_camera(soup).up, [0, 1, 0])
    result = layout(path, size=(96, 96))
    assert np.allclose(result.camera.up, [0, 1, 0])


def test_teapot_is_drawn_y_up():
    soup = meshvis.load(real_model("teapot.obj"))
    camera = Camera.fit(soup)
    assert np.allclose(camera.up, [0, 1, 0])
    # the camera looks at the teapot from above its horizon, not from its side
    assert camera.position[1] > camera.target[1]


def test_repair_preview_takes_up(tmp_path):
    path = tmp_path / "ball.obj"
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=1)
    meshvis.save((sphere.vertices, sphere.faces), str(path))
    png = tmp_path / "p.png"
    args = ["orient", str(path), "-o", str(tmp_path / "o.obj"), "--preview", str(png), "--up", "x", "-q"]
    assert main(args) == 0 and png.exists()
