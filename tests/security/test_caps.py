"""Small files and arguments that would expand without bound: each is refused by a cap of
meshvis.limits, fast, with one line naming the file (exit status 2 in the CLI, a
MeshvisError subclass in the library), and leaves nothing behind.  The hostile files are
built in a temporary folder; two run in a child process whose address space is limited, so
"bounded memory" is checked, not assumed."""

from __future__ import annotations

import json
import os
import resource
import struct
import subprocess
import sys
import tempfile
import time
import zipfile

import numpy as np
import pytest

import meshvis
from meshvis import limits
from meshvis.cli.main import main
from meshvis.errors import ModelFormatError, ParameterError

TETRA_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
TETRA_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def _tetra_obj(path, scale: float = 1.0) -> str:
    with open(path, "w") as fh:
        fh.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in (TETRA_V * scale).tolist())
        fh.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in TETRA_F.tolist())
    return str(path)


def _one_line_error(capsys, argv, *needles, status: int = 2) -> str:
    t0 = time.monotonic()
    rc = main(argv)
    err = capsys.readouterr().err
    assert rc == status, err
    assert err.count("\n") == 1 and err.startswith("meshvis: error: "), err
    for n in needles:
        assert n in err, err
    assert time.monotonic() - t0 < 30
    return err


def _limited_run(argv: list[str], gigabytes: float = 3.0) -> subprocess.CompletedProcess:
    """``python -m meshvis ARGV`` with its address space limited to ``gigabytes``."""

    def limit() -> None:
        cap = int(gigabytes * (1 << 30))
        resource.setrlimit(resource.RLIMIT_AS, (cap, cap))

    return subprocess.run(
        [sys.executable, "-m", "meshvis", *argv],
        capture_output=True,
        text=True,
        preexec_fn=limit,
        timeout=120,
        cwd=tempfile.gettempdir(),  # the installed package, not a meshvis/ folder in the working one
    )


# ---------------------------------------------------------------------------- 3MF (zip)
def _3mf(path, declared: int | None = None, entries: int = 0) -> str:
    """A 3MF holding one tetrahedron; ``declared`` patches the model entry's inflated size."""
    xml = (
        '<?xml version="1.0"?><model unit="millimeter" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">'
        '<resources><object id="1" type="model"><mesh><vertices>'
        + "".join(f'<vertex x="{x}" y="{y}" z="{z}"/>' for x, y, z in TETRA_V.tolist())
        + "</vertices><triangles>"
        + "".join(f'<triangle v1="{a}" v2="{b}" v3="{c}"/>' for a, b, c in TETRA_F.tolist())
        + '</triangles></mesh></object></resources><build><item objectid="1"/></build></model>'
    )
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("3D/3dmodel.model", xml)
        for i in range(entries):
            zf.writestr(f"Metadata/x{i}.txt", "")
    if declared is not None:  # the central directory's "uncompressed size" of the first entry
        data = bytearray(open(path, "rb").read())
        at = data.rfind(b"PK\x01\x02", 0, data.find(b"3D/3dmodel.model", len(data) // 2) + 1)
        struct.pack_into("<I", data, at + 24, declared)
        open(path, "wb").write(bytes(data))
    return str(path)


def test_3mf_inflating_past_the_cap_is_refused(tmp_path, capsys):
    ok = _3mf(tmp_path / "ok.3mf")
    assert meshvis.load(ok).n_faces == 4
    bomb = _3mf(tmp_path / "bomb.3mf", declared=0xFFFF0000)  # 4.2 GB declared
    _one_line_error(
        capsys, ["orient", bomb, "-o", str(tmp_path / "o.obj")], bomb, "inflates to 4294901760 bytes"
    )
    with pytest.raises(ModelFormatError, match="more than the cap of"):
        meshvis.load(bomb)
    assert sorted(os.listdir(tmp_path)) == ["bomb.3mf", "ok.3mf"]


def test_3mf_with_too_many_entries_is_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(limits, "MAX_ZIP_ENTRIES", 50)
    many = _3mf(tmp_path / "many.3mf", entries=60)
    _one_line_error(capsys, ["info", many], many, "61 entries, more than the cap of 50")


def test_a_real_zip_bomb_fails_within_bounded_memory(tmp_path):
    """1.2 GB of zeros in a 1.2 MB 3MF: refused before inflating, under a 3 GB address space."""
    path = tmp_path / "zeros.3mf"
    block = b"\0" * (1 << 24)
    with (
        zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED, compresslevel=1) as zf,
        zf.open("3D/3dmodel.model", "w", force_zip64=True) as fh,
    ):
        for _ in range(72):
            fh.write(block)
    assert path.stat().st_size < 8 << 20
    r = _limited_run(["info", str(path)])
    assert r.returncode == 2, r.stderr
    assert r.stderr.count("\n") == 1 and "more than the cap of" in r.stderr and str(path) in r.stderr


# ---------------------------------------------------------------------------- glTF
def _doubling_gltf(levels: int) -> dict:
    """Two nodes per level, each with both nodes of the next level as children; the scene
    starts from one of the first two, so it places 2**levels meshes."""
    pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    import base64

    nodes = []
    for k in range(levels):
        kids = [2 * (k + 1), 2 * (k + 1) + 1]
        nodes += [{"children": kids}, {"children": kids}]
    nodes += [{"mesh": 0}, {"mesh": 0}]
    return {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [
            {
                "byteLength": 36,
                "uri": "data:application/octet-stream;base64," + base64.b64encode(pos).decode(),
            }
        ],
    }


def test_gltf_node_graph_doubling_at_22_levels_fails_fast(tmp_path, capsys):
    path = tmp_path / "doubling.gltf"
    path.write_text(json.dumps(_doubling_gltf(22), separators=(",", ":")))
    assert path.stat().st_size < 3000
    _one_line_error(
        capsys, ["orient", str(path), "-o", str(tmp_path / "o.obj")], str(path), "4194304 mesh instances"
    )
    small = tmp_path / "small.gltf"
    small.write_text(json.dumps(_doubling_gltf(3)))
    assert meshvis.load(small).n_faces == 8  # 2**3 instances of one triangle: the walk itself works


def test_gltf_cycle_and_bad_indices_are_refused(tmp_path, capsys):
    doc = _doubling_gltf(1)
    doc["nodes"][2]["children"] = [0]  # a cycle
    p = tmp_path / "cycle.gltf"
    p.write_text(json.dumps(doc))
    _one_line_error(capsys, ["info", str(p)], str(p), "cycle in the node graph")
    for mutate, needle in [
        (lambda d: d["accessors"][0].update(bufferView=-1), "bufferView -1, which does not exist"),
        (lambda d: d["accessors"][0].update(count=100), "reads past the end of bufferView 0"),
        (lambda d: d["bufferViews"][0].update(byteLength=1000), "bufferView 0 lies outside its buffer"),
        (lambda d: d["nodes"][0].update(children=[99]), "node 0 has a child that does not exist"),
    ]:
        doc = _doubling_gltf(1)
        mutate(doc)
        p.write_text(json.dumps(doc))
        with pytest.raises(ModelFormatError, match=needle):
            meshvis.load(p)
        _one_line_error(capsys, ["info", str(p)], str(p), needle)


# ---------------------------------------------------------------------------- OBJ polygons
def test_obj_face_with_too_many_corners_is_refused(tmp_path, capsys):
    k = 20_000
    t = np.linspace(0, 2 * np.pi, k, endpoint=False)
    path = tmp_path / "ngon.obj"
    with open(path, "w") as fh:
        fh.writelines(f"v {float(np.cos(a))!r} {float(np.sin(a))!r} 0\n" for a in t)
        fh.write("f " + " ".join(str(i + 1) for i in range(k)) + "\n")
    _one_line_error(
        capsys, ["orient", str(path), "-o", str(tmp_path / "o.obj")], str(path), "polygon 0 has 20000 corners"
    )
    assert sorted(os.listdir(tmp_path)) == ["ngon.obj"]
    with pytest.raises(ModelFormatError, match=f"cap of {limits.MAX_POLYGON_CORNERS}"):
        meshvis.load(path)


def test_obj_vertex_line_with_too_many_numbers_is_refused(tmp_path):
    path = tmp_path / "wide.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0 " + "1 " * 100_000 + "\nf 1 2 3\n")
    with pytest.raises(ModelFormatError, match="a vertex line has 100003 numbers"):
        meshvis.load(path)


# ---------------------------------------------------------------------------- arguments
@pytest.mark.parametrize(
    "extra, needle",
    [
        (["--rays-per-node", "1000000000"], "rays_per_node must be at most 65536 (the cap MAX_RAYS_PER_NODE"),
        (["--samples-per-face", "1000000"], "samples_per_face must be at most 1024"),
        (
            ["--rays-per-point", "1000000000"],
            "rays_per_point must be at most 65536 (the cap MAX_RAYS_PER_NODE",
        ),
        (["--seed", "-1"], "seed must be at least 0, got -1"),
    ],
)
def test_classification_arguments_past_their_caps(tmp_path, capsys, extra, needle):
    src = _tetra_obj(tmp_path / "t.obj")
    _one_line_error(capsys, ["orient", src, "-o", str(tmp_path / "o.obj"), "-q", *extra], needle)
    assert sorted(os.listdir(tmp_path)) == ["t.obj"]


def test_render_size_past_the_pixel_cap(tmp_path, capsys):
    src = _tetra_obj(tmp_path / "t.obj")
    _one_line_error(
        capsys,
        ["render", src, "-o", str(tmp_path / "p.png"), "--size", "60000", "60000"],
        "3600000000 pixels",
    )
    assert sorted(os.listdir(tmp_path)) == ["t.obj"]
    with pytest.raises(ParameterError, match="MAX_PIXELS"):
        meshvis.render((TETRA_V, TETRA_F), size=(60000, 60000))


def test_render_size_past_the_cap_within_bounded_memory(tmp_path):
    src = _tetra_obj(tmp_path / "t.obj")
    r = _limited_run(["render", src, "-o", str(tmp_path / "p.png"), "--size", "60000", "60000"])
    assert r.returncode == 2 and r.stderr.count("\n") == 1 and "MAX_PIXELS" in r.stderr, r.stderr


# ---------------------------------------------------------------------------- coordinates
@pytest.mark.parametrize("scale", [1e154, 1e200, 1e300])
def test_coordinates_where_the_arithmetic_fails_are_refused(tmp_path, capsys, scale):
    src = _tetra_obj(tmp_path / "t.obj", scale)
    _one_line_error(
        capsys, ["orient", src, "-o", str(tmp_path / "o.obj"), "-q"], src, "coordinates too large"
    )
    assert sorted(os.listdir(tmp_path)) == ["t.obj"]


def test_coordinates_up_to_the_cap_give_the_unit_scale_answer(tmp_path):
    """At MAX_COORDINATE the whole pipeline still holds: the same flips as at scale 1."""
    f = TETRA_F.copy()
    f[1] = f[1, ::-1]
    flips = []
    for scale in (1.0, limits.MAX_COORDINATE / 2):
        r = meshvis.orient((TETRA_V * scale, f), seed=3, rays_per_node=16)
        flips.append(r.flipped.tolist())
        assert meshvis.diagnose((TETRA_V * scale, f)) is not None
    assert flips[0] == flips[1] and sum(flips[0]) == 1


def test_batch_checks_its_options_once_before_starting(tmp_path, capsys):
    src = _tetra_obj(tmp_path / "t.obj")
    out = tmp_path / "out"
    for extra, needle in [
        (["--seed", "-1"], "seed must be at least 0"),
        (["--rays-per-node", "99999999"], "MAX_RAYS"),
    ]:
        _one_line_error(capsys, ["batch", src, "--op", "orient", "--out", str(out), *extra], needle)
    assert not out.exists()


def test_total_ray_budget_is_capped(monkeypatch):
    """Rays per byte of input: refused before any analysis or ray, whatever the options."""
    import trimesh

    ball = trimesh.creation.icosphere(2)  # 320 faces
    monkeypatch.setattr(limits, "MIN_RAY_CAP", 10_000)
    with pytest.raises(
        ParameterError, match=r"320 faces may ask for \d+ rays .* more than the \d+ an input of"
    ):
        meshvis.classify(ball, rays_per_node=4096, progressive=False)
    monkeypatch.setattr(limits, "RAYS_PER_INPUT_BYTE", 1)
    assert meshvis.classify(ball, rays_per_node=8, samples_per_face=1).n_rays <= 10_000
