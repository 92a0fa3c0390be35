"""Bad input through the command line: one line on stderr naming the file and the problem,
exit status 2, no traceback, nothing already written lost.

Most cases call ``cli.main.main`` in this process (fast; an unexpected exception fails the
test, so "no traceback" is checked too); a few run ``python -m meshvis`` to check the real
stderr.  Cases that must *work* (a single triangle, many-vertex polygons, coordinates
around 1e30) check the output instead.
"""

from __future__ import annotations

import errno
import json
import os
import struct
import subprocess
import sys

import numpy as np
import pytest

import meshvis.io as mio
from meshvis.cli.main import build_parser, main

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FORMATS = ("obj", "ply", "stl", "off", "glb", "gltf", "3mf")
IS_ROOT = hasattr(os, "geteuid") and os.geteuid() == 0

PLY_HEAD = (
    "ply\nformat ascii 1.0\nelement vertex {nv}\nproperty float x\nproperty float y\nproperty float z\n"
    "element face {nf}\nproperty list uchar int vertex_indices\nend_header\n"
)
TRI = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])


def _available() -> set[str]:
    sub = next(a for a in build_parser()._actions if a.dest == "command")
    return set(sub.choices)


COMMANDS_HERE = _available()
MODEL_COMMANDS = [
    c for c in ("info", "classify", "orient", "remove-interior", "layers", "render") if c in COMMANDS_HERE
]


def _argv(cmd: str, path: str, tmp_path, out: str | None = None) -> list[str]:
    """Arguments of ``cmd`` reading ``path``."""
    if cmd == "info":
        return ["info", path, "--no-intersections"]
    if cmd == "classify":
        return ["classify", path, "-q"]
    if cmd == "render":
        return ["render", path, "-o", out or str(tmp_path / "picture.png"), "-q", "--size", "32", "32"]
    ext = os.path.splitext(path)[1] or ".obj"
    if ext == ".3mf" or (cmd == "layers" and ext in (".stl", ".off")):
        ext = ".glb"  # a format that cannot hold the result is refused before the input is read
    return [cmd, path, "-o", out or str(tmp_path / f"out{ext}"), "-q"]


def _cli(capsys, argv: list[str]) -> tuple[int, str, str]:
    rc = main(argv)
    out, err = capsys.readouterr()
    return rc, out, err


def _assert_one_line_error(rc: int, err: str, path, *words: str) -> str:
    """Exit status 2 and exactly one stderr line ``meshvis: error: <file>: <problem>``."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert rc == 2, err
    assert len(lines) == 1, err
    line = lines[0]
    assert line.startswith("meshvis: error: ")
    assert os.path.basename(str(path)) in line
    for w in words:
        assert w.lower() in line.lower(), line
    assert "Traceback" not in err
    return line


def _write(path, data: str | bytes) -> str:
    with open(path, "wb") as fh:
        fh.write(data.encode() if isinstance(data, str) else data)
    return str(path)


@pytest.fixture(scope="module")
def good_files(tmp_path_factory) -> dict[str, str]:
    """An 80-face sphere in every format (3MF through trimesh)."""
    import trimesh

    folder = tmp_path_factory.mktemp("good")
    sphere = trimesh.creation.icosphere(1)
    files = {}
    for ext in FORMATS[:-1]:
        files[ext] = str(folder / f"sphere.{ext}")
        mio.save((sphere.vertices, sphere.faces), files[ext])
    files["3mf"] = str(folder / "sphere.3mf")
    sphere.export(files["3mf"])
    files["ply-ascii"] = _write(
        folder / "ascii.ply",
        PLY_HEAD.format(nv=len(sphere.vertices), nf=len(sphere.faces))
        + "".join("%r %r %r\n" % tuple(v) for v in sphere.vertices)
        + "".join("3 %d %d %d\n" % tuple(f) for f in sphere.faces),
    )
    return files


# ------------------------------------------------------------------ damaged content
@pytest.mark.parametrize("fraction", [0.1, 0.5, 0.9, 0.99])
@pytest.mark.parametrize("fmt", ["ply", "ply-ascii", "stl", "off", "glb", "gltf", "3mf"])
def test_truncated_file(tmp_path, capsys, good_files, fmt, fraction):
    data = open(good_files[fmt], "rb").read()
    ext = "ply" if fmt == "ply-ascii" else fmt
    path = _write(tmp_path / f"cut.{ext}", data[: int(len(data) * fraction)])
    rc, _, err = _cli(capsys, _argv("remove-interior", path, tmp_path))
    _assert_one_line_error(rc, err, path)
    assert not os.path.exists(tmp_path / f"out.{ext}")


def test_truncated_obj(tmp_path, capsys, good_files):
    """OBJ has no counts: a cut between two records is a smaller valid model and cannot be
    told apart; cuts inside the vertex block or inside a face record are errors."""
    text = open(good_files["obj"]).read()
    first_face = text.index("\nf ")
    path = _write(tmp_path / "cut.obj", text[: first_face // 2])
    _assert_one_line_error(*_cli(capsys, _argv("orient", path, tmp_path))[::2], path, "no faces")
    path = _write(tmp_path / "cut1.obj", text[: first_face + 1] + "f 1")  # cut after one corner
    _assert_one_line_error(*_cli(capsys, _argv("orient", path, tmp_path))[::2], path, "3 vertices")


@pytest.mark.parametrize("cmd", MODEL_COMMANDS)
@pytest.mark.parametrize("ext", FORMATS)
def test_random_bytes(tmp_path, capsys, cmd, ext):
    rng = np.random.default_rng(FORMATS.index(ext))
    data = rng.integers(0, 256, 2000, dtype=np.uint8).tobytes()  # 2000 bytes: not 84 + 50 k
    path = _write(tmp_path / f"noise.{ext}", data)
    rc, _, err = _cli(capsys, _argv(cmd, path, tmp_path))
    _assert_one_line_error(rc, err, path)


@pytest.mark.parametrize(
    "content,ext",
    [
        ("obj", "stl"),
        ("ply", "obj"),
        ("stl", "ply"),
        ("glb", "obj"),
        ("off", "ply"),
        ("3mf", "glb"),
        ("obj", "off"),
    ],
)
def test_wrong_extension(tmp_path, capsys, good_files, content, ext):
    path = _write(tmp_path / f"model.{ext}", open(good_files[content], "rb").read())
    rc, _, err = _cli(capsys, _argv("remove-interior", path, tmp_path))
    _assert_one_line_error(rc, err, path)


@pytest.mark.parametrize("name", ["model.xyz", "model", "model.obj.bak"])
def test_unknown_extension(tmp_path, capsys, good_files, name):
    path = _write(tmp_path / name, open(good_files["obj"], "rb").read())
    rc, _, err = _cli(capsys, _argv("orient", path, tmp_path, out=str(tmp_path / "o.obj")))
    _assert_one_line_error(rc, err, path, "extension")


# ------------------------------------------------------------------ bad numbers
def _text_model(ext: str, vertices: list[str], faces: list[list[int]]) -> str:
    """A model file in a text format with the vertex lines given as text."""
    if ext == "obj":
        return "".join(f"v {v}\n" for v in vertices) + "".join(
            "f " + " ".join(str(i + 1 if i >= 0 else i) for i in f) + "\n" for f in faces
        )
    if ext == "off":
        return (
            f"OFF\n{len(vertices)} {len(faces)} 0\n"
            + "".join(f"{v}\n" for v in vertices)
            + "".join(f"{len(f)} " + " ".join(map(str, f)) + "\n" for f in faces)
        )
    if ext == "ply":
        return (
            PLY_HEAD.format(nv=len(vertices), nf=len(faces))
            + "".join(f"{v}\n" for v in vertices)
            + "".join(f"{len(f)} " + " ".join(map(str, f)) + "\n" for f in faces)
        )
    if ext == "stl":  # ASCII STL: faces are given by position
        body = "".join(
            "facet normal 0 0 1\nouter loop\n"
            + "".join(f"vertex {vertices[i]}\n" for i in f)
            + "endloop\nendfacet\n"
            for f in faces
        )
        return f"solid t\n{body}endsolid t\n"
    raise ValueError(ext)


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
@pytest.mark.parametrize("ext", ["obj", "off", "ply", "stl"])
def test_non_finite_coordinates(tmp_path, capsys, ext, value):
    path = _write(tmp_path / f"bad.{ext}", _text_model(ext, ["0 0 0", f"1 {value} 0", "0 1 0"], [[0, 1, 2]]))
    rc, _, err = _cli(capsys, _argv("orient", path, tmp_path))
    _assert_one_line_error(rc, err, path, "nan or infinite")


def test_non_finite_binary_stl(tmp_path, capsys):
    tri = struct.pack("<12fH", 0, 0, 1, 0, 0, 0, float("nan"), 0, 0, 0, 1, 0, 0)
    path = _write(tmp_path / "bad.stl", b"\0" * 80 + struct.pack("<I", 1) + tri)
    rc, _, err = _cli(capsys, _argv("layers", path, tmp_path))
    _assert_one_line_error(rc, err, path, "nan or infinite")


@pytest.mark.parametrize("index", [3, 99, -1, -9])
@pytest.mark.parametrize("ext", ["obj", "off", "ply"])
def test_bad_vertex_index(tmp_path, capsys, ext, index):
    # OBJ counts from 1 and reads negative numbers as relative: -1 is the last vertex, so
    # use -4 (before the first) instead
    if ext == "obj" and index == -1:
        index = -4
    path = _write(tmp_path / f"bad.{ext}", _text_model(ext, ["0 0 0", "1 0 0", "0 1 0"], [[0, 1, index]]))
    rc, _, err = _cli(capsys, _argv("remove-interior", path, tmp_path))
    line = _assert_one_line_error(rc, err, path)
    assert "index" in line or "range" in line or "before the first" in line


@pytest.mark.parametrize("corners", [[0, 1], [0]])
@pytest.mark.parametrize("ext", ["obj", "off", "ply"])
def test_faces_with_fewer_than_three_vertices(tmp_path, capsys, ext, corners):
    path = _write(tmp_path / f"short.{ext}", _text_model(ext, ["0 0 0", "1 0 0", "0 1 0"], [corners]))
    rc, _, err = _cli(capsys, _argv("orient", path, tmp_path))
    lines = [ln for ln in err.splitlines() if ln.strip()]
    # a two-corner record is an edge: skipped with a one-line warning; then there is no face
    assert all(ln.startswith(("meshvis: error: ", "meshvis: warning: ")) for ln in lines), err
    _assert_one_line_error(rc, "\n".join(ln for ln in lines if "error" in ln), path)


@pytest.mark.parametrize("ext", ["obj", "off", "ply"])
def test_two_vertex_record_next_to_a_face_is_skipped_with_a_warning(tmp_path, capsys, ext):
    path = _write(
        tmp_path / f"mixed.{ext}", _text_model(ext, ["0 0 0", "1 0 0", "0 1 0"], [[0, 1, 2], [0, 1]])
    )
    out = str(tmp_path / f"out.{ext}")
    rc, _, err = _cli(capsys, _argv("orient", path, tmp_path, out=out))
    assert rc == 0, err
    assert [ln for ln in err.splitlines() if ln.strip()] == [ln for ln in err.splitlines() if "warning" in ln]
    # the output keeps the edge record, as the input had it, so reading it warns again
    with pytest.warns(UserWarning, match="with 2 vertices"):
        assert mio.load(out).n_faces == 1


@pytest.mark.parametrize("ext", ["obj", "off", "ply"])
def test_polygon_with_many_vertices_works(tmp_path, capsys, ext):
    n = 300
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    verts = [f"{float(np.cos(a))!r} {float(np.sin(a))!r} 0" for a in angle]
    path = _write(tmp_path / f"poly.{ext}", _text_model(ext, verts, [list(range(n))]))
    out = str(tmp_path / f"out.{ext}")
    rc, _, err = _cli(capsys, _argv("remove-interior", path, tmp_path, out=out))
    assert rc == 0, err
    soup = mio.load(out)
    assert soup.n_faces == n - 2  # triangulated, every triangle visible (a flat sheet)
    assert np.isclose(soup.total_area, 0.5 * n * np.sin(2 * np.pi / n))


@pytest.mark.parametrize("fmt", ["obj", "off", "ply", "stl", "stl-binary", "gltf", "glb"])
def test_zero_faces(tmp_path, capsys, fmt):
    if fmt == "stl-binary":
        path = _write(tmp_path / "empty.stl", b"\0" * 80 + struct.pack("<I", 0))
    elif fmt in ("gltf", "glb"):
        js = json.dumps({"asset": {"version": "2.0"}}).encode()
        js += b" " * (-len(js) % 4)
        data = (
            js
            if fmt == "gltf"
            else (b"glTF" + struct.pack("<II", 2, 20 + len(js)) + struct.pack("<I", len(js)) + b"JSON" + js)
        )
        path = _write(tmp_path / f"empty.{fmt}", data)
    else:
        path = _write(tmp_path / f"empty.{fmt}", _text_model(fmt, ["0 0 0", "1 0 0", "0 1 0"], []))
    rc, _, err = _cli(capsys, _argv("orient", path, tmp_path))
    _assert_one_line_error(rc, err, path, "no faces")


def test_empty_file(tmp_path, capsys):
    path = _write(tmp_path / "empty.obj", b"")
    _assert_one_line_error(*_cli(capsys, _argv("classify", path, tmp_path))[::2], path, "empty")


def test_only_degenerate_faces(tmp_path, capsys):
    path = _write(tmp_path / "flat.obj", _text_model("obj", ["0 0 0", "1 0 0", "2 0 0"], [[0, 1, 2]]))
    _assert_one_line_error(*_cli(capsys, _argv("orient", path, tmp_path))[::2], path, "degenerate")


@pytest.mark.parametrize(
    "cmd", [c for c in ("classify", "orient", "remove-interior", "layers") if c in COMMANDS_HERE]
)
def test_single_triangle_works(tmp_path, capsys, cmd):
    path = _write(tmp_path / "tri.obj", _text_model("obj", ["0 0 0", "1 0 0", "0 1 0"], [[0, 1, 2]]))
    report = str(tmp_path / "report.json")
    rc, _, err = _cli(capsys, _argv(cmd, path, tmp_path) + ["--report", report])
    assert rc == 0, err
    data = json.load(open(report))
    if cmd != "classify":
        out = mio.load(tmp_path / "out.obj")
        assert out.n_faces == 1
        assert np.array_equal(np.sort(out.triangles[0], axis=0), np.sort(TRI, axis=0))
    # a lone triangle is seen from both sides: one layer
    per_face = data["per_face"]
    if cmd == "layers":
        assert per_face["layer"] == [1] and per_face["outer_side"] == [2]
    elif cmd == "remove-interior":
        assert per_face["keep"] == [True] and per_face["reason"] == ["kept: seen from the region"]
    else:
        assert per_face["outside_front"] == [1.0] and per_face["outside_back"] == [1.0]


def _tetra_obj(scale: float) -> str:
    """A tetrahedron with its second face turned inward."""
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float) * scale
    f = [[0, 2, 1], [0, 3, 1], [0, 3, 2], [1, 2, 3]]  # the second face points inward (outward: 0 1 3)
    return _text_model("obj", ["%r %r %r" % tuple(map(float, p)) for p in v], f)


@pytest.mark.parametrize("ext", ["obj", "ply", "stl", "glb"])
def test_huge_coordinates_work(tmp_path, capsys, ext):
    """Coordinates of 1e30 work (the ray scene is built on a unit-size copy) and give the
    same result as the same model at scale 1; they survive every output format
    (float32 formats hold values up to 3.4e38)."""
    results = []
    for scale in (1.0, 1e30):
        path = _write(tmp_path / f"tet{scale:g}.obj", _tetra_obj(scale))
        out, report = str(tmp_path / f"out{scale:g}.{ext}"), str(tmp_path / f"r{scale:g}.json")
        rc, _, err = _cli(capsys, _argv("orient", path, tmp_path, out=out) + ["--report", report])
        assert rc == 0, err
        flipped = json.load(open(report))["per_face"]["flipped"]
        soup = mio.load(out)
        assert np.isfinite(soup.vertices).all()
        assert np.isclose(np.abs(soup.vertices).max(), scale, rtol=1e-6)
        results.append(flipped)
    assert results[0] == results[1] == [False, True, False, False]


def test_coordinates_too_large_fail_cleanly(tmp_path, capsys):
    path = _write(tmp_path / "tet.obj", _tetra_obj(1e301))
    _assert_one_line_error(*_cli(capsys, _argv("orient", path, tmp_path))[::2], path, "too large")


# ------------------------------------------------------------------ paths
@pytest.mark.parametrize("cmd", MODEL_COMMANDS)
def test_folder_as_input(tmp_path, capsys, cmd):
    folder = tmp_path / "model.obj"
    folder.mkdir()
    rc, _, err = _cli(capsys, _argv(cmd, str(folder), tmp_path))
    _assert_one_line_error(rc, err, folder, "folder")


@pytest.mark.parametrize("cmd", MODEL_COMMANDS)
def test_missing_file(tmp_path, capsys, cmd):
    path = str(tmp_path / "nowhere.obj")
    _assert_one_line_error(*_cli(capsys, _argv(cmd, path, tmp_path))[::2], path, "not found")


def test_unreadable_file(tmp_path, capsys, monkeypatch, good_files):
    path = _write(tmp_path / "locked.obj", open(good_files["obj"], "rb").read())
    if IS_ROOT:  # root reads every file: make the loader's open() refuse, as the system would

        def refuse(*args, **kwargs):
            raise PermissionError(errno.EACCES, "Permission denied")

        monkeypatch.setattr(mio.reading, "open", refuse, raising=False)
    else:
        os.chmod(path, 0)
    rc, _, err = _cli(capsys, _argv("orient", path, tmp_path))
    _assert_one_line_error(rc, err, path, "permission denied")


def test_unwritable_output_folder(tmp_path, capsys, monkeypatch, good_files):
    folder = tmp_path / "locked"
    folder.mkdir()
    if IS_ROOT:  # root writes everywhere: make the folder look read-only to the checks
        real_access = os.access
        monkeypatch.setattr(
            os,
            "access",
            lambda p, mode, **kw: False if os.path.abspath(p) == str(folder) else real_access(p, mode, **kw),
        )
    else:
        os.chmod(folder, 0o500)
    out = str(folder / "out.obj")
    for cmd in ("orient", "remove-interior", "layers"):
        rc, _, err = _cli(capsys, _argv(cmd, good_files["obj"], tmp_path, out=out))
        _assert_one_line_error(rc, err, folder, "not writable")
    assert os.listdir(folder) == []


def test_output_folder_missing(tmp_path, capsys, good_files):
    out = str(tmp_path / "nope" / "out.obj")
    rc, _, err = _cli(capsys, _argv("orient", good_files["obj"], tmp_path, out=out))
    _assert_one_line_error(rc, err, "nope", "does not exist")


def test_output_path_is_the_input(tmp_path, capsys, good_files):
    path = _write(tmp_path / "model.obj", open(good_files["obj"], "rb").read())
    before = open(path, "rb").read()
    link = tmp_path / "link.obj"
    link.symlink_to(path)
    spellings = [path, os.path.join(str(tmp_path), ".", "model.obj"), str(link)]
    for out in spellings:
        for force in ([], ["--force"]):
            rc, _, err = _cli(capsys, _argv("remove-interior", path, tmp_path, out=out) + force)
            _assert_one_line_error(rc, err, os.path.basename(out), "input")
    # --removed and --report may not hit the input either
    rc, _, err = _cli(
        capsys, _argv("remove-interior", path, tmp_path, out=str(tmp_path / "o.obj")) + ["--removed", path]
    )
    _assert_one_line_error(rc, err, path, "input")
    assert open(path, "rb").read() == before


def test_existing_output_needs_force(tmp_path, capsys, good_files):
    out = _write(tmp_path / "out.obj", "old")
    rc, _, err = _cli(capsys, _argv("orient", good_files["obj"], tmp_path, out=out))
    _assert_one_line_error(rc, err, out, "--force")
    assert open(out).read() == "old"


class _FullDisk:
    """A file object whose writes fail with ENOSPC, as on a full disk."""

    def __init__(self, fh):
        self._fh = fh

    def write(self, data):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    def __getattr__(self, name):
        return getattr(self._fh, name)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._fh.close()


@pytest.mark.parametrize("ext", ["obj", "ply", "stl", "off", "glb"])
def test_disk_full_keeps_the_old_file(tmp_path, capsys, monkeypatch, good_files, ext):
    out = _write(tmp_path / f"out.{ext}", "old content")
    real_fdopen = os.fdopen
    monkeypatch.setattr(os, "fdopen", lambda *a, **kw: _FullDisk(real_fdopen(*a, **kw)))
    rc, _, err = _cli(capsys, _argv("orient", good_files["obj"], tmp_path, out=out) + ["--force"])
    _assert_one_line_error(rc, err, out, "no space left")
    assert open(out).read() == "old content"
    assert sorted(os.listdir(tmp_path)) == [f"out.{ext}"]  # no temporary file left


def test_disk_full_on_the_report(tmp_path, capsys, monkeypatch, good_files):
    """The model is staged; the report then fails: clean error, and neither the model nor a
    temporary file is left (a command's outputs appear together or not at all)."""
    real_fdopen = os.fdopen

    def fdopen(fd, mode="r", *a, **kw):
        fh = real_fdopen(fd, mode, *a, **kw)
        return _FullDisk(fh) if "b" not in mode else fh  # the report is text, the PLY binary

    monkeypatch.setattr(os, "fdopen", fdopen)
    report = str(tmp_path / "report.json")
    rc, _, err = _cli(
        capsys,
        _argv("orient", good_files["ply"], tmp_path, out=str(tmp_path / "out.ply")) + ["--report", report],
    )
    _assert_one_line_error(rc, err, report, "no space left")
    assert sorted(os.listdir(tmp_path)) == []


# ------------------------------------------------------------------ the real stderr
def _run_cli(*args: str, cwd: str) -> subprocess.CompletedProcess:
    # the installed package, as a user has it (the repository's meshvis/ folder lacks
    # meshvis.cli and meshvis.labeling, which install from cli/ and labeling/)
    return subprocess.run(
        [sys.executable, "-m", "meshvis", *args],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=120,
    )


@pytest.mark.slow
def test_real_stderr_has_one_line_and_no_traceback(tmp_path):
    _write(tmp_path / "noise.ply", np.random.default_rng(0).integers(0, 256, 999, dtype=np.uint8).tobytes())
    _write(tmp_path / "short.obj", _text_model("obj", ["0 0 0", "1 0 0", "0 1 0"], [[0, 1]]))
    p = _run_cli("remove-interior", "noise.ply", "-o", "out.ply", cwd=str(tmp_path))
    assert p.returncode == 2
    assert p.stderr.count("\n") == 1 and p.stderr.startswith("meshvis: error: noise.ply: ")
    p = _run_cli("orient", "short.obj", "-o", "out.obj", cwd=str(tmp_path))
    assert p.returncode == 2
    lines = p.stderr.splitlines()
    assert lines == [lines[0], lines[1]] and lines[0].startswith("meshvis: warning: short.obj: ")
    assert lines[1].startswith("meshvis: error: short.obj: ")
    assert "Traceback" not in p.stderr
    assert not (tmp_path / "out.ply").exists() and not (tmp_path / "out.obj").exists()


def test_io_error_while_reading(tmp_path, capsys, monkeypatch, good_files):
    """An OSError from the system (here: EIO while reading the file's first bytes) is one line too."""

    def broken(*args, **kwargs):
        raise OSError(errno.EIO, os.strerror(errno.EIO), good_files["obj"])

    monkeypatch.setattr(mio.reading, "sniff", broken)
    rc, _, err = _cli(capsys, _argv("orient", good_files["obj"], tmp_path))
    _assert_one_line_error(rc, err, good_files["obj"], "input/output error")
