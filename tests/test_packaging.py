"""The package installs as one namespace: the wheel's only top-level name is ``meshvis``,
and files named like its subpackages in the working folder do not shadow them."""

from __future__ import annotations

import os
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: files a user might have in the working folder, named like the installed subpackages
SHADOWS = {
    "cli.py": "raise SystemExit('the local cli.py was imported')",
    "labeling.py": "raise SystemExit(3)",
}


@pytest.fixture
def shadowed_folder(tmp_path):
    for name, text in SHADOWS.items():
        (tmp_path / name).write_text(text + "\n")
    return tmp_path


def test_imports_ignore_local_cli_py(shadowed_folder):
    code = "import meshvis, meshvis.labeling, meshvis.cli, meshvis.cli.main; print('ok')"
    run = subprocess.run([sys.executable, "-c", code], cwd=shadowed_folder, capture_output=True, text=True)
    assert run.returncode == 0 and run.stdout.strip() == "ok", run.stderr


@pytest.mark.parametrize("how", ["module", "script"])
def test_help_works_next_to_a_local_cli_py(shadowed_folder, how):
    script = Path(sysconfig.get_path("scripts")) / ("meshvis.exe" if os.name == "nt" else "meshvis")
    command = [sys.executable, "-m", "meshvis", "--help"] if how == "module" else [str(script), "--help"]
    if how == "script" and not script.exists():
        pytest.fail(f"the console script is not installed at {script}")
    run = subprocess.run(command, cwd=shadowed_folder, capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "usage: meshvis" in run.stdout and "orient" in run.stdout


def _source_modules() -> list[str]:
    """Every .py file of the package as the wheel names it (package-dir applied)."""
    found = []
    for folder, installed in (
        ("meshvis", "meshvis"),
        ("labeling", "meshvis/labeling"),
        ("cli", "meshvis/cli"),
    ):
        for path in (ROOT / folder).rglob("*.py"):
            found.append(f"{installed}/{path.relative_to(ROOT / folder).as_posix()}")
    return found


@pytest.mark.slow
def test_wheel_has_one_top_level_name(tmp_path):
    """Build the wheel (pip wheel, build isolation) and read what it would install."""
    run = subprocess.run(
        [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(tmp_path), str(ROOT)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stderr
    (wheel,) = tmp_path.glob("meshvis-*.whl")
    with zipfile.ZipFile(wheel) as z:
        names = z.namelist()
        (top_level,) = [n for n in names if n.endswith(".dist-info/top_level.txt")]
        assert z.read(top_level).decode().split() == ["meshvis"]
    assert {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")} == {"meshvis"}
    for needed in ("meshvis/py.typed", "meshvis/labeling/__init__.py", "meshvis/cli/main.py"):
        assert needed in names
    # every module of the source tree is in the wheel (a new subpackage needs its pyproject entry)
    assert {n for n in names if n.endswith(".py")} >= set(_source_modules())
    assert any(n.endswith(".dist-info/licenses/LICENSE") for n in names)
    # the page of `meshvis view` and the three.js it loads, with three.js's licence
    web = [
        p.relative_to(ROOT / "labeling").as_posix()
        for p in (ROOT / "labeling" / "web").rglob("*")
        if p.is_file()
    ]
    assert web and {f"meshvis/labeling/{p}" for p in web} <= set(names)
    assert "meshvis/labeling/web/vendor/three/LICENSE" in names
