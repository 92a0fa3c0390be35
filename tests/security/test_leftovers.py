"""Stops and failures at known points leave no partial output: SIGTERM and a full disk
during the OBJ/MTL/texture writes, a failing preview after the model, SIGTERM to a running
command (a batch: tests/batch/test_batch.py); plus the inputs that used to block or be refused (a FIFO, a
245-character output name) and ``--removed`` with nothing removed."""

from __future__ import annotations

import errno
import io
import os
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np
import pytest
import trimesh

import meshvis.io as mio
import meshvis.io.mtl as mtl_module
from meshvis.cli.main import main

#: child commands run from the temporary folder: the installed package, not a meshvis/ folder
#: in the working one
CWD = tempfile.gettempdir()


def _png() -> bytes:
    from PIL import Image

    buf = io.BytesIO()
    Image.new("RGB", (4, 4), (200, 10, 10)).save(buf, format="PNG")
    return buf.getvalue()


def _textured_sphere(folder) -> str:
    """An 80-face sphere with UVs and a material whose texture is tex.png."""
    os.makedirs(folder, exist_ok=True)
    s = trimesh.creation.icosphere(1)
    lines = ["mtllib m.mtl"] + [f"v {x!r} {y!r} {z!r}" for x, y, z in s.vertices.tolist()]
    lines += ["vt 0 0", "vt 1 0", "vt 0 1", "usemtl skin"]
    lines += [f"f {a + 1}/1 {b + 1}/2 {c + 1}/3" for a, b, c in s.faces.tolist()]
    (folder / "m.obj").write_text("\n".join(lines) + "\n")
    (folder / "m.mtl").write_text("newmtl skin\nKd 1 1 1\nmap_Kd tex.png\n")
    (folder / "tex.png").write_bytes(_png())
    return str(folder / "m.obj")


def _slow_ply(path, n: int = 3000) -> str:
    """Intersecting random triangles: seconds of rays at 2048 rays per node."""
    rng = np.random.default_rng(0)
    tris = rng.random((n, 1, 3)) + 0.08 * rng.normal(size=(n, 3, 3))
    mio.save((tris.reshape(-1, 3), np.arange(3 * n).reshape(-1, 3)), path)
    return str(path)


def _files(folder) -> list[str]:
    return sorted(os.path.relpath(os.path.join(r, f), folder) for r, _, fs in os.walk(folder) for f in fs)


# ---------------------------------------------------------------------------- single file, in process
def test_sigterm_while_the_mtl_is_written_leaves_nothing(tmp_path, capsys, monkeypatch):
    """SIGTERM arrives after the texture is copied and the OBJ is in its temporary file,
    just as the MTL starts: exit 143 and none of OBJ, MTL, texture or temporary files."""
    src = _textured_sphere(tmp_path / "in")
    out = tmp_path / "out"
    out.mkdir()
    real = mtl_module.atomic_write

    def stop_here(path, mode="w", **kw):
        assert [f for f in os.listdir(out) if f.endswith(".tmp")]  # the OBJ is being written
        assert "tex.png" in os.listdir(out)  # the texture is already there
        os.kill(os.getpid(), signal.SIGTERM)
        return real(path, mode, **kw)

    monkeypatch.setattr(mtl_module, "atomic_write", stop_here)
    rc = main(["orient", src, "-o", str(out / "fixed.obj"), "--report", str(out / "r.json"), "-q"])
    assert rc == 143
    assert capsys.readouterr().err == "meshvis: terminated\n"
    assert os.listdir(out) == []
    assert signal.getsignal(signal.SIGTERM) is signal.SIG_DFL  # the handler is put back


@pytest.mark.parametrize("fail_at", ["obj", "mtl"])
def test_full_disk_during_the_obj_or_mtl_leaves_no_texture(tmp_path, capsys, monkeypatch, fail_at):
    src = _textured_sphere(tmp_path / "in")
    out = tmp_path / "out"
    out.mkdir()
    real_fdopen = os.fdopen

    class Full:
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

    calls = []

    def fdopen(fd, mode="r", *a, **kw):
        fh = real_fdopen(fd, mode, *a, **kw)
        if "b" in mode:  # textures are binary
            return fh
        calls.append(mode)
        return Full(fh) if len(calls) == (1 if fail_at == "obj" else 2) else fh

    monkeypatch.setattr(os, "fdopen", fdopen)
    rc = main(["orient", src, "-o", str(out / "fixed.obj"), "-q"])
    err = capsys.readouterr().err
    assert rc == 2 and "no space left" in err.lower() and err.count("\n") == 1
    assert os.listdir(out) == []


def test_a_failing_preview_after_the_model_leaves_nothing(tmp_path, capsys, monkeypatch):
    """Decision (docs/security.md): a non-zero exit means no output of the command exists."""
    import meshvis.rays.render as render_module

    src = _textured_sphere(tmp_path / "in")
    out = tmp_path / "out"
    out.mkdir()
    (out / "fixed.obj").write_text("old")

    def full(image, path):
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), path)

    monkeypatch.setattr(render_module, "save_image", full)
    argv = ["remove-interior", src, "-o", str(out / "fixed.obj"), "--preview", str(out / "p.png")]
    rc = main(argv + ["--report", str(out / "r.json"), "--force", "-q"])
    assert rc == 2 and "p.png" in capsys.readouterr().err
    assert _files(out) == ["fixed.obj"] and (out / "fixed.obj").read_text() == "old"


# ---------------------------------------------------------------------------- single file, real signal
def test_sigterm_to_a_running_command(tmp_path):
    """SIGTERM once the model is loaded (its first line printed), during the classification."""
    src = _slow_ply(tmp_path / "slow.ply")
    out = tmp_path / "out"
    out.mkdir()
    argv = [
        "orient",
        src,
        "-o",
        str(out / "o.obj"),
        "--report",
        str(out / "r.json"),
        "--rays-per-node",
        "1024",  # within the ray cap of the 267 KB file (RAYS_PER_INPUT_BYTE)
        "--verbose",  # prints the model's size once it is loaded
    ]
    proc = subprocess.Popen(
        [sys.executable, "-m", "meshvis", *argv, "--no-progressive"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ, PYTHONUNBUFFERED="1"),  # the first line arrives when printed
        cwd=CWD,
    )
    try:
        first = proc.stdout.readline()
        assert "3000 faces" in first
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
    assert proc.returncode == 143, err
    assert err == "meshvis: terminated\n"
    assert os.listdir(out) == []


# ---------------------------------------------------------------------------- odd paths
def test_a_fifo_named_like_a_model_is_refused_not_waited_for(tmp_path, capsys):
    fifo = tmp_path / "x.obj"
    os.mkfifo(fifo)
    t0 = time.monotonic()
    assert main(["info", str(fifo)]) == 2
    err = capsys.readouterr().err
    assert err == f"meshvis: error: {fifo}: is not a regular file (a FIFO, socket or device)\n"
    r = subprocess.run(
        [
            sys.executable,
            "-m",
            "meshvis",
            "batch",
            str(tmp_path),
            "--op",
            "orient",
            "--out",
            str(tmp_path / "o"),
        ],
        capture_output=True,
        text=True,
        cwd=CWD,
        timeout=120,
    )
    assert r.returncode == 1 and "is not a regular file" in r.stdout
    assert time.monotonic() - t0 < 120


def test_a_245_character_output_name_works(tmp_path, capsys):
    src = _textured_sphere(tmp_path / "in")
    name = "n" * 241 + ".obj"
    assert len(name) == 245
    out = tmp_path / "out"
    out.mkdir()
    assert main(["orient", src, "-o", str(out / name), "-q"]) == 0, capsys.readouterr().err
    assert sorted(os.listdir(out)) == sorted([name, "n" * 241 + ".mtl", "tex.png"])
    assert mio.load(out / name).n_faces == 80


def test_removed_with_nothing_removed(tmp_path, capsys):
    src = tmp_path / "ball.obj"
    mio.save(trimesh.creation.icosphere(1), src)
    out, removed = tmp_path / "kept.obj", tmp_path / "removed.obj"
    assert main(["remove-interior", str(src), "-o", str(out), "--removed", str(removed)]) == 0
    assert f"nothing was removed: {removed} not written" in capsys.readouterr().out
    assert sorted(os.listdir(tmp_path)) == ["ball.obj", "kept.obj"]
    removed.write_text("an older result")
    argv = ["remove-interior", str(src), "-o", str(out), "--removed", str(removed), "--force", "-q"]
    assert main(argv) == 0
    assert sorted(os.listdir(tmp_path)) == ["ball.obj", "kept.obj"]  # not left to pass for this run's


def test_removed_faces_are_written_when_there_are_some(tmp_path, capsys):
    a, b = trimesh.creation.icosphere(1), trimesh.creation.icosphere(1)
    v = np.vstack([a.vertices, 0.5 * b.vertices])
    f = np.vstack([a.faces, b.faces + len(a.vertices)])
    src = tmp_path / "nested.obj"
    mio.save((v, f), src)
    argv = ["remove-interior", str(src), "-o", str(tmp_path / "k.obj"), "--removed", str(tmp_path / "r.obj")]
    assert main(argv) == 0
    said = capsys.readouterr().out
    assert (
        "removed 80 of 160 faces" in said and f"wrote {tmp_path / 'k.obj'} and {tmp_path / 'r.obj'}" in said
    )
    assert mio.load(tmp_path / "r.obj").n_faces == 80 and mio.load(tmp_path / "k.obj").n_faces == 80
