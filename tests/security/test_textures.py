"""Hostile models against the file rules of docs/security.md: each case is built in a
temporary folder holding a canary file outside the model's folder, and the command must
read no file outside the model's folder, change no existing file without ``--force`` and
write nothing outside the output's folder.

Reads are watched with an audit hook (``open`` events) while ``meshvis.cli.main.main`` runs
in this process.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
import sys

import numpy as np
import pytest

import meshvis.io as mio
from meshvis.cli.main import main

CANARY = b"CANARY-7f3a-secret"
_OPENED: list[str] | None = None


def _audit(event: str, args: tuple) -> None:
    if _OPENED is not None and event == "open" and isinstance(args[0], (str, bytes, os.PathLike)):
        _OPENED.append(os.path.abspath(os.fsdecode(args[0])))


sys.addaudithook(_audit)


def _png(rgb=(255, 0, 0)) -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.new("RGB", (4, 4), rgb).save(buf, format="PNG")
    return buf.getvalue()


def _tree(root) -> dict[str, str]:
    """Relative path -> sha1 of every file under ``root``."""
    out = {}
    for folder, _, files in os.walk(root):
        for f in files:
            p = os.path.join(folder, f)
            out[os.path.relpath(p, root)] = hashlib.sha1(open(p, "rb").read()).hexdigest()
    return out


def _textured_obj(folder, maps: list[str], name: str = "model", mtl: str | None = None) -> str:
    """A tetrahedron whose material references the texture paths ``maps``."""
    os.makedirs(folder, exist_ok=True)
    mtl = mtl or name + ".mtl"
    lines = [f"mtllib {mtl}", "v 0 0 0", "v 1 0 0", "v 0 1 0", "v 0 0 1"]
    lines += ["vt 0 0", "vt 1 0", "vt 0 1", "usemtl skin"]
    lines += ["f 1/1 3/3 2/2", "f 1/1 2/2 4/3", "f 1/1 4/3 3/2", "f 2/1 3/2 4/3"]
    with open(os.path.join(folder, name + ".obj"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    keys = ["map_Kd", "map_Ka", "map_Ks", "map_Bump", "map_d"]
    block = ["newmtl skin", "Kd 1 1 1"] + [f"{keys[i % len(keys)]} {m}" for i, m in enumerate(maps)]
    mtl_path = os.path.join(folder, mtl)
    if not os.path.exists(mtl_path):
        with open(mtl_path, "w") as fh:
            fh.write("\n".join(block) + "\n")
    return os.path.join(folder, name + ".obj")


@pytest.fixture
def world(tmp_path):
    """tmp/canary.txt, tmp/canary.png, tmp/evil/.bashrc, tmp/models/m/ (model), tmp/home/ (output)."""
    (tmp_path / "canary.txt").write_bytes(CANARY)
    (tmp_path / "canary.png").write_bytes(_png((1, 2, 3)) + CANARY)
    (tmp_path / "evil").mkdir()
    (tmp_path / "evil" / ".bashrc").write_bytes(b"# the user's own shell setup\n")
    (tmp_path / "home").mkdir()
    (tmp_path / "home" / ".bashrc").write_bytes(b"# the user's own shell setup\n")
    (tmp_path / "models" / "m").mkdir(parents=True)
    return tmp_path


def _run(argv: list[str], capsys, model_folder, out_folder) -> tuple[int, str, list[str]]:
    """Run the CLI; return (status, stderr, files opened outside both folders)."""
    global _OPENED
    root = os.path.dirname(os.path.dirname(str(model_folder)))
    _OPENED = []
    try:
        rc = main(argv)
    finally:
        opened, _OPENED = _OPENED, None
    allowed = [os.path.realpath(model_folder), os.path.realpath(out_folder)]
    outside = [
        p
        for p in opened
        if os.path.realpath(p).startswith(os.path.realpath(root))
        and not any(os.path.realpath(p) == a or os.path.realpath(p).startswith(a + os.sep) for a in allowed)
    ]
    return rc, capsys.readouterr().err, outside


def _no_canary(folder) -> None:
    for path in _tree(folder):
        assert CANARY not in open(os.path.join(folder, path), "rb").read(), path


def test_textures_outside_the_model_folder_are_neither_read_nor_written(world, capsys):
    """map_Kd ../evil/.bashrc, an absolute path and a path two levels up: skipped, named."""
    m = world / "models" / "m"
    (m / "tex.png").write_bytes(_png())
    src = _textured_obj(m, ["tex.png", "../../evil/.bashrc", str(world / "canary.png"), "../../canary.txt"])
    before = _tree(world)
    rc, err, outside = _run(
        ["orient", src, "-o", str(world / "home" / "fixed.obj"), "-q"], capsys, m, world / "home"
    )
    assert rc == 0, err
    assert outside == []
    assert err.count("outside the model's folder; skipped") == 3
    assert "../../evil/.bashrc" in err and "../../canary.txt" in err
    after = _tree(world)
    assert {k: v for k, v in after.items() if k in before} == before  # nothing changed
    new = sorted(set(after) - set(before))
    assert new == ["home/fixed.mtl", "home/fixed.obj", "home/tex.png"]
    _no_canary(world / "home")
    mtl = (world / "home" / "fixed.mtl").read_text()
    assert "map_Kd tex.png" in mtl and "bashrc" not in mtl and "canary" not in mtl
    assert mio.load(world / "home" / "fixed.obj").n_faces == 4


def test_a_symlink_out_of_the_model_folder_is_not_followed(world, capsys):
    m = world / "models" / "m"
    os.symlink(world / "canary.png", m / "link.png")
    src = _textured_obj(m, ["link.png"])
    rc, err, outside = _run(
        ["orient", src, "-o", str(world / "home" / "o.obj"), "-q"], capsys, m, world / "home"
    )
    assert rc == 0 and outside == [] and "link.png is outside the model's folder" in err
    _no_canary(world / "home")


def test_an_mtl_outside_the_model_folder_is_not_read(world, capsys):
    m = world / "models" / "m"
    (world / "models" / "x.mtl").write_text("newmtl skin\nmap_Kd ../canary.png\n")
    src = _textured_obj(m, [], mtl="../x.mtl")
    rc, err, outside = _run(
        ["orient", src, "-o", str(world / "home" / "o.obj"), "-q"], capsys, m, world / "home"
    )
    assert rc == 0 and outside == [] and "MTL file ../x.mtl is outside the model's folder" in err
    _no_canary(world / "home")


def test_a_texture_never_replaces_an_existing_file(world, capsys):
    """The output folder already holds a different tex.png and a file named like the input
    texture: both stay, the copy gets a new name; a rerun with --force reuses its own copy."""
    m = world / "models" / "m"
    (m / "tex.png").write_bytes(_png((0, 255, 0)))
    (world / "home" / "tex.png").write_bytes(b"someone else's picture")
    src = _textured_obj(m, ["tex.png"])
    out = str(world / "home" / "fixed.obj")
    for argv in (["orient", src, "-o", out, "-q"], ["orient", src, "-o", out, "-q", "--force"]):
        rc, err, outside = _run(argv, capsys, m, world / "home")
        assert rc == 0 and outside == [], err
        assert (world / "home" / "tex.png").read_bytes() == b"someone else's picture"
        assert (world / "home" / "tex_1.png").read_bytes() == (m / "tex.png").read_bytes()
        assert "map_Kd tex_1.png" in (world / "home" / "fixed.mtl").read_text()
    assert sorted(os.listdir(world / "home")) == [".bashrc", "fixed.mtl", "fixed.obj", "tex.png", "tex_1.png"]


def test_output_next_to_the_input_references_its_textures_in_place(world, capsys):
    m = world / "models" / "m"
    (m / "sub").mkdir()
    (m / "sub" / "tex.png").write_bytes(_png())
    src = _textured_obj(m, ["sub/tex.png"])
    before = _tree(m)
    rc, err, _ = _run(["orient", src, "-o", str(m / "fixed.obj"), "-q"], capsys, m, m)
    assert rc == 0, err
    after = _tree(m)
    assert {k: v for k, v in after.items() if k in before} == before
    assert sorted(set(after) - set(before)) == ["fixed.mtl", "fixed.obj"]
    assert "map_Kd sub/tex.png" in (m / "fixed.mtl").read_text()


def test_the_output_mtl_is_not_overwritten_without_force(world, capsys):
    m = world / "models" / "m"
    src = _textured_obj(m, [])
    (world / "home" / "fixed.mtl").write_text("# mine\n")
    out = str(world / "home" / "fixed.obj")
    rc, err, _ = _run(["orient", src, "-o", out, "-q"], capsys, m, world / "home")
    assert rc == 2 and "fixed.mtl: exists (the MTL file of the output); use --force" in err
    assert err.count("\n") == 1
    assert (world / "home" / "fixed.mtl").read_text() == "# mine\n" and not os.path.exists(out)
    rc, err, _ = _run(["orient", src, "-o", out, "-q", "--force"], capsys, m, world / "home")
    assert rc == 0 and "newmtl skin" in (world / "home" / "fixed.mtl").read_text()


def test_the_output_mtl_is_never_the_input_mtl(world, capsys):
    """model.obj uses shared.mtl; writing shared.obj next to it would replace shared.mtl."""
    m = world / "models" / "m"
    src = _textured_obj(m, [], mtl="shared.mtl")
    before = _tree(world)
    rc, err, _ = _run(["orient", src, "-o", str(m / "shared.obj"), "-q", "--force"], capsys, m, m)
    assert rc == 2 and "shared.mtl: is a file of the input model" in err and err.count("\n") == 1
    assert _tree(world) == before  # no shared.obj, no temporary file, shared.mtl unchanged


def test_obj_to_glb_embeds_no_file_from_outside(world, capsys):
    m = world / "models" / "m"
    src = _textured_obj(m, [str(world / "canary.png")])
    out = world / "home" / "o.glb"
    rc, err, outside = _run(["orient", src, "-o", str(out), "-q"], capsys, m, world / "home")
    assert rc == 0 and outside == [] and "canary.png is outside the model's folder" in err
    assert CANARY not in out.read_bytes() and _png((1, 2, 3)) not in out.read_bytes()


def test_obj_to_glb_embeds_its_own_texture(world, capsys):
    m = world / "models" / "m"
    (m / "tex.png").write_bytes(_png((9, 8, 7)))
    src = _textured_obj(m, ["tex.png"])
    out = world / "home" / "o.glb"
    rc, err, _ = _run(["orient", src, "-o", str(out), "-q"], capsys, m, world / "home")
    assert rc == 0 and err == "" and _png((9, 8, 7)) in out.read_bytes()


def test_a_non_image_texture_with_glb_output_is_one_warning(world, capsys):
    m = world / "models" / "m"
    (m / "tex.png").write_bytes(b"this is not a picture")
    src = _textured_obj(m, ["tex.png"])
    rc, err, _ = _run(["orient", src, "-o", str(world / "home" / "o.glb"), "-q"], capsys, m, world / "home")
    assert rc == 0
    assert err.count("\n") == 1 and src in err and "texture tex.png is not an image" in err


def test_batch_same_named_textures_do_not_overwrite_each_other(world, capsys):
    m = world / "models" / "m"
    (m / "a").mkdir()
    (m / "b").mkdir()
    (m / "a" / "tex.png").write_bytes(_png((10, 0, 0)))
    (m / "b" / "tex.png").write_bytes(_png((0, 10, 0)))
    _textured_obj(m, ["a/tex.png"], name="x")
    _textured_obj(m, ["b/tex.png"], name="y")
    out = world / "home" / "batch"
    argv = ["batch", str(m / "x.obj"), str(m / "y.obj"), "--op", "orient", "--out", str(out), "-q"]
    rc, err, outside = _run(argv + ["--jobs", "2"], capsys, m, out)
    assert rc == 0, err
    got = {}
    for stem in ("x", "y"):
        mtl = (out / f"{stem}.orient.mtl").read_text()
        tex = next(line.split()[-1] for line in mtl.splitlines() if line.startswith("map_Kd"))
        got[stem] = (out / tex).read_bytes()
    assert got == {"x": (m / "a" / "tex.png").read_bytes(), "y": (m / "b" / "tex.png").read_bytes()}


def test_gltf_buffer_outside_the_model_folder_is_refused(world, capsys):
    m = world / "models" / "m"
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(CANARY), "uri": "../../canary.txt"}],
        "bufferViews": [{"buffer": 0, "byteLength": 12}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 1, "type": "VEC3"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "nodes": [{"mesh": 0}],
    }
    src = m / "s.gltf"
    src.write_text(json.dumps(doc))
    rc, err, outside = _run(
        ["orient", str(src), "-o", str(world / "home" / "o.obj"), "-q"], capsys, m, world / "home"
    )
    assert rc == 2 and outside == [] and err.count("\n") == 1
    assert str(src) in err and "../../canary.txt" in err and "outside the model's folder" in err
    assert os.listdir(world / "home") == [".bashrc"]


def test_library_texture_rules(world):
    """The same rules through meshvis.load / meshvis.save."""
    m = world / "models" / "m"
    src = _textured_obj(m, ["../../canary.png"])
    with pytest.warns(mio.mtl.TextureWarning, match="outside the model's folder"):
        soup = mio.load(src)
    mio.save(soup, world / "home" / "o.obj")
    _no_canary(world / "home")
    assert np.array_equal(mio.load(world / "home" / "o.obj").faces, soup.faces)
