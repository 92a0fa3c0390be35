"""Fast and early: arguments, regions and output formats are refused before any work, and
every output is written in the format its extension names.

The early checks are shown by order, not by time: the input of these commands does not
exist, so an error about anything else proves that it came before the model was read.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import meshvis
from meshvis.cli.main import main

ROOT = Path(__file__).resolve().parents[2]
MODELS = ROOT / "models"


def _error(capsys, argv: list[str]) -> str:
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("meshvis: error: "), err
    assert "file not found" not in err  # refused before the input was read
    return err


@pytest.mark.parametrize(
    "argv, words",
    [
        (["remove-interior", "missing.obj", "-o", "{tmp}/k.obj", "--from", "box:1,2"], "expected 6"),
        (["remove-interior", "missing.obj", "-o", "{tmp}/k.obj", "--from", "nowhere"], "unknown region"),
        (["orient", "missing.obj", "-o", "{tmp}/o.obj", "--from", "points:1,2"], "expected 3"),
        (["visible", "missing.obj", "--from", "upper-hemisphere:0,0,0"], "non-zero"),
        (["remove-interior", "missing.obj", "-o", "{tmp}/k.xyz"], "cannot write '.xyz'"),
        (["orient", "missing.obj", "-o", "{tmp}/o.3mf"], "cannot write '.3mf'"),
        (["remove-interior", "missing.obj", "-o", "{tmp}/k.obj", "--removed", "{tmp}/r.dae"], "'.dae'"),
        (["orient", "missing.obj", "-o", "{tmp}/o.obj", "--preview", "{tmp}/p.bmp"], "'.bmp' pictures"),
        (["layers", "missing.obj", "-o", "{tmp}/l.stl"], "STL files cannot hold layers"),
        (["layers", "missing.obj", "-o", "{tmp}/l.off"], "OFF files cannot hold layers"),
        (["render", "missing.obj", "-o", "{tmp}/x.gif"], "'.gif' pictures"),
        (["visible", "missing.obj", "--preview", "{tmp}/p.tiff"], "'.tiff' pictures"),
    ],
)
def test_refused_before_the_model_is_read(capsys, tmp_path, argv, words):
    err = _error(capsys, [a.replace("{tmp}", str(tmp_path)) for a in argv])
    assert words in err
    assert os.listdir(tmp_path) == []


def test_batch_checks_its_region_before_any_file(capsys, tmp_path):
    err = _error(
        capsys,
        [
            "batch",
            "missing.obj",
            "--op",
            "remove-interior",
            "--out",
            str(tmp_path / "out"),
            "--from",
            "box:0",
        ],
    )
    assert "expected 6" in err and not (tmp_path / "out").exists()


def test_layers_to_a_format_without_groups_writes_nothing(capsys, tmp_path):
    """An STL output of ``layers`` was a byte-identical copy of the input; now it is refused."""
    src = str(MODELS / "nested_shells.obj")
    err = _error(capsys, ["layers", src, "-o", str(tmp_path / "l.stl")])
    assert ".ply" in err and ".glb" in err  # says what to write instead
    assert os.listdir(tmp_path) == []
    assert main(["layers", src, "-o", str(tmp_path / "l.ply"), "-q"]) == 0
    back = meshvis.load(str(tmp_path / "l.ply"))
    assert back.n_faces == meshvis.load(src).n_faces


@pytest.mark.parametrize(
    "ext, magic", [(".png", b"\x89PNG"), (".jpg", b"\xff\xd8\xff"), (".JPEG", b"\xff\xd8\xff")]
)
def test_render_writes_the_format_its_extension_names(tmp_path, ext, magic):
    out = tmp_path / f"view{ext}"
    assert main(["render", str(MODELS / "cup.obj"), "-o", str(out), "--size", "32", "24", "-q"]) == 0
    assert out.read_bytes()[: len(magic)] == magic
    from PIL import Image

    assert Image.open(out).size == (32, 24)


@pytest.mark.slow
def test_render_color_by_layer_shows_every_layer(tmp_path):
    from PIL import Image

    from meshvis.rays.camera import Camera
    from meshvis.rays.render import render, render_layers

    src = str(MODELS / "nested_shells.obj")
    out = tmp_path / "layers.png"
    assert main(["render", src, "-o", str(out), "--color-by", "layer", "--size", "64", "64", "-q"]) == 0
    got = np.asarray(Image.open(out))
    soup = meshvis.load(src)
    peeled = meshvis.layers(soup, seed=0)
    assert peeled.n_layers == 3
    want = render_layers(soup, peeled.layer, Camera.fit(soup), size=(64, 64))
    np.testing.assert_array_equal(got, want)
    # the inner layers show through the outer one: the centre is not the outer layer's alone
    outer = render(soup, Camera.fit(soup), size=(64, 64), color_by="layer", face_values=peeled.layer).image
    assert (np.abs(got[24:40, 24:40].astype(int) - outer[24:40, 24:40]).sum(axis=2) > 30).mean() > 0.9


def test_the_version_imports_no_heavy_module():
    """``meshvis --version`` builds no command's parser and imports no kernel."""
    code = (
        "import sys; from meshvis.cli.main import main; main(['--version']) if 0 else None; "
        "from meshvis.cli.main import build_parser; build_parser('--version'); "
        "print(' '.join(sorted({m.split('.')[0] for m in sys.modules} & "
        "{'numba', 'scipy', 'trimesh', 'embreex', 'matplotlib', 'PIL', 'rich', 'igl'})))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == ""


def test_numba_caches_live_in_the_user_cache_folder(tmp_path):
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    env["XDG_CACHE_HOME"] = str(tmp_path)
    code = "import meshvis, numba; print(numba.config.CACHE_DIR)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.strip() == str(tmp_path / "meshvis" / "numba")
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "mine")  # the user's own choice is kept
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.strip() == str(tmp_path / "mine")


def test_runs_from_the_repository_root_without_installing(tmp_path):
    """``python -m meshvis`` and ``import meshvis.labeling`` in a checkout that is not installed."""
    import site
    import sysconfig

    # the dependencies' folders, without the .pth files that install this checkout
    folders = {sysconfig.get_paths()["purelib"], *site.getsitepackages()}
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sorted(folders))}
    code = "import meshvis.labeling, meshvis.cli.main; print(meshvis.cli.main.__file__)"
    run = subprocess.run(
        [sys.executable, "-S", "-c", code], cwd=ROOT, capture_output=True, text=True, env=env
    )
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == str(ROOT / "cli" / "main.py")
    run = subprocess.run(
        [sys.executable, "-S", "-m", "meshvis", "--version"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        env=env,
    )
    assert run.returncode == 0 and run.stdout.startswith("meshvis "), run.stderr
