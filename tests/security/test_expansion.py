"""Small files that ask for unbounded memory or time: each is refused quickly with one line
naming the file (exit status 2; ``ModelFormatError`` / ``ParameterError`` in the library), or,
where the work is legitimate (a deep node chain), done in time linear in the file.

The child-process checks of memory are in ``test_tiny_files.py``.
"""

from __future__ import annotations

import base64
import io
import json
import os
import struct
import time
import warnings

import pytest

import meshvis
from meshvis import limits
from meshvis.cli.main import main
from meshvis.errors import ModelFormatError, ParameterError

POS = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


def _data_uri(data: bytes) -> str:
    return "data:application/octet-stream;base64," + base64.b64encode(data).decode()


def triangle_gltf() -> dict:
    """One triangle, its positions in a data URI."""
    return {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [{"byteLength": 36, "uri": _data_uri(POS)}],
    }


def _write(path, doc) -> str:
    path.write_text(json.dumps(doc, separators=(",", ":")))
    return str(path)


def _refused(capsys, path: str, needle: str, seconds: float = 30) -> None:
    """The command and the library both refuse ``path`` quickly, naming it and ``needle``."""
    t0 = time.monotonic()
    assert main(["info", path, "--no-intersections"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"meshvis: error: {path}: ") and needle in err, err
    with pytest.raises(ModelFormatError, match=needle.replace("(", r"\(").replace(")", r"\)")):
        meshvis.load(path)
    assert time.monotonic() - t0 < seconds


# ---------------------------------------------------------------------------- glTF accessors
ACCESSOR_CASES = {
    # an accessor of zeros, no data behind it
    "no bufferView": (
        lambda d: d["accessors"].__setitem__(0, {"componentType": 5126, "count": 10**8, "type": "VEC3"}),
        "decode to 1200000000 bytes",
    ),
    # sparse: a count of substitutions past the accessor's own
    "sparse count": (
        lambda d: d["accessors"][0].update(
            sparse={
                "count": 10**8,
                "indices": {"bufferView": 0, "componentType": 5125},
                "values": {"bufferView": 0},
            }
        ),
        "replaces 100000000 of its 3 elements",
    ),
    # a sparse accessor of 10**8 zeros
    "sparse zeros": (
        lambda d: d["accessors"].__setitem__(
            0,
            {
                "componentType": 5126,
                "count": 10**8,
                "type": "VEC3",
                "sparse": {
                    "count": 1,
                    "indices": {"bufferView": 0, "componentType": 5125},
                    "values": {"bufferView": 0},
                },
            },
        ),
        "decode to 1200000000 bytes",
    ),
    # a byteStride of 0 would let any count pass the view's length
    "stride 0": (lambda d: d["bufferViews"][0].update(byteStride=0), "byteStride of 0"),
    "stride below the element": (
        lambda d: (d["bufferViews"][0].update(byteStride=4), d["accessors"][0].update(count=9)),
        "wider than the byteStride 4",
    ),
    # a view and a buffer declaring more bytes than the data URI holds
    "buffer longer than its data": (
        lambda d: (d["buffers"][0].update(byteLength=10**9), d["bufferViews"][0].update(byteLength=10**9)),
        "bufferView 0 lies outside its buffer",
    ),
    # many accessors over the same bytes
    "many accessors": (
        lambda d: d.update(
            accessors=[{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}] * 200_000
        ),
        "decode to 7200000 bytes",
    ),
}


@pytest.mark.parametrize("case", ACCESSOR_CASES)
def test_gltf_accessors_that_ask_for_more_than_their_data(tmp_path, capsys, monkeypatch, case):
    mutate, needle = ACCESSOR_CASES[case]
    if case == "many accessors":  # 7.2 MB from a 12 MB file passes the floor; lower it to see the rule
        monkeypatch.setattr(limits, "MIN_EXPANSION_BYTES", 1 << 20)
        monkeypatch.setattr(limits, "MAX_EXPANSION", 0.5)
    doc = triangle_gltf()
    mutate(doc)
    path = _write(tmp_path / "s.gltf", doc)
    _refused(capsys, path, needle)


def _textured_gltf(image: bytes, mime: str) -> dict:
    doc = triangle_gltf()
    blob = POS + struct.pack("<6f", 0, 0, 1, 0, 0, 1)
    doc["buffers"] = [{"byteLength": 60, "uri": _data_uri(blob)}]
    doc["bufferViews"].append({"buffer": 0, "byteOffset": 36, "byteLength": 24})
    doc["accessors"].append({"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"})
    doc["meshes"][0]["primitives"][0].update(attributes={"POSITION": 0, "TEXCOORD_0": 1}, material=0)
    doc["materials"] = [{"name": "skin", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    doc["textures"] = [{"source": 0}]
    doc["images"] = [{"uri": f"data:{mime};base64," + base64.b64encode(image).decode()}]
    return doc


def _image(side: int, fmt: str) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.new("L", (side, side)).save(buf, format=fmt)
    return buf.getvalue()


def test_a_small_png_of_many_pixels_is_copied_not_decoded(tmp_path):
    """140 KB of PNG holding 12000 x 12000 pixels: written into a rebuilt output as it is."""
    png = _image(12_000, "PNG")
    src = _write(tmp_path / "s.gltf", _textured_gltf(png, "image/png"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # not even PIL's warning about a decompression bomb
        soup = meshvis.load(src)
    meshvis.save(soup, tmp_path / "o.obj")
    tex = next(
        line.split()[-1]
        for line in (tmp_path / "o.mtl").read_text().splitlines()
        if line.startswith("map_Kd")
    )
    assert (tmp_path / tex).read_bytes() == png


def test_a_small_image_that_must_be_decoded_is_left_out(tmp_path):
    """A GIF of 9000 x 9000 pixels (324 MB decoded) from a few KB: written without it, with a warning."""
    gif = _image(9_000, "GIF")
    assert len(gif) < 200_000
    src = _write(tmp_path / "s.gltf", _textured_gltf(gif, "image/gif"))
    soup = meshvis.load(src)
    with pytest.warns(UserWarning, match="would decode past the cap MAX_EXPANSION"):
        meshvis.save(soup, tmp_path / "o.obj")  # rebuilt: the texture would be decoded and written as PNG
    assert "map_Kd" not in (tmp_path / "o.mtl").read_text()
    assert sorted(os.listdir(tmp_path)) == ["o.mtl", "o.obj", "s.gltf"]


def test_a_real_model_is_well_within_the_expansion():
    """The accessors of the milk truck decode to about its size, far below MAX_EXPANSION."""
    from helpers import real_model

    from meshvis.io.gltf import _check_accessors
    from meshvis.io.gltf_edit import read_container

    path = real_model("CesiumMilkTruck.glb")
    doc, buffers, _ = read_container(path, path)
    decoded = _check_accessors(doc, path, [len(b) for b in buffers])
    assert decoded < 2 * os.path.getsize(path) < limits.MAX_EXPANSION * os.path.getsize(path)


# ---------------------------------------------------------------------------- glTF node graph
def test_a_deep_node_chain_loads_in_linear_time(tmp_path):
    """100,000 nested nodes (2.2 MB) took 49 s with a walk that copied its path at every node."""
    times = []
    for n in (25_000, 100_000):
        doc = triangle_gltf()
        doc["nodes"] = [{"children": [i + 1]} for i in range(n - 1)] + [{"mesh": 0}]
        path = _write(tmp_path / f"chain{n}.gltf", doc)
        t0 = time.perf_counter()
        assert meshvis.load(path).n_faces == 1
        times.append(time.perf_counter() - t0)
    assert times[1] < 20, times
    assert times[1] < 8 * times[0] + 1, times  # 4x the nodes: far from 16x


# ---------------------------------------------------------------------------- extensionsRequired
def test_a_required_extension_meshvis_does_not_implement_is_refused(tmp_path, capsys):
    doc = triangle_gltf()
    doc["extensionsUsed"] = doc["extensionsRequired"] = ["EXT_meshopt_compression", "KHR_texture_transform"]
    path = _write(tmp_path / "s.gltf", doc)
    _refused(
        capsys, path, "requires the glTF extension EXT_meshopt_compression, which meshvis does not implement"
    )


def test_a_used_extension_that_is_not_required_is_read(tmp_path):
    doc = triangle_gltf()
    doc["extensionsUsed"] = ["EXT_meshopt_compression"]
    assert meshvis.load(_write(tmp_path / "s.gltf", doc)).n_faces == 1


def test_a_required_shading_extension_is_read_with_a_warning(tmp_path, capsys):
    doc = triangle_gltf()
    doc["extensionsUsed"] = doc["extensionsRequired"] = ["KHR_materials_unlit"]
    path = _write(tmp_path / "s.gltf", doc)
    with pytest.warns(
        UserWarning, match="requires the glTF extension KHR_materials_unlit; meshvis reads it without"
    ):
        assert meshvis.load(path).n_faces == 1
    assert main(["info", path, "--no-intersections"]) == 0
    assert "meshvis: warning:" in capsys.readouterr().err


# ---------------------------------------------------------------------------- PLY lists and counts
BIN_HEAD = (
    "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
    "element face {n}\nproperty list {count} int vertex_indices\nend_header\n"
)


def test_binary_ply_with_a_negative_list_count(tmp_path, capsys):
    """227 bytes: a list count of -1 made the row walk stand still (> 60 s, 1.8 GB)."""
    body = POS + struct.pack("<b3i", 3, 0, 1, 2) + struct.pack("<b", -1) + struct.pack("<3i", 0, 1, 2)
    for n, needle in ((100_000_000, "the file is truncated (in the 'face' data)"), (2, "has -1 entries")):
        path = tmp_path / f"neg{n}.ply"
        path.write_bytes(BIN_HEAD.format(n=n, count="char").encode() + body)
        assert path.stat().st_size < 300
        _refused(capsys, str(path), needle, seconds=10)


def test_binary_ply_with_a_huge_list_count(tmp_path, capsys):
    body = POS + struct.pack("<i3i", 2**31 - 1, 0, 1, 2)
    path = tmp_path / "huge.ply"
    path.write_bytes(BIN_HEAD.format(n=1, count="int").encode() + body)
    _refused(capsys, str(path), "the file is truncated", seconds=10)


@pytest.mark.parametrize(
    "faces, body, needle",
    [
        (300_000_000, "3 0 1 2\n", "the file is truncated (in the 'face' data)"),  # 188 bytes reached 2.35 GB
        (2, "3 0 1 2\n-1 0 1 2\n", "has -1 entries"),
        (2, "3 0 1 2\n2.5 0 1 2\n", "has 2.5 entries"),
    ],
)
def test_ascii_ply_counts_that_the_file_cannot_hold(tmp_path, capsys, faces, body, needle):
    path = tmp_path / "a.ply"
    path.write_text(
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        f"element face {faces}\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
        + body
    )
    _refused(capsys, str(path), needle, seconds=10)


# ---------------------------------------------------------------------------- frames of a labelling
def test_label_orbit_past_the_frame_cap(tmp_path, capsys):
    (tmp_path / "t.obj").write_text(TETRA)
    t0 = time.monotonic()
    rc = main(["label", str(tmp_path / "t.obj"), "-o", str(tmp_path / "l.svg"), "--orbit", "100000"])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "MAX_FRAMES" in err and "100000" in err, err
    assert time.monotonic() - t0 < 20
    assert sorted(os.listdir(tmp_path)) == ["t.obj"]


def test_label_camera_path_past_the_frame_cap(tmp_path, capsys):
    (tmp_path / "t.obj").write_text(TETRA)
    cams = [{"position": [3, 3, 3], "target": [0, 0, 0]}] * 20_000
    (tmp_path / "path.json").write_text(json.dumps(cams))
    rc = main(
        [
            "label",
            str(tmp_path / "t.obj"),
            "-o",
            str(tmp_path / "l.svg"),
            "--camera-path",
            str(tmp_path / "path.json"),
        ]
    )
    err = capsys.readouterr().err
    assert (
        rc == 2 and err.startswith(f"meshvis: error: {tmp_path / 'path.json'}: ") and "MAX_FRAMES" in err
    ), err


def test_label_frames_times_pixels_past_the_sequence_cap(tmp_path):
    from meshvis.labeling.frames import layout_frames
    from meshvis.rays.camera import Camera

    (tmp_path / "t.obj").write_text(TETRA)
    cams = [Camera((3, 3, 3), (0, 0, 0))] * 600
    with pytest.raises(ParameterError, match="MAX_SEQUENCE_PIXELS"):
        layout_frames(str(tmp_path / "t.obj"), cams, size=(512, 512))
    with pytest.raises(ParameterError, match="MAX_FRAMES"):
        layout_frames(str(tmp_path / "t.obj"), cams * 2, size=(8, 8))
