"""trimesh objects in, the same kind back with their visuals (Soup.to_trimesh)."""

import warnings

import numpy as np
import trimesh
from helpers import real_model

import meshvis


def test_a_textured_trimesh_comes_back_with_uvs_and_texture():
    mesh = trimesh.load(real_model("spot.obj"), process=False)
    result = meshvis.orient(mesh)
    back = result.soup.to_trimesh()
    assert isinstance(back, trimesh.Trimesh)
    assert back.visual.kind == "texture"
    assert np.array_equal(back.visual.uv, mesh.visual.uv)
    assert np.array_equal(np.asarray(back.visual.material.image), np.asarray(mesh.visual.material.image))
    assert np.array_equal(back.vertices, mesh.vertices)
    flipped = result.flipped
    assert np.array_equal(back.faces[~flipped], mesh.faces[~flipped])
    assert np.array_equal(back.faces[flipped], mesh.faces[flipped][:, [0, 2, 1]])


def test_removal_keeps_face_colours_of_the_kept_faces():
    mesh = trimesh.creation.icosphere(subdivisions=2)
    colours = np.random.default_rng(0).integers(0, 255, (len(mesh.faces), 4), dtype=np.uint8)
    mesh.visual.face_colors = colours
    soup = meshvis.as_soup(mesh)
    keep = np.arange(soup.n_faces) % 3 != 0
    back = soup.subset(keep).to_trimesh()
    assert np.array_equal(back.faces, mesh.faces[keep])
    assert np.array_equal(back.visual.face_colors, colours[keep])


def test_a_scene_comes_back_as_a_scene_with_its_instancing():
    scene = trimesh.load(real_model("pins.glb"))
    soup = meshvis.as_soup(scene)
    one_dowel = soup.part_id == 2
    back = soup.flipped(one_dowel).to_trimesh()
    assert isinstance(back, trimesh.Scene)
    assert len(back.graph.nodes_geometry) == len(scene.graph.nodes_geometry)
    assert len(back.geometry) == len(scene.geometry) + 1  # only the flipped instance got a copy
    again = meshvis.as_soup(back)
    assert again.part_names == soup.part_names
    assert np.allclose(again.normals, soup.flipped(one_dowel).normals, atol=1e-9)
    unchanged = soup.to_trimesh()
    assert len(unchanged.geometry) == len(scene.geometry)


def test_float32_input_gives_no_warnings():
    mesh = trimesh.load(real_model("spot.obj"), process=False)
    vertices = np.asarray(mesh.vertices, np.float32)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = meshvis.orient((vertices, mesh.faces))
        s = meshvis.as_soup(trimesh.Trimesh(vertices, mesh.faces, process=False))
    assert r.soup.n_faces == len(mesh.faces) and s.vertices.dtype == np.float64


def test_a_soup_without_trimesh_source_gives_its_geometry():
    soup = meshvis.load(real_model("suzanne.obj"))
    mesh = soup.to_trimesh()
    assert np.array_equal(mesh.faces, soup.faces)
