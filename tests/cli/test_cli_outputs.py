"""Outputs of the repair commands: --removed when nothing is removed."""

import json

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
