"""meshvis.fix_normals and meshvis.remove_hidden: trimesh objects in, the same kind out.

The first two tests are the case of trimesh's open request about ``fix_normals`` on meshes
that are not watertight: an open scan (the cow "spot", 5,856 faces, holes at the eyes and
seams) given to both ``trimesh.repair.fix_normals`` and ``meshvis.fix_normals``.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from helpers import real_model

import meshvis
from meshvis.cli.main import main

#: share of the faces turned over in the partly flipped input
FLIPPED_SHARE = 0.3


def _outward(mesh: trimesh.Trimesh, truth: np.ndarray) -> np.ndarray:
    """(m,) bool: the face's front faces the same way as the outward truth's normal."""
    return np.einsum("ij,ij->i", mesh.face_normals, truth) > 0


@pytest.fixture(scope="module")
def spot():
    mesh = trimesh.load(real_model("spot.obj"), process=False)
    assert not mesh.is_watertight and mesh.volume > 0  # open, and wound outward as stored
    return mesh


@pytest.mark.slow
def test_fix_normals_turns_an_open_unwelded_partly_flipped_mesh_outward_where_trimesh_does_not(spot):
    n = len(spot.faces)
    corners = spot.vertices[spot.faces].reshape(-1, 3)  # unwelded: no two faces share a vertex
    faces = np.arange(3 * n).reshape(n, 3)
    flip = np.random.default_rng(0).random(n) < FLIPPED_SHARE
    faces[flip] = faces[flip][:, ::-1]
    given = trimesh.Trimesh(corners, faces, process=False)
    truth = spot.face_normals

    theirs = given.copy()
    trimesh.repair.fix_normals(theirs)  # in place, as trimesh does it
    ours = meshvis.fix_normals(given)

    assert isinstance(ours, trimesh.Trimesh) and len(ours.faces) == n
    assert _outward(ours, truth).all()
    # trimesh finds no shared edge to follow and no watertight body to measure
    assert (~_outward(theirs, truth)).sum() == flip.sum()
    assert np.array_equal(given.faces, faces)  # the input is untouched


@pytest.mark.slow
def test_fix_normals_turns_an_open_mesh_wound_inward_where_trimesh_leaves_it(spot):
    inward = trimesh.Trimesh(spot.vertices, spot.faces[:, ::-1], process=False)
    theirs = inward.copy()
    trimesh.repair.fix_normals(theirs)
    ours = meshvis.fix_normals(inward)
    assert _outward(ours, spot.face_normals).all()
    assert not _outward(theirs, spot.face_normals).any()  # not watertight: trimesh keeps it inward


def test_fix_normals_keeps_the_texture_and_uvs(spot):
    faces = spot.faces.copy()
    faces[::5] = faces[::5, ::-1]
    flipped = trimesh.Trimesh(spot.vertices, faces, visual=spot.visual.copy(), process=False)
    fixed = meshvis.fix_normals(flipped)
    assert fixed.visual.kind == "texture"
    assert np.array_equal(fixed.visual.uv, spot.visual.uv)
    assert np.array_equal(np.asarray(fixed.visual.material.image), np.asarray(spot.visual.material.image))


def _box_in_box() -> trimesh.Trimesh:
    outer = trimesh.creation.box(extents=(2, 2, 2))
    inner = trimesh.creation.icosphere(1, radius=0.5)
    outer.visual.face_colors = (200, 30, 30, 255)
    inner.visual.face_colors = (30, 30, 200, 255)
    return trimesh.util.concatenate([outer, inner])


def test_remove_hidden_drops_the_inner_part_and_keeps_face_colours():
    both = _box_in_box()
    kept = meshvis.remove_hidden(both)
    assert isinstance(kept, trimesh.Trimesh)
    assert len(kept.faces) == 12
    assert (kept.visual.face_colors == (200, 30, 30, 255)).all()
    assert len(both.faces) == 12 + 80  # the input is untouched


def test_a_scene_comes_back_as_a_scene_with_its_graph():
    scene = trimesh.Scene()
    scene.add_geometry(trimesh.creation.box(extents=(2, 2, 2)), node_name="shell", geom_name="shell")
    moved = trimesh.transformations.translation_matrix((0.3, 0, 0))
    ball = trimesh.creation.icosphere(1, radius=0.4)
    scene.add_geometry(ball, node_name="core", geom_name="core", transform=moved)
    out = meshvis.remove_hidden(scene)
    assert isinstance(out, trimesh.Scene)
    assert np.allclose(out.graph.get("core")[0], moved)  # transforms kept
    faces = {name: len(out.geometry[out.graph[name][1]].faces) for name in out.graph.nodes_geometry}
    assert faces == {"shell": 12} or faces == {"shell": 12, "core": 0}
    assert isinstance(meshvis.fix_normals(scene), trimesh.Scene)


@pytest.mark.parametrize("model", ["wallhole", "box_in_box"])
def test_the_helpers_give_the_command_lines_faces(model, tmp_path):
    mesh = _box_in_box() if model == "box_in_box" else trimesh.load(real_model("wallhole.obj"), process=False)
    given = str(tmp_path / "given.ply")  # PLY keeps trimesh's face order
    mesh.export(given)
    assert main(["orient", given, "-o", str(tmp_path / "oriented.ply"), "-q"]) == 0
    cli = meshvis.load(str(tmp_path / "oriented.ply"))
    assert np.array_equal(meshvis.fix_normals(mesh).faces, cli.faces)
    assert main(["remove-interior", given, "-o", str(tmp_path / "kept.ply"), "-q"]) == 0
    cli = meshvis.load(str(tmp_path / "kept.ply"))
    assert np.array_equal(meshvis.remove_hidden(mesh).triangles, cli.triangles)
