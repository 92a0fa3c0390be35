"""Outputs of the repair commands: --removed when nothing is removed."""

import json
import subprocess
import sys

import trimesh

from meshvis.cli.main import main
from meshvis.io import load, save


def test_removed_with_nothing_removed_writes_no_file_and_exits_0(tmp_path, capsys):
    sphere = trimesh.creation.icosphere(subdivisions=2)
    path = tmp_path / "ball.obj"
    save((sphere.vertices, sphere.faces), str(path))
    out, removed, rep = tmp_path / "k.obj", tmp_path / "r.obj", tmp_path / "k.json"
    code = main(
        ["remove-interior", str(path), "-o", str(out), "--removed", str(removed), "--report", str(rep)]
    )
    assert code == 0
    assert json.loads(rep.read_text())["removed_faces"] == 0
    assert load(str(out)).n_faces == len(sphere.faces)
    assert not removed.exists()
    assert f"nothing was removed: {removed} not written" in capsys.readouterr().out


def test_a_command_builds_only_its_own_parser(tmp_path):
    # the labeling and benchmark parsers import their libraries; `info` needs neither
    code = (
        "import sys, trimesh; from meshvis.cli.main import main, build_parser;"
        f"trimesh.creation.box().export({str(tmp_path / 'box.stl')!r});"
        f"status = main(['info', {str(tmp_path / 'box.stl')!r}]);"
        "print(status, 'meshvis.labeling' in sys.modules, 'meshvis.eval.bench.real_models' in sys.modules);"
        "names = build_parser()._subparsers._group_actions[0].choices; print(sorted(names) == sorted("
        "__import__('meshvis.cli.main', fromlist=['COMMANDS']).COMMANDS))"
    )
    # run outside the checkout: from its root, `-c` would import the source tree's meshvis,
    # which has no `cli` (it is installed from the top-level cli/ folder)
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert run.stdout.splitlines()[-2:] == ["0 False False", "True"]


def test_the_version_builds_no_command_parser(tmp_path):
    code = (
        "import sys; from meshvis.cli.main import main\n"
        "try:\n    main(['--version'])\nexcept SystemExit as e:\n    print(e.code)\n"
        "print('meshvis.labeling' in sys.modules, 'meshvis.cli.cmd_repair' in sys.modules)"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    assert run.stdout.splitlines()[0].startswith("meshvis ")
    assert run.stdout.splitlines()[-2:] == ["0", "False False"]
