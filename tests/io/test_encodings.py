"""Text encodings: a UTF-8 byte-order mark at the start of a text file is not part of its
first line (it used to hide an OBJ's first vertex, so faces silently indexed the wrong
ones), and a file name that is not valid UTF-8 is written as text without a traceback."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

import meshvis
from meshvis.cli.main import main

BOM = b"\xef\xbb\xbf"
TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
TEXTS = {
    "obj": TETRA,
    "off": "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
    "ply": "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
    "element face 4\nproperty list uchar int vertex_indices\nend_header\n"
    "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n",
    "stl": "solid t\n"
    + "".join(
        "facet normal 0 0 0\nouter loop\n"
        + "".join(f"vertex {x} {y} {z}\n" for x, y, z in tri)
        + "endloop\nendfacet\n"
        for tri in ([(0, 0, 0), (0, 1, 0), (1, 0, 0)], [(0, 0, 0), (1, 0, 0), (0, 0, 1)])
    )
    + "endsolid t\n",
}


@pytest.mark.parametrize("fmt", TEXTS)
def test_a_byte_order_mark_loses_nothing(tmp_path, fmt):
    plain, marked = tmp_path / f"plain.{fmt}", tmp_path / f"marked.{fmt}"
    plain.write_text(TEXTS[fmt])
    marked.write_bytes(BOM + TEXTS[fmt].encode())
    a, b = meshvis.load(plain), meshvis.load(marked)
    assert np.array_equal(a.vertices, b.vertices) and np.array_equal(a.faces, b.faces)


def test_a_byte_order_mark_on_the_mtl_keeps_the_material_and_texture(tmp_path):
    (tmp_path / "skin.png").write_bytes(b"\x89PNG fake")
    (tmp_path / "m.obj").write_bytes(BOM + ("mtllib m.mtl\nusemtl skin\n" + TETRA).encode())
    (tmp_path / "m.mtl").write_bytes(BOM + b"newmtl skin\nKd 1 0 0\nmap_Kd skin.png\n")
    soup = meshvis.load(tmp_path / "m.obj")
    assert soup.n_vertices == 4 and [m.name for m in soup.materials] == ["skin"]
    assert soup.materials[0].source is not None and soup.materials[0].source.textures() == [
        ("map_Kd", "skin.png")
    ]
    meshvis.save(soup, tmp_path / "out.obj")
    assert "map_Kd skin.png" in (tmp_path / "out.mtl").read_text()


def test_a_byte_order_mark_on_gltf_json(tmp_path):
    import base64
    import struct

    pos = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
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
    (tmp_path / "s.gltf").write_bytes(BOM + json.dumps(doc).encode())
    assert meshvis.load(tmp_path / "s.gltf").n_faces == 1


# ---------------------------------------------------------------------------- file names
NAME = os.fsdecode(b"caf\xe9")  # Latin-1 bytes: not UTF-8, a lone surrogate in Python


@pytest.mark.parametrize("out", ["o.obj", "o.ply", "o.glb", "o.gltf", "o.stl", "o.off"])
def test_a_file_name_that_is_not_utf8(tmp_path, capsys, out):
    src = tmp_path / f"{NAME}.obj"
    src.write_text(TETRA)
    assert main(["orient", str(src), "-o", str(tmp_path / out), "-q"]) == 0, capsys.readouterr().err
    soup = meshvis.load(tmp_path / out)
    assert soup.n_faces == 4


def test_a_batch_over_a_file_name_that_is_not_utf8(tmp_path, capsys):
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / f"{NAME}.obj").write_text(TETRA)
    assert main(["batch", str(tmp_path / "lib"), "--op", "layers", "--out", str(tmp_path / "out"), "-q"]) == 0
    assert (tmp_path / "out" / "summary.csv").read_text().count("\n") == 2
    rows = json.loads((tmp_path / "out" / "summary.json").read_text())["files"]
    assert os.path.exists(rows[0]["output"])  # JSON escapes keep the name as it is


def test_messages_about_a_file_name_that_is_not_utf8(tmp_path):
    """With a strict standard output (a UTF-8 locale other than C), the summary line naming
    the file is printed with the bytes escaped instead of ending in a UnicodeEncodeError."""
    import subprocess
    import sys

    src = tmp_path / f"{NAME}.obj"
    src.write_text(TETRA)
    env = {**os.environ, "PYTHONIOENCODING": "utf-8:strict"}
    r = subprocess.run(
        [sys.executable, "-m", "meshvis", "orient", os.fsencode(src), "-o", str(tmp_path / "o.obj")],
        capture_output=True,
        env=env,
        cwd=tmp_path,
        timeout=120,
    )
    assert r.returncode == 0, r.stderr.decode(errors="replace")
    assert b"caf\\udce9.obj: orient: turned 0 of 4 faces" in r.stdout
