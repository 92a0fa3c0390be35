"""``orient_from`` / ``orient --from REGION``: faces turn to the side that viewers in a region see."""

from __future__ import annotations

import json

import numpy as np
import trimesh

from meshvis.cli.main import main
from meshvis.io import load, save
from meshvis.repair.orient import orient_from

VIEWERS = "box:-0.5,-0.5,-0.5,0.5,0.5,0.5"


def _room_with_closet(seed: int = 0):
    """A closed 4 x 4 x 4 room and a closed closet in its corner, 40 % of the faces turned."""
    room = trimesh.creation.box(extents=(4, 4, 4))
    closet = trimesh.creation.box(extents=(0.8, 0.8, 0.8))
    closet.apply_translation((1.4, 1.4, -1.4))
    v = np.vstack([room.vertices, closet.vertices])
    f = np.vstack([room.faces, closet.faces + len(room.vertices)])
    turn = np.random.default_rng(seed).random(len(f)) < 0.4
    f[turn] = f[turn][:, ::-1]
    return v, f, len(room.faces)


def _facing(v, f, center) -> np.ndarray:
    """+1 where a face's normal points toward ``center``, -1 where it points away."""
    tri = v[f]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    return np.sign(np.einsum("ij,ij->i", n, center - tri.mean(axis=1)))


def test_every_wall_faces_the_viewers_and_the_closet_shows_its_outside():
    v, f, n_room = _room_with_closet()
    r = orient_from((v, f), VIEWERS, seed=0)
    out, status = r.soup.faces, np.asarray(r.status)
    assert (_facing(v, out[:n_room], np.zeros(3)) > 0).all()  # the room's walls face in
    # the closet's three sides toward the viewers face out; the three toward the walls are
    # seen by nobody (hidden) and keep their winding
    closet = np.arange(n_room, len(f))
    seen = status[closet] == 0
    assert seen.sum() == 6 and (status[closet][~seen] == 2).all()
    assert (_facing(v, out[closet[seen]], np.array([1.4, 1.4, -1.4])) < 0).all()
    assert not r.flipped[closet[~seen]].any()
    assert r.classification is None and r.view is not None


def test_viewers_outside_see_the_outside_of_the_room():
    v, f, n_room = _room_with_closet(seed=1)
    r = orient_from((v, f), "outside", seed=0)
    assert (_facing(v, r.soup.faces[:n_room], np.zeros(3)) < 0).all()  # the walls face out
    # nobody outside sees the closet: its faces are hidden and keep their winding
    assert not r.flipped[n_room:].any()
    assert (np.asarray(r.status)[n_room:] == 2).all()  # "hidden"


def test_same_seed_same_answer_and_cw_turns_the_other_way():
    v, f, _ = _room_with_closet(seed=2)
    a, b = orient_from((v, f), VIEWERS, seed=3), orient_from((v, f), VIEWERS, seed=3)
    assert np.array_equal(a.flipped, b.flipped)
    cw = orient_from((v, f), VIEWERS, seed=3, front="cw")
    seen = np.asarray(a.status) == 0  # one-sided: cw turns exactly the faces ccw keeps
    assert np.array_equal(cw.flipped[seen], ~a.flipped[seen]) and not cw.flipped[~seen].any()


def test_orient_from_on_the_command_line(tmp_path, capsys):
    v, f, n_room = _room_with_closet()
    src, out, rep = tmp_path / "room.obj", tmp_path / "out.obj", tmp_path / "r.json"
    save((v, f), src)
    assert main(["orient", str(src), "-o", str(out), "--from", VIEWERS, "--report", str(rep), "-q"]) == 0
    oriented = load(out)
    assert (_facing(oriented.vertices, oriented.faces[:n_room], np.zeros(3)) > 0).all()
    report = json.loads(rep.read_text())
    assert "view" in report and "classification" not in report
