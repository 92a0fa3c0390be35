"""A tiny file (1 MB at most) never makes a command use more than 1 GB or 20 s.

Every hostile input of the "small inputs that ask for unbounded memory or time" kind is
built here (glTF accessors of zeros, sparse and strided accessors, PLY list counts, a deep
node chain, FIFOs named by URIs, label frames, a 3MF and texture bombs, copies of one
triangle) and run through the command line in one child process whose address space is
limited to 1 GB: an allocation past it would surface as a ``MemoryError`` (or the "more
data than fits in memory" refusal), so each case must end with its own refusal message or
succeed, and within 20 s.
"""

from __future__ import annotations

import base64
import io
import json
import os
import resource
import struct
import subprocess
import sys
import tempfile

import pytest

LIMIT_BYTES = 1 << 30
LIMIT_SECONDS = 20
POS = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"

#: the child: runs every (argv, ...) of the JSON list on stdin through ``main``, printing
#: status, seconds and stderr of each
CHILD = """
import contextlib, io, json, sys, time
from meshvis.cli.main import main
out = []
for argv in json.load(sys.stdin):
    err = io.StringIO()
    t0 = time.monotonic()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            rc = main(argv)
        except MemoryError:
            rc = "MemoryError"
    out.append([rc, time.monotonic() - t0, err.getvalue()])
json.dump(out, sys.stdout)
"""


def _uri(data: bytes, mime: str = "application/octet-stream") -> str:
    return f"data:{mime};base64," + base64.b64encode(data).decode()


def _gltf(**changes) -> dict:
    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [{"byteLength": 36, "uri": _uri(POS)}],
    }
    doc.update(changes)
    return doc


def _textured(image: bytes, mime: str) -> dict:
    blob = POS + struct.pack("<6f", 0, 0, 1, 0, 0, 1)
    return _gltf(
        meshes=[{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "material": 0}]}],
        accessors=[
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
            {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
        ],
        bufferViews=[{"buffer": 0, "byteLength": 36}, {"buffer": 0, "byteOffset": 36, "byteLength": 24}],
        buffers=[{"byteLength": 60, "uri": _uri(blob)}],
        materials=[{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}],
        textures=[{"source": 0}],
        images=[{"uri": _uri(image, mime)}],
    )


def _image(side: int, fmt: str) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.new("L", (side, side)).save(buf, format=fmt)
    return buf.getvalue()


def _cases(d: str) -> list[tuple[str, list[str], int, str]]:
    """(file, argv, expected status, words of the message) of every case, files built in ``d``."""
    files: dict[str, bytes | str | dict] = {}
    sparse = {"count": 1, "indices": {"bufferView": 0, "componentType": 5125}, "values": {"bufferView": 0}}
    for count in (10**8, 4 * 10**8):
        files[f"zeros{count}.gltf"] = _gltf(
            accessors=[{"componentType": 5126, "count": count, "type": "VEC3"}]
        )
    files["sparse.gltf"] = _gltf(
        accessors=[{"componentType": 5126, "count": 10**8, "type": "VEC3", "sparse": sparse}]
    )
    files["sparse_count.gltf"] = _gltf(
        accessors=[
            {
                "bufferView": 0,
                "componentType": 5126,
                "count": 3,
                "type": "VEC3",
                "sparse": {**sparse, "count": 10**8},
            }
        ]
    )
    files["stride0.gltf"] = _gltf(bufferViews=[{"buffer": 0, "byteLength": 36, "byteStride": 0}])
    n = 40_000  # about 1 MB of nodes
    files["chain.gltf"] = _gltf(nodes=[{"children": [i + 1]} for i in range(n - 1)] + [{"mesh": 0}])
    for kind in ("buffers", "images"):
        doc = _gltf()
        doc[kind] = [{"byteLength": 36, "uri": "fifo.bin"}] if kind == "buffers" else [{"uri": "fifo.bin"}]
        files[f"fifo_{kind}.gltf"] = doc
    ply_head = (
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face {n}\nproperty list char int vertex_indices\nend_header\n"
    )
    body = POS + struct.pack("<b3i", 3, 0, 1, 2) + struct.pack("<b3i", -1, 0, 1, 2)
    files["negative.ply"] = ply_head.format(n=10**8).encode() + body
    files["negative2.ply"] = ply_head.format(n=2).encode() + body
    files["faces.ply"] = (
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 300000000\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"
    )
    files["t.obj"] = TETRA
    files["path.json"] = json.dumps([{"position": [3, 3, 3], "target": [0, 0, 0]}] * 20_000)
    files["gif.gltf"] = _textured(_image(9_000, "GIF"), "image/gif")
    files["png.gltf"] = _textured(_image(12_000, "PNG"), "image/png")
    xml = (
        '<?xml version="1.0"?><model unit="millimeter" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02">'
        '<resources><object id="1" type="model"><mesh><vertices><vertex x="0" y="0" z="0"/><vertex x="1" y="0" z="0"/>'
        '<vertex x="0" y="1" z="0"/></vertices><triangles>'
        + '<triangle v1="0" v2="1" v3="2"/>' * 600_000
        + '</triangles></mesh></object></resources><build><item objectid="1"/></build></model>'
    )
    import zipfile

    from helpers import write_glb

    # copies of one triangle: a node graph doubling 13 times over one cube, one face 20,000 times
    corners = struct.pack("<24f", *[c for z in (0, 1) for y in (0, 1) for x in (0, 1) for c in (x, y, z)])
    cube = [
        0,
        2,
        1,
        1,
        2,
        3,
        4,
        5,
        6,
        5,
        7,
        6,
        0,
        1,
        4,
        1,
        5,
        4,
        2,
        6,
        3,
        3,
        6,
        7,
        0,
        4,
        2,
        2,
        4,
        6,
        1,
        3,
        5,
        3,
        7,
        5,
    ]
    blob = corners + struct.pack("<36H", *cube)
    nodes = [{"children": [2 * k + 2, 2 * k + 3]} for k in range(13) for _ in (0, 1)] + [{"mesh": 0}] * 2
    cubes = _gltf(
        nodes=nodes,
        meshes=[{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        accessors=[
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
        bufferViews=[{"buffer": 0, "byteLength": 96}, {"buffer": 0, "byteOffset": 96, "byteLength": 72}],
        buffers=[{"byteLength": len(blob)}],
    )
    write_glb(cubes, blob, os.path.join(d, "cubes.glb"))
    files["copies.obj"] = "v 0 0 0\nv 1 0 0\nv 0 1 0\n" + "f 1 2 3\n" * 20_000

    with zipfile.ZipFile(os.path.join(d, "bomb.3mf"), "w", zipfile.ZIP_DEFLATED, compresslevel=9) as zf:
        zf.writestr("3D/3dmodel.model", xml)
    for name, content in files.items():
        data = json.dumps(content, separators=(",", ":")) if isinstance(content, dict) else content
        with open(os.path.join(d, name), "wb") as fh:
            fh.write(data.encode() if isinstance(data, str) else data)
    os.mkfifo(os.path.join(d, "fifo.bin"))

    def p(name: str) -> str:
        return os.path.join(d, name)

    def orient(name: str) -> list[str]:
        return ["orient", p(name), "-o", p("out.obj"), "-q", "--force"]

    label = ["label", p("t.obj"), "-o", p("l.svg"), "-q", "--force"]
    return [
        ("zeros100000000.gltf", orient("zeros100000000.gltf"), 2, "the accessors decode to 1200000000 bytes"),
        ("zeros400000000.gltf", orient("zeros400000000.gltf"), 2, "the accessors decode to 4800000000 bytes"),
        ("sparse.gltf", orient("sparse.gltf"), 2, "the accessors decode to"),
        ("sparse_count.gltf", orient("sparse_count.gltf"), 2, "replaces 100000000 of its 3 elements"),
        ("stride0.gltf", orient("stride0.gltf"), 2, "byteStride of 0"),
        ("negative.ply", orient("negative.ply"), 2, "the file is truncated"),
        ("negative2.ply", orient("negative2.ply"), 2, "has -1 entries"),
        ("faces.ply", orient("faces.ply"), 2, "the file is truncated"),
        ("chain.gltf", ["info", p("chain.gltf")], 0, ""),
        ("chain.gltf", orient("chain.gltf"), 0, ""),
        ("fifo_buffers.gltf", orient("fifo_buffers.gltf"), 2, "not a regular file"),
        ("fifo_images.gltf", orient("fifo_images.gltf"), 2, "not a regular file"),
        ("t.obj", [*label, "--orbit", "100000"], 2, "MAX_FRAMES"),
        ("path.json", [*label, "--camera-path", p("path.json")], 2, "MAX_FRAMES"),
        ("bomb.3mf", orient("bomb.3mf"), 2, "the archive inflates to 19200353 bytes"),
        ("gif.gltf", orient("gif.gltf"), 0, "would decode past the cap MAX_EXPANSION"),
        ("png.gltf", orient("png.gltf"), 0, ""),
        ("cubes.glb", ["info", p("cubes.glb")], 0, ""),
        (
            "cubes.glb",
            ["remove-interior", p("cubes.glb"), "-o", p("out.glb"), "--force"],
            2,
            "MAX_FACE_COPIES",
        ),
        ("copies.obj", ["info", p("copies.obj")], 0, ""),
        ("copies.obj", orient("copies.obj"), 2, "MAX_FACE_COPIES"),
    ]


@pytest.mark.slow
def test_tiny_hostile_files_stay_within_1_gb_and_20_s():
    with tempfile.TemporaryDirectory() as d:
        cases = _cases(d)
        for name, *_ in cases:
            assert os.path.getsize(os.path.join(d, name)) <= 1 << 20, name

        def limit() -> None:
            resource.setrlimit(resource.RLIMIT_AS, (LIMIT_BYTES, LIMIT_BYTES))

        r = subprocess.run(
            [sys.executable, "-c", CHILD],
            input=json.dumps([argv for _, argv, _, _ in cases]),
            capture_output=True,
            text=True,
            preexec_fn=limit,
            timeout=LIMIT_SECONDS * len(cases),
            cwd=d,
        )
        assert r.returncode == 0, r.stderr[-2000:]
        results = json.loads(r.stdout)
    for (name, argv, status, words), (rc, seconds, err) in zip(cases, results):
        assert rc == status, (name, argv[0], rc, err)
        assert words in err, (name, err)
        assert "fits in memory" not in err and "Traceback" not in err, (name, err)
        assert seconds < LIMIT_SECONDS, (name, seconds)


def _measure() -> None:
    """Print a Markdown row per case: each run alone, its time and peak memory (``/usr/bin/time``)."""
    with tempfile.TemporaryDirectory() as d:
        for name, argv, _, _ in _cases(d):
            r = subprocess.run(
                ["/usr/bin/time", "-f", "%e %M", sys.executable, "-m", "meshvis", *argv],
                capture_output=True,
                text=True,
                cwd=d,
                timeout=300,
            )
            seconds, kb = r.stderr.strip().splitlines()[-1].split()
            said = next((ln for ln in r.stderr.splitlines() if ln.startswith("meshvis:")), "")
            said = said.replace(d + os.sep, "")
            shown = argv[:2] + (argv[-2:] if argv[0] == "label" else [])
            what = " ".join(a.replace(d + os.sep, "") for a in shown)
            print(
                f"| {name}, {os.path.getsize(os.path.join(d, name)):,} bytes | `{what}` | exit {r.returncode}, "
                f"{float(seconds):.1f} s, {int(kb) // 1024} MB | {said[:110]} |"
            )


if __name__ == "__main__":  # the table of docs/security.md
    _measure()
