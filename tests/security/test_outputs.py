"""What a command writes: never over a file its input reads, never two outputs on one path,
all of its outputs or none of them, and ``-`` as standard output wherever a report or JSON
can be written."""

from __future__ import annotations

import json
import os

import pytest

import meshvis
from meshvis.cli.main import main
from meshvis.errors import OutputError

TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
#: two nested tetrahedra: two layers
NESTED = TETRA + "v .2 .2 .2\nv .4 .2 .2\nv .2 .4 .2\nv .2 .2 .4\nf 5 7 6\nf 5 6 8\nf 5 8 7\nf 6 7 8\n"


def _files(root) -> dict[str, bytes]:
    return {
        os.path.relpath(os.path.join(d, f), root): open(os.path.join(d, f), "rb").read()
        for d, _, fs in os.walk(root)
        for f in fs
    }


def _error(capsys, argv, *needles) -> str:
    rc = main(argv)
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and err.startswith("meshvis: error: "), err
    for n in needles:
        assert n in err, err
    return err


# ---------------------------------------------------------------------------- L2: outputs over inputs
@pytest.fixture
def textured(tmp_path):
    """m.obj whose MTL names textures called like outputs: sub/o.obj, sub/o.mtl, r.json."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "m.obj").write_text("mtllib m.mtl\nusemtl a\n" + TETRA)
    (tmp_path / "m.mtl").write_text(
        "newmtl a\nmap_Kd sub/o.obj\nmap_Ks r.json\nmap_Ka sub/o.mtl\nbump shot.png\n"
    )
    for name in ("sub/o.obj", "sub/o.mtl", "r.json", "shot.png"):
        (tmp_path / name).write_bytes(b"texture " + name.encode())
    return tmp_path


@pytest.mark.parametrize(
    "extra, named",
    [
        (["-o", "sub/o.obj"], "sub/o.obj"),  # the model output over a texture
        (["-o", "sub/o2.obj", "--report", "r.json"], "r.json"),  # the report over a texture
        (["-o", "sub/o2.obj", "--report", "sub/o.mtl"], "sub/o.mtl"),
        (["-o", "sub/o.obj.glb", "--preview", "shot.png"], "shot.png"),
    ],
)
def test_no_output_replaces_a_texture_even_with_force(textured, capsys, monkeypatch, extra, named):
    monkeypatch.chdir(textured)
    before = _files(textured)
    _error(capsys, ["orient", "m.obj", "-q", "--force", *extra], f"{named}: is a file of the input model")
    assert _files(textured) == before


@pytest.mark.parametrize(
    "argv",
    [
        ["render", "m.obj", "-o", "r.json.png"],
        ["visible", "m.obj", "--preview", "r.json.png"],
        ["visible", "m.obj", "--report", "r.json.png"],
        ["label", "m.obj", "-o", "r.json.png", "--size", "32", "32"],
        ["label", "m.obj", "-o", "l.svg", "--json", "r.json.png", "--size", "32", "32"],
    ],
    ids=lambda argv: " ".join(argv[:1] + argv[2:3]),
)
def test_no_picture_or_report_replaces_a_texture(textured, capsys, monkeypatch, argv):
    monkeypatch.chdir(textured)
    (textured / "m.mtl").write_text("newmtl a\nmap_Kd r.json.png\n")
    (textured / "r.json.png").write_bytes(b"texture")
    before = _files(textured)
    _error(capsys, [*argv, "-q", "--force"], "r.json.png: is a file of the input model")
    assert _files(textured) == before


def test_the_library_does_not_save_over_a_texture(textured):
    soup = meshvis.load(textured / "m.obj")
    with pytest.raises(OutputError, match="is a file of the input model"):
        meshvis.save(soup, textured / "sub" / "o.obj")
    meshvis.save(soup, textured / "sub" / "o.ply")  # a new name is fine
    meshvis.save(soup, textured / "sub" / "p.obj")
    assert (textured / "sub" / "o.obj").read_bytes() == b"texture sub/o.obj"


# ---------------------------------------------------------------------------- L4: two outputs on one path
@pytest.mark.parametrize(
    "argv, named",
    [
        (["orient", "t.obj", "-o", "out/o.obj", "--report", "out/o.mtl"], "out/o.mtl"),
        (["orient", "t.obj", "-o", "out/o.obj", "--report", "out/../out/o.obj"], "o.obj"),
        (["remove-interior", "t.obj", "-o", "out/o.obj", "--removed", "out/o.obj"], "out/o.obj"),
        (["classify", "t.obj", "--report", "out/r.json", "--per-face", "out/r.json"], "out/r.json"),
        (["visible", "t.obj", "--preview", "out/x.png", "--report", "out/x.png"], "out/x.png"),
        (["label", "t.obj", "-o", "out/x.svg", "--json", "out/x.svg"], "out/x.svg"),
        (["label", "t.obj", "-o", "out/x.svg", "--png", "out/x.svg"], "out/x.svg"),
        (["label", "t.obj", "-o", "out/x.png", "--png", "out/x.png"], "out/x.png"),
        (["label", "t.obj", "-o", "out/x.svg", "--orbit", "3", "--json", "out/x_001.svg"], "out/x_001.svg"),
        (
            ["orient", "t.obj", "-o", "out/o.glb", "--report", "out/r.png", "--preview", "out/r.png"],
            "out/r.png",
        ),
        (["classify", "t.obj", "--graphml", "out/g.json", "--report", "out/g.json"], "out/g.json"),
        (
            [
                "remove-interior",
                "t.obj",
                "-o",
                "out/a.obj",
                "--removed",
                "out/b.obj",
                "--report",
                "out/b.mtl",
            ],
            "out/b.mtl",
        ),
    ],
)
def test_two_outputs_of_one_command_on_one_path(tmp_path, capsys, monkeypatch, argv, named):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.obj").write_text(TETRA)
    (tmp_path / "out").mkdir()
    _error(capsys, [*argv, "-q"], named, "two outputs of the command are this one file")
    assert os.listdir(tmp_path / "out") == []


def test_layers_report_onto_a_per_layer_file(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "n.obj").write_text(NESTED)
    for extra, named in (
        (["--report", "o.layer1.obj"], "o.layer1.obj"),
        (["--report", "o.layer2.mtl"], "o.layer2.mtl"),
    ):
        _error(capsys, ["layers", "n.obj", "-o", "o.obj", "-q", *extra], named, "a file of one layer")
        assert sorted(os.listdir(tmp_path)) == ["n.obj"]
    assert main(["layers", "n.obj", "-o", "o.obj", "-q", "--preview", "o.png"]) == 0
    assert {"o.obj", "o.layer1.obj", "o.layer2.obj", "o.png"} <= set(os.listdir(tmp_path))


# ---------------------------------------------------------------------------- L3: all or nothing
def test_a_name_too_long_for_the_file_system_is_refused_before_any_work(tmp_path, capsys):
    (tmp_path / "t.obj").write_text(TETRA)
    report = str(tmp_path / ("r" * 251 + ".json"))  # 256 bytes
    _error(
        capsys,
        ["orient", str(tmp_path / "t.obj"), "-o", str(tmp_path / "o.obj"), "--report", report, "-q"],
        "more than the file system allows",
    )
    assert sorted(os.listdir(tmp_path)) == ["t.obj"]


def test_a_rename_failing_while_outputs_are_published_leaves_none(tmp_path, capsys, monkeypatch):
    """The third of three renames fails: the first two are taken back, the old files return."""
    (tmp_path / "t.obj").write_text(TETRA)
    (tmp_path / "o.obj").write_text("old model\n")
    real_replace = os.replace
    calls = []

    def replace(src, dst, *a, **k):
        if str(src).endswith(".tmp") and not os.path.basename(str(dst)).startswith("."):
            calls.append(dst)
            if str(dst).endswith("r.json"):
                raise OSError(28, "No space left on device", str(src))
        return real_replace(src, dst, *a, **k)

    monkeypatch.setattr(os, "replace", replace)
    argv = ["orient", str(tmp_path / "t.obj"), "-o", str(tmp_path / "o.obj"), "-q", "--force"]
    _error(
        capsys, [*argv, "--preview", str(tmp_path / "p.png"), "--report", str(tmp_path / "r.json")], "r.json"
    )
    assert len(calls) >= 3
    assert sorted(os.listdir(tmp_path)) == ["o.obj", "t.obj"]
    assert (tmp_path / "o.obj").read_text() == "old model\n"


# ---------------------------------------------------------------------------- L5: demo
@pytest.mark.parametrize("extra", [["--size", "0"], ["--size", "-5"], ["--size", "5000"], ["--seed", "-1"]])
def test_a_refused_demo_writes_nothing(tmp_path, capsys, extra):
    out = tmp_path / "demo"
    _error(capsys, ["demo", "--out", str(out), "-q", *extra])
    assert not out.exists()


def test_a_demo_failing_midway_leaves_nothing(tmp_path, capsys, monkeypatch):
    from meshvis.eval import demo

    def broken(*a, **k):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(demo, "layers", broken)
    out = tmp_path / "demo"
    assert main(["demo", "--out", str(out), "-q", "--size", "16"]) == 2
    assert not out.exists()


# ---------------------------------------------------------------------------- M3: '-' is standard output
def test_visible_report_dash_goes_to_standard_output(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.obj").write_text(TETRA)
    assert main(["visible", "t.obj", "--report", "-"]) == 0
    out = capsys.readouterr().out
    assert json.loads(out)["faces"] == 4
    assert sorted(os.listdir(tmp_path)) == ["t.obj"]


def test_label_json_dash_goes_to_standard_output(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.obj").write_text(TETRA)
    assert main(["label", "t.obj", "-o", "l.svg", "--json", "-", "--size", "64", "64"]) == 0
    out = capsys.readouterr().out
    assert json.loads(out)["inputs"] == ["t.obj"]
    assert sorted(os.listdir(tmp_path)) == ["l.svg", "t.obj"]
