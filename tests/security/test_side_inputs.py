"""The files a command reads beside the model (camera, camera path, label texts, a region's
path, a batch's earlier reports) and the options that are checked before any work: a bad
one is one line naming the file and the problem (exit status 2), never a traceback.

``main`` runs in this process, so an unexpected exception fails the test."""

from __future__ import annotations

import contextlib
import json
import os

import pytest

from meshvis.cli.main import main

TETRA = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
DEEP = "[" * 100_000
BIG = "[[1" + "0" * 400 + ", 0, 0]]"


@pytest.fixture
def here(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "t.obj").write_text(TETRA)
    return tmp_path


def _error(capsys, argv, *needles) -> str:
    rc = main(argv)
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and err.startswith("meshvis: error: "), err
    for n in needles:
        assert n in err, err
    return err


LABEL = ["label", "t.obj", "-o", "l.svg", "-q", "--size", "64", "64"]
SIDE_FILES = {
    # option -> the argv reading FILE
    "--from path:": lambda f: ["visible", "t.obj", "--from", f"path:{f}", "-q"],
    "remove-interior --from path:": lambda f: [
        "remove-interior",
        "t.obj",
        "-o",
        "o.obj",
        "--from",
        f"path:{f}",
        "--visibility",
        "view",
        "-q",
    ],
    "--camera": lambda f: [*LABEL, "--camera", f],
    "--camera-path": lambda f: [*LABEL, "--camera-path", f],
    "--texts": lambda f: [*LABEL, "--texts", f],
}


# ---------------------------------------------------------------------------- C1, C2: JSON side files
@pytest.mark.parametrize("option", SIDE_FILES)
@pytest.mark.parametrize(
    "content",
    [DEEP, BIG, "{", "\x00\x01", '"just a string"', "[]", "{}", "[1, 2]"],
    ids=["nested 100000 deep", "400-digit integer", "truncated", "binary", "a string", "[]", "{}", "[1, 2]"],
)
def test_every_json_side_file_fails_in_one_line_naming_it(here, capsys, option, content):
    (here / "side.json").write_text(content)
    rc = main(SIDE_FILES[option]("side.json"))
    err = capsys.readouterr().err
    if rc == 0:  # some contents are valid for some options ('{}': no texts)
        assert content in ("{}", "[]") and option == "--texts", (option, content)
        return
    assert rc == 2 and err.count("\n") == 1 and err.startswith("meshvis: error: side.json: "), err
    assert not os.path.exists(here / "l.svg") and not os.path.exists(here / "o.obj")


def test_a_json_side_file_with_a_byte_order_mark_is_read(here, capsys):
    (here / "cam.json").write_bytes(
        b"\xef\xbb\xbf" + json.dumps({"position": [3, 3, 3], "target": [0, 0, 0]}).encode()
    )
    (here / "texts.json").write_bytes(b"\xef\xbb\xbf" + json.dumps({"t": "Tetra"}).encode())
    assert (
        main(
            [
                *LABEL,
                "--size",
                "256",
                "256",
                "--camera",
                "cam.json",
                "--texts",
                "texts.json",
                "--json",
                "l.json",
            ]
        )
        == 0
    )
    assert json.loads((here / "l.json").read_text())["frames"][0]["labels"][0]["text"] == "Tetra"


# ---------------------------------------------------------------------------- C6, M2: texts
def test_a_texts_csv_field_past_the_csv_limit(here, capsys):
    (here / "t.csv").write_text("t," + "x" * 140_000 + "\n")
    _error(
        capsys,
        [*LABEL, "--texts", "t.csv"],
        "t.csv: cannot read the label texts",
        "field larger than field limit",
    )


def test_a_label_text_past_its_cap(here, capsys):
    (here / "t.csv").write_text("t," + "x" * 5_000 + "\n")
    _error(
        capsys,
        [*LABEL, "--texts", "t.csv"],
        "t.csv: the label text of 't' has 5000 characters (at most 1000)",
    )


@pytest.mark.parametrize(
    "name, content", [("t.csv", "nobody,Text\n"), ("t.json", '{"nobody": "Text"}'), ("t.json", '{"7": "x"}')]
)
def test_a_texts_key_naming_no_part_names_the_file(here, capsys, name, content):
    (here / name).write_text(content)
    _error(capsys, [*LABEL, "--texts", name], f"{name}: label text for")


def test_a_texts_csv_with_a_byte_order_mark(here, capsys):
    (here / "t.csv").write_bytes(b"\xef\xbb\xbft,Tetra\n")
    assert main([*LABEL, "--size", "256", "256", "--texts", "t.csv", "--json", "l.json"]) == 0
    assert json.loads((here / "l.json").read_text())["frames"][0]["labels"][0]["text"] == "Tetra"


# ---------------------------------------------------------------------------- M2, W2: cameras
@pytest.mark.parametrize(
    "camera, needle",
    [
        (
            {"position": [3, 3, 3], "target": [0, 0, 0], "ortho_height": -1, "orthographic": True},
            "ortho_height must be above 0",
        ),
        ({"position": [3, 3, 3], "target": [0, 0, 0], "fov": "wide"}, "field of view must be a number"),
        ({"position": [3, 3, 3], "target": [0, 0, 0], "fov": 200}, "field of view must be in (0, 180)"),
        ({"position": [3, 3], "target": [0, 0, 0]}, "camera position must have shape (k, 3)"),
        ({"position": [3, 3, 3], "target": [0, 0, 0], "up": [0, 0, 0]}, "camera up must not be zero"),
        ({"position": [3, 3, 3]}, "the camera has no target"),
        ({"position": [3, 3, 3], "target": [0, 0, 0], "zoom": 2}, "unknown camera keys: zoom"),
        (
            {"position": [3, 3, 3], "target": [0, 0, 0], "orthographic": "yes"},
            "orthographic must be True or False",
        ),
    ],
)
def test_a_bad_camera_names_its_file(here, capsys, camera, needle):
    (here / "cam.json").write_text(json.dumps(camera))
    _error(capsys, [*LABEL, "--camera", "cam.json"], "cam.json: ", needle)
    (here / "path.json").write_text(json.dumps([{"position": [3, 3, 3], "target": [0, 0, 0]}, camera]))
    _error(capsys, [*LABEL, "--camera-path", "path.json"], "path.json: camera 1: ", needle)


@pytest.mark.parametrize(
    "extra, needle",
    [
        (["--distance=-1"], "distance must be above 0"),
        (["--fit-margin", "0"], "margin must be above 0"),
        (["--fov", "0"], "field of view must be in (0, 180)"),
        (["--fov", "nan"], "field of view must be finite"),
    ],
)
def test_label_camera_options_out_of_range(here, capsys, extra, needle):
    _error(capsys, [*LABEL, *extra], needle)
    _error(capsys, [*LABEL, "--orbit", "2", *extra], needle)


# ---------------------------------------------------------------------------- M1: a viewer on the surface
@pytest.mark.parametrize(
    "region",
    ["points:0,0.5,0.5", "points:0,0,0", "points:0,0,0;1,0,0", "box:0,0,0,0,0,0", "box:0,0,0,0.1,0.1,0"],
)
def test_a_viewer_standing_on_the_model(here, capsys, region):
    assert main(["visible", "t.obj", "--from", region, "--report", "r.json", "-q"]) == 0, (
        capsys.readouterr().err
    )
    assert json.loads((here / "r.json").read_text())["seen_faces"] >= 3


# ---------------------------------------------------------------------------- C3: a tampered resume
@pytest.mark.parametrize(
    "tamper",
    [
        lambda d: d["batch"].update(faces_in="abc", seconds="slow", rays=[1]),
        lambda d: d.update(batch=[1]),
        lambda d: d.update(batch="x"),
        lambda d: d["batch"].update(options=[1]),
        lambda d: d.update(status=["ok"]),
    ],
)
def test_batch_resume_with_a_tampered_report(here, capsys, tamper):
    os.mkdir("lib")
    os.replace("t.obj", "lib/t.obj")
    argv = ["batch", "lib", "--op", "orient", "--out", "out"]
    assert main([*argv, "-q"]) == 0
    report = here / "out" / "t.orient.report.json"
    data = json.loads(report.read_text())
    tamper(data)
    report.write_text(json.dumps(data))
    assert main([*argv, "--resume"]) == 0
    out = capsys.readouterr().out
    assert "t.obj" in out


def test_batch_resume_with_a_report_nested_too_deep(here, capsys):
    os.mkdir("lib")
    os.replace("t.obj", "lib/t.obj")
    argv = ["batch", "lib", "--op", "orient", "--out", "out", "-q"]
    assert main(argv) == 0
    (here / "out" / "t.orient.report.json").write_text('{"status": "ok", "batch": ' + DEEP)
    assert main([*argv, "--resume"]) == 0  # not complete: run again
    assert json.loads((here / "out" / "t.orient.report.json").read_text())["status"] == "ok"


# ---------------------------------------------------------------------------- W1: batch options
@pytest.mark.parametrize(
    "extra, needle",
    [
        (["--from", "junk"], "unknown region 'junk'"),
        (["--from", "path:missing.json"], "missing.json: camera path file not found"),
        (["--from", "box:1,1,1,0,0,0"], "min <= max"),
        (["--keep-border", "-1"], "keep_border must be at least 0, got -1"),
        (["--budget", "0"], "invalid positive_int value"),
    ],
)
def test_batch_options_are_checked_once_before_any_file(here, capsys, extra, needle):
    os.mkdir("lib")
    os.replace("t.obj", "lib/t.obj")
    with pytest.raises(SystemExit) if needle.startswith("invalid") else contextlib.nullcontext():
        _error(capsys, ["batch", "lib", "--op", "remove-interior", "--out", "out", "-q", *extra], needle)
    assert not os.path.exists("out")


# ---------------------------------------------------------------------------- C4: seeds on the command line
@pytest.mark.parametrize(
    "argv",
    [
        ["visible", "t.obj"],
        ["orient", "t.obj", "-o", "o.obj", "--from", "box:-1,-1,-1,2,2,2"],
        ["remove-interior", "t.obj", "-o", "o.obj", "--visibility", "view"],
        ["remove-interior", "t.obj", "-o", "o.obj"],
        ["layers", "t.obj", "-o", "o.obj"],
        ["render", "t.obj", "-o", "o.png", "--color-by", "layer"],
        ["demo", "--out", "d"],
    ],
    ids=lambda argv: " ".join(argv[:1] + argv[4:6] if len(argv) > 4 else argv[:1]),
)
@pytest.mark.parametrize("seed", ["-5", str(2**200)])
def test_every_seed_option_is_checked(here, capsys, argv, seed):
    _error(capsys, [*argv, "--seed", seed, "-q"], "seed must be at")
    assert sorted(os.listdir(here)) == ["t.obj"]
