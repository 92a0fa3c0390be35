"""References a model or a batch makes to other files: no file outside the input's folder is
read, none is named in an output, and nothing that is not a regular file is opened (a FIFO
would block the command, or a whole batch, forever).

Each case builds a folder holding the model next to an ``elsewhere`` folder with a private
file, then checks what the command read and wrote.
"""

from __future__ import annotations

import json
import os
import threading

import pytest

import meshvis
from meshvis.cli.main import main
from meshvis.errors import ModelFormatError
from meshvis.io.mtl import TextureWarning

TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
PRIVATE = "# private model\n" + TETRA


def _files(root) -> set[str]:
    return {os.path.relpath(os.path.join(d, f), root) for d, _, fs in os.walk(root) for f in fs}


@pytest.fixture
def lib(tmp_path):
    """tmp/elsewhere/private.obj and tmp/lib/good.obj."""
    (tmp_path / "elsewhere").mkdir()
    (tmp_path / "elsewhere" / "private.obj").write_text(PRIVATE)
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "good.obj").write_text(TETRA)
    return tmp_path


# ---------------------------------------------------------------------------- batch
def test_batch_does_not_follow_a_link_out_of_its_input_folder(lib, capsys):
    os.symlink(os.path.join("..", "elsewhere", "private.obj"), lib / "lib" / "evil.obj")
    out = lib / "out"
    assert main(["batch", str(lib / "lib"), "--op", "orient", "--out", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    assert "evil.obj: lies outside" in err and "skipped" in err
    assert _files(out) == {"good.orient.obj", "good.orient.report.json", "summary.csv", "summary.json"}
    assert "private" not in (out / "summary.csv").read_text()


def test_batch_links_inside_the_folder_still_work(lib, capsys):
    (lib / "lib" / "sub").mkdir()
    os.symlink(os.path.join("..", "good.obj"), lib / "lib" / "sub" / "same.obj")  # the same file: once
    os.symlink("good.obj", lib / "lib" / "alias.obj")
    out = lib / "out"
    assert main(["batch", str(lib / "lib"), "--op", "orient", "--out", str(out), "-q"]) == 0
    assert "lies outside" not in capsys.readouterr().err
    assert sum(f.endswith(".orient.obj") for f in _files(out)) == 1


def test_batch_pattern_climbing_out_with_dots_writes_nothing_outside_out(lib, capsys):
    """``lib/*/../../elsewhere/*.obj``: its file is outside the pattern's folder ``lib``; the
    output name would have been ``out/../elsewhere/private.orient.obj``."""
    (lib / "lib" / "sub").mkdir()
    before = _files(lib / "elsewhere")
    pattern = str(lib / "lib" / "*" / ".." / ".." / "elsewhere" / "*.obj")
    rc = main(
        ["batch", pattern, str(lib / "lib" / "good.obj"), "--op", "orient", "--out", str(lib / "out"), "-q"]
    )
    assert rc == 0
    assert "lies outside" in capsys.readouterr().err
    assert _files(lib / "elsewhere") == before
    assert "good.orient.obj" in _files(lib / "out")


def test_batch_with_only_links_out_is_a_usage_error(lib, capsys):
    os.remove(lib / "lib" / "good.obj")
    os.symlink(os.path.join("..", "elsewhere", "private.obj"), lib / "lib" / "evil.obj")
    assert main(["batch", str(lib / "lib"), "--op", "orient", "--out", str(lib / "out"), "-q"]) == 2
    assert "no model file to run on" in capsys.readouterr().err
    assert not (lib / "out").exists()


# ---------------------------------------------------------------------------- MTL references
@pytest.mark.parametrize(
    "reference",
    [
        "file:///etc/hostname",
        "file:tex.png",
        "http://example.com/tex.png",
        "C:\\Users\\me\\tex.png",
        "..\\..\\elsewhere\\tex.png",
        "/etc/hostname",
    ],
)
def test_a_texture_reference_outside_the_folder_is_left_out_of_the_output(tmp_path, capsys, reference):
    m = tmp_path / "models" / "m"
    m.mkdir(parents=True)
    (tmp_path / "models" / "elsewhere").mkdir()
    (tmp_path / "models" / "elsewhere" / "tex.png").write_bytes(b"private")
    (m / "m.obj").write_text("mtllib m.mtl\nusemtl a\n" + TETRA)
    (m / "m.mtl").write_text(f"newmtl a\nKd 1 0 0\nmap_Kd {reference}\nmap_Ks kept.png\n")
    out = tmp_path / "out"
    out.mkdir()
    assert main(["orient", str(m / "m.obj"), "-o", str(out / "o.obj"), "-q"]) == 0
    err = capsys.readouterr().err
    assert f"m.obj: m.mtl: texture {reference} is outside the model's folder; skipped" in err
    mtl = (out / "o.mtl").read_text()
    assert reference not in mtl and "map_Kd" not in mtl
    assert "map_Ks kept.png" in mtl  # a missing texture inside the folder keeps its reference
    assert _files(out) == {"o.obj", "o.mtl"}


def test_a_backslash_path_inside_the_folder_is_found(tmp_path):
    (tmp_path / "tex").mkdir()
    (tmp_path / "tex" / "skin.png").write_bytes(b"\x89PNG fake")
    (tmp_path / "m.obj").write_text("mtllib m.mtl\nusemtl a\n" + TETRA)
    (tmp_path / "m.mtl").write_text("newmtl a\nmap_Kd tex\\skin.png\n")
    soup = meshvis.load(tmp_path / "m.obj")
    assert soup.materials[0].source.texture_path("tex\\skin.png") == str(tmp_path / "tex" / "skin.png")


@pytest.mark.parametrize("mtllib", ["../elsewhere/x.mtl", "file:///etc/x.mtl", "/etc/x.mtl"])
def test_an_mtllib_outside_the_folder_is_left_out_of_an_edited_obj(tmp_path, mtllib):
    """No ``usemtl``, so no MTL is written and the input's lines are kept -- but not this one."""
    (tmp_path / "m.obj").write_text(f"mtllib {mtllib}\nmtllib own.mtl\n" + TETRA)
    soup = meshvis.load(tmp_path / "m.obj")
    meshvis.save(soup.flipped(soup.faces[:, 0] >= 0), tmp_path / "o.obj")
    text = (tmp_path / "o.obj").read_text()
    assert mtllib not in text and "mtllib own.mtl" in text


# ---------------------------------------------------------------------------- glTF URIs
def _gltf(uri: str, kind: str = "buffers") -> dict:
    import base64
    import struct

    data = (
        "data:application/octet-stream;base64,"
        + base64.b64encode(struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)).decode()
    )
    doc = {
        "asset": {"version": "2.0"},
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}],
        "bufferViews": [{"buffer": 0, "byteLength": 36}],
        "buffers": [{"byteLength": 36, "uri": uri if kind == "buffers" else data}],
    }
    if kind == "images":
        doc["images"] = [{"uri": uri}]
    return doc


@pytest.mark.parametrize("kind", ["buffers", "images"])
def test_a_gltf_uri_naming_a_fifo_is_refused_not_waited_for(tmp_path, capsys, kind):
    os.mkfifo(tmp_path / "fifo.bin")
    src = tmp_path / "s.gltf"
    src.write_text(json.dumps(_gltf("fifo.bin", kind)))
    done = []
    worker = threading.Thread(target=lambda: done.append(main(["info", str(src)])), daemon=True)
    worker.start()
    worker.join(60)
    if worker.is_alive():  # unblock the reader so the test process can end
        with open(tmp_path / "fifo.bin", "wb"):
            pass
        worker.join(10)
        pytest.fail("the command waited for a writer on the FIFO")
    assert done == [2]
    err = capsys.readouterr().err
    assert f"{kind[:-1]} 0 refers to fifo.bin, which is not a regular file" in err and err.count("\n") == 1


@pytest.mark.parametrize(
    "uri", ["file:///etc/hostname", "file:x.bin", "C:/x.bin", "..\\..\\x.bin", "http:x.bin"]
)
def test_every_gltf_uri_form_that_leaves_the_folder_is_refused(tmp_path, uri):
    src = tmp_path / "s.gltf"
    src.write_text(json.dumps(_gltf(uri)))
    with pytest.raises(ModelFormatError, match="outside the model's folder"):
        meshvis.load(src)


def test_the_library_warns_about_outside_textures_too(tmp_path):
    (tmp_path / "m.obj").write_text("mtllib m.mtl\nusemtl a\n" + TETRA)
    (tmp_path / "m.mtl").write_text("newmtl a\nmap_Kd file:///etc/hostname\n")
    with pytest.warns(TextureWarning, match="outside the model's folder"):
        meshvis.load(tmp_path / "m.obj")


def test_a_texture_warning_names_the_mtl_file(tmp_path):
    (tmp_path / "mat").mkdir()
    (tmp_path / "m.obj").write_text("mtllib mat/lib.mtl\nusemtl a\n" + TETRA)
    (tmp_path / "mat" / "lib.mtl").write_text("newmtl a\nmap_Kd ../../x.png\n")
    with pytest.warns(TextureWarning) as caught:
        meshvis.load(tmp_path / "m.obj")
    assert str(caught[0].message) == (
        f"{tmp_path / 'm.obj'}: {os.path.join('mat', 'lib.mtl')}: texture ../../x.png is outside the model's folder; skipped"
    )
