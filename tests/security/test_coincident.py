"""Many copies of one triangle: small files whose faces all lie in one place.

The intersection tests compare every pair of faces whose boxes overlap, so ``k`` copies of
one triangle would make ``k**2 / 2`` pairs: a 160 KB OBJ repeating one face 20,000 times,
a 1 KB GLB whose node graph doubles 13 times (8,192 coincident cubes), a Draco-compressed
GLB read as its placeholder zeros.  Each must finish in bounded memory (a child process
with a limited address space) or be refused with one line; compressed glTF geometry is
decoded, never read as zeros.
"""

from __future__ import annotations

import resource
import subprocess
import sys
import tempfile

import numpy as np
import pytest
from helpers import write_glb

import meshvis
from meshvis import limits
from meshvis.errors import ModelError, ModelFormatError
from meshvis.geometry.intersect import intersection_flags

#: address space of the child processes: the copies once took 3 GB, and 24 GB for Draco zeros
LIMIT_GB = 2.0


def _limited_run(argv: list[str], gigabytes: float = LIMIT_GB) -> subprocess.CompletedProcess:
    """``python -m meshvis ARGV`` with its address space limited to ``gigabytes``."""

    def limit() -> None:
        cap = int(gigabytes * (1 << 30))
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))

    return subprocess.run(
        [sys.executable, "-m", "meshvis", *argv],
        capture_output=True,
        text=True,
        preexec_fn=limit,
        timeout=300,
        cwd=tempfile.gettempdir(),  # the installed package, not a meshvis/ folder in the working one
    )


def _one_face_obj(path, copies: int) -> str:
    with open(path, "w") as fh:
        fh.write("v 0 0 0\nv 1 0 0\nv 0 1 0\n")
        fh.write("f 1 2 3\n" * copies)
    return str(path)


def _cube_arrays() -> tuple[np.ndarray, np.ndarray]:
    v = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], np.float32)
    f = np.array(
        [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4]]
        + [[2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]],
        np.uint16,
    )
    return v, f


def _doubling_cubes_glb(path, levels: int) -> str:
    """One cube mesh, placed ``2**levels`` times at the same spot by a doubling node graph."""
    v, f = _cube_arrays()
    blob = v.tobytes() + f.tobytes()
    nodes = []
    for k in range(levels):
        kids = [2 * (k + 1), 2 * (k + 1) + 1]
        nodes += [{"children": kids}, {"children": kids}]
    nodes += [{"mesh": 0}, {"mesh": 0}]
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": 8,
                "type": "VEC3",
                "min": [0, 0, 0],
                "max": [1, 1, 1],
            },
            {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteLength": v.nbytes},
            {"buffer": 0, "byteOffset": v.nbytes, "byteLength": f.nbytes},
        ],
        "buffers": [{"byteLength": len(blob)}],
    }
    write_glb(doc, blob, str(path))
    return str(path)


@pytest.mark.slow
def test_twenty_thousand_copies_of_one_face_in_bounded_memory(tmp_path):
    path = _one_face_obj(tmp_path / "copies.obj", 20_000)
    r = _limited_run(["info", path])
    assert r.returncode == 0, r.stderr
    assert "19,999" in r.stdout  # duplicate faces
    d = meshvis.diagnose(path)
    assert d["duplicate_faces"] == 19_999 and d["coplanar_faces"] == 20_000 and d["intersecting_faces"] == 0


def test_copies_are_flagged_like_their_first_face():
    # a triangle stored 3 times (once turned over), crossed by a fourth face
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.2, 0.2, -0.5], [0.3, 0.2, 0.5], [0.2, 0.3, 0.5]], float)
    f = np.array([[0, 1, 2], [0, 2, 1], [3, 4, 5], [1, 2, 0]])
    d = intersection_flags(v, f)
    assert d["intersects"].all() and d["coplanar"].tolist() == [True, True, False, True]
    assert d["duplicate_first"].tolist() == [0, 0, 2, 0]
    # the pairs stand for the group: the first face with the crossing one, each copy with the first
    assert d["intersect_pairs"].tolist() == [[0, 2]]
    assert d["coplanar_pairs"].tolist() == [[0, 1], [0, 3]]


@pytest.mark.slow
def test_a_doubling_node_graph_of_coincident_cubes_in_bounded_memory(tmp_path):
    path = _doubling_cubes_glb(tmp_path / "cubes.glb", 13)
    assert (tmp_path / "cubes.glb").stat().st_size < 1500
    soup = meshvis.load(path)
    assert soup.n_faces == 12 * 8192
    r = _limited_run(["info", path])
    assert r.returncode == 0, r.stderr
    assert f"{12 * 8192 - 12:,}" in r.stdout  # every cube but the first is a copy
    # the commands that cast rays: one line at the scene, before the analysis (each ray
    # through the stack would test all 8,192 copies: remove-interior took 10 minutes)
    r = _limited_run(["remove-interior", path, "-o", str(tmp_path / "o.glb")])
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert "8192 faces lie exactly on top of each other" in r.stderr and "MAX_FACE_COPIES" in r.stderr
    assert not (tmp_path / "o.glb").exists()


def test_a_few_copies_of_a_face_are_cast_against():
    import trimesh

    ball = trimesh.creation.icosphere(1)
    f = np.concatenate([ball.faces] * limits.MAX_FACE_COPIES)
    assert meshvis.classify((ball.vertices, f), seed=0).hidden.sum() == 0
    with pytest.raises(ModelError, match=f"{limits.MAX_FACE_COPIES + 1} faces lie exactly on top"):
        meshvis.classify((ball.vertices, np.concatenate([f, ball.faces])), seed=0)


def test_distinct_faces_stacked_in_one_place_are_refused(monkeypatch):
    # a fan of slightly different triangles through one edge: no two are copies, every
    # pair's boxes overlap
    k = 400
    angle = np.linspace(0, np.pi, k, endpoint=False)
    v = np.concatenate([[[0, 0, 0], [1, 0, 0]], np.stack([np.full(k, 0.5), np.cos(angle), np.sin(angle)], 1)])
    f = np.stack([np.zeros(k, int), np.ones(k, int), 2 + np.arange(k)], 1)
    assert intersection_flags(v, f)["candidates"] >= k * (k - 1) // 2
    monkeypatch.setattr(limits, "MIN_FACE_PAIRS", 1000)
    monkeypatch.setattr(limits, "MAX_FACE_PAIRS_PER_FACE", 10)
    with pytest.raises(ModelError, match="more than the cap MAX_FACE_PAIRS_PER_FACE"):
        intersection_flags(v, f)


# ---------------------------------------------------------------------------- compressed glTF
def _draco_glb(path, v: np.ndarray, f: np.ndarray) -> str:
    DracoPy = pytest.importorskip("DracoPy")
    blob = DracoPy.encode(v.astype(np.float32), f.astype(np.uint32), preserve_order=True)
    draco = {"bufferView": 0, "attributes": {"POSITION": 0}}
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_draco_mesh_compression"],
        "extensionsRequired": ["KHR_draco_mesh_compression"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [
            {
                "primitives": [
                    {
                        "attributes": {"POSITION": 0},
                        "indices": 1,
                        "extensions": {"KHR_draco_mesh_compression": draco},
                    }
                ]
            }
        ],
        "accessors": [
            {
                "componentType": 5126,
                "count": len(v),
                "type": "VEC3",
                "min": v.min(0).tolist(),
                "max": v.max(0).tolist(),
            },
            {"componentType": 5125, "count": f.size, "type": "SCALAR"},
        ],
        "bufferViews": [{"buffer": 0, "byteLength": len(blob)}],
        "buffers": [{"byteLength": len(blob)}],
    }
    write_glb(doc, blob, str(path))
    return str(path)


def test_draco_compressed_geometry_is_decoded(tmp_path):
    import trimesh

    ball = trimesh.creation.icosphere(3)
    path = _draco_glb(tmp_path / "ball.glb", np.asarray(ball.vertices), np.asarray(ball.faces))
    soup = meshvis.load(path)
    assert soup.n_faces == len(ball.faces)
    assert abs(soup.total_area - ball.area) < 1e-3 * ball.area  # not the placeholder zeros
    d = meshvis.diagnose(path)
    assert d["degenerate_faces"] == 0 and d["closed"]


def test_draco_without_its_decoder_is_one_line(tmp_path, monkeypatch, capsys):
    import trimesh

    from meshvis.cli.main import main

    ball = trimesh.creation.icosphere(1)
    path = _draco_glb(tmp_path / "ball.glb", np.asarray(ball.vertices), np.asarray(ball.faces))
    monkeypatch.setitem(sys.modules, "DracoPy", None)  # as if not installed
    with pytest.raises(ModelFormatError, match="Draco-compressed and DracoPy"):
        meshvis.load(path)
    assert main(["info", path]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and path in err and "DracoPy" in err


def test_meshopt_compressed_buffers_are_refused(tmp_path, capsys):
    from meshvis.cli.main import main

    v, f = _cube_arrays()
    blob = v.tobytes() + f.tobytes()
    meshopt = {"buffer": 0, "byteLength": v.nbytes, "byteStride": 12, "count": 8, "mode": "ATTRIBUTES"}
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["EXT_meshopt_compression"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "accessors": [
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": 8,
                "type": "VEC3",
                "min": [0, 0, 0],
                "max": [1, 1, 1],
            },
            {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
        ],
        "bufferViews": [
            {"buffer": 0, "byteLength": v.nbytes, "extensions": {"EXT_meshopt_compression": meshopt}},
            {"buffer": 0, "byteOffset": v.nbytes, "byteLength": f.nbytes},
        ],
        "buffers": [{"byteLength": len(blob)}],
    }
    path = str(tmp_path / "cube.glb")
    write_glb(doc, blob, path)
    assert main(["info", path]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and path in err and "EXT_meshopt_compression" in err
