"""A scene standing on a ground is seen from above its ground only.

``orient``'s visible-sides step counts a ray that leaves such a scene downward as stopped
by the ground (:class:`meshvis.repair.evidence.RayStream`), where
:func:`meshvis.repair.evidence.stands_on_ground` detects the ground; the monastery, whose
courtyard floors open onto the empty space below the scene, is checked from above in
``test_orient_twice.py`` (``shared_models``).
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from meshvis.cli.main import main
from meshvis.io import load, save
from meshvis.rays.caster import RayCaster
from meshvis.repair.evidence import stands_on_ground
from meshvis.repair.orient import orient
from meshvis.soup import Soup

UP = np.array([0.0, 0.0, 1.0])


def _scene() -> Soup:
    """A 10 x 10 ground sheet wound facing down, and a closed box standing on it (z up)."""
    ground = np.array([[-5, -5, 0], [5, -5, 0], [5, 5, 0], [-5, 5, 0]], float)
    box = trimesh.creation.box(extents=(2, 2, 2))
    vertices = np.vstack([ground, np.asarray(box.vertices) + [0, 0, 1]])
    faces = np.vstack([[[0, 2, 1], [0, 3, 2]], np.asarray(box.faces) + 4])
    return Soup(vertices, faces)


def test_a_ground_sheet_wound_down_faces_up():
    """Seen from everywhere, the sheet's two sides are seen about as often and it keeps its
    winding; seen from above its ground only, it faces up."""
    soup = _scene()
    assert (soup.normals[:2] @ UP < 0).all()
    r = orient(soup, seed=0, ground=None)
    assert r.visibility["ground"] and r.flipped[:2].all()
    assert (r.soup.normals[:2] @ UP > 0).all()
    kept = orient(soup, seed=0)  # the default: seen from every direction
    assert not kept.visibility["ground"] and not kept.flipped[:2].any()


def test_the_ground_is_the_model_up_axis_ground():
    """The same scene with x as its up axis stands on no ground (seen along x, it is a wall)."""
    soup = _scene()
    assert not orient(soup, seed=0, up="x", ground=None).visibility["ground"]


@pytest.mark.parametrize("turned", [False, True])
def test_stands_on_ground_does_not_depend_on_the_winding(turned):
    soup = _scene()
    soup = soup.flipped(np.full(soup.n_faces, turned))
    assert stands_on_ground(soup, RayCaster(soup), UP)


def test_a_ball_and_a_car_like_object_stand_on_no_ground():
    """An object resting on a few points is not a scene standing on a ground."""
    ball = trimesh.creation.icosphere(2)
    soup = Soup(np.asarray(ball.vertices), np.asarray(ball.faces))
    assert not stands_on_ground(soup, RayCaster(soup), UP)
    body = trimesh.creation.box(extents=(4, 2, 1))
    wheels = [trimesh.creation.cylinder(0.4, 0.3, sections=12) for _ in range(4)]
    parts = [body.apply_translation((0, 0, 1.2))] + [
        w.apply_transform(trimesh.transformations.rotation_matrix(np.pi / 2, (1, 0, 0))).apply_translation(
            (x, y, 0.4)
        )
        for w, (x, y) in zip(wheels, [(-1.5, -1), (-1.5, 1), (1.5, -1), (1.5, 1)])
    ]
    car = trimesh.util.concatenate(parts)
    soup = Soup(np.asarray(car.vertices), np.asarray(car.faces))
    assert not stands_on_ground(soup, RayCaster(soup), UP)


def test_orient_on_a_ground_twice_is_once_and_the_cli_agrees(tmp_path):
    soup = _scene()
    once = orient(soup, seed=0, ground=None)
    assert once.visibility["ground"]
    assert not orient(once.soup, seed=0, ground=None).flipped.any()
    path, out = tmp_path / "scene.stl", tmp_path / "oriented.stl"  # STL: z up
    save(soup, str(path))
    assert main(["orient", str(path), "-o", str(out), "--ground", "auto", "--quiet"]) == 0
    np.testing.assert_allclose(load(str(out)).normals, once.soup.normals, atol=1e-6)


@pytest.mark.parametrize("scale, shift", [(1e-6, 0.0), (1e6, 0.0), (1.0, 1e6)])
def test_the_ground_is_found_at_any_scale_and_far_away(scale, shift):
    soup = _scene()
    soup = Soup(soup.vertices * scale + shift, soup.faces)
    assert stands_on_ground(soup, RayCaster(soup), UP)
    assert orient(soup, seed=0, ground=None).flipped[:2].all()


def test_no_ground_under_nothing_or_a_wall():
    wall = Soup(np.array([[0.0, 0, 0], [1, 0, 0], [0, 0, 1]]), np.array([[0, 1, 2]]))
    assert not stands_on_ground(wall, RayCaster(wall), UP)
    empty = Soup(np.zeros((0, 3)), np.zeros((0, 3), np.int64))
    assert not stands_on_ground(empty, None, UP)  # type: ignore[arg-type]


def _courtyard(gap: float) -> Soup:
    """A ground (z up), three walls around a courtyard open on one side, fronts out, and a
    closed block ``gap`` away from the back wall's front (every face wound outward).

    The back wall (faces 4 and 5) is seen from both sides from above: through its back
    from the open courtyard, through its front down the slit to the block.  Its own rays
    see its back more than 4x as often; its patch (the three walls) shows their fronts.
    """

    def quad(a: int, b: int, c: int, d: int) -> list[list[int]]:
        return [[a, b, c], [a, c, d]]

    ground = [[-10, -10, 0], [10, -10, 0], [10, 10, 0], [-10, 10, 0]]
    corners = [[2, -2], [-2, -2], [-2, 2], [2, 2]]
    walls = [[x, y, 0] for x, y in corners] + [[x, y, 2] for x, y in corners]
    x0 = -2 - gap
    foot = [[x0 - 1, -2, 0], [x0, -2, 0], [x0, 2, 0], [x0 - 1, 2, 0]]
    block = foot + [[x, y, 4] for x, y, _ in foot]
    faces = quad(0, 1, 2, 3)
    faces += [f for i in range(3) for f in quad(4 + i, 8 + i, 9 + i, 5 + i)]
    b = [[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]]
    faces += [f for q in b for f in quad(*(12 + i for i in q))]
    return Soup(np.array(ground + walls + block, float), np.array(faces, np.int64))


@pytest.mark.parametrize("gap", [0.05, 0.1])
@pytest.mark.parametrize("ground", [True, None])
def test_a_wall_seen_from_both_sides_above_the_ground_keeps_its_patch(gap, ground):
    """Seen from above its ground, a face does not leave its patch for the side seen more
    often where viewers above see its patch's side: the back wall keeps the winding of
    the walls it belongs to.  It was turned before (at 0.05 by the cut, at 0.1 by the
    wall's own rays)."""
    soup = _courtyard(gap)
    back_wall = [4, 5]
    assert (soup.normals[back_wall] @ [-1.0, 0, 0] > 0.99).all()  # its front faces the block
    r = orient(soup, seed=0, ground=ground)
    assert r.visibility["ground"]
    assert not r.flipped.any(), np.flatnonzero(r.flipped)
    assert r.visibility["kept_seen_from_above"] == len(back_wall)
    assert not orient(r.soup, seed=0, ground=ground).flipped.any()


@pytest.mark.parametrize("ground, up", [(False, None), (None, "y")])
def test_seen_from_every_direction_the_wall_takes_the_side_seen_more(ground, up):
    """By default, or where the scene stands on no ground (along y), viewers all around
    see the back wall through the courtyard more than 4x as often: it is turned."""
    r = orient(_courtyard(0.1), seed=0, ground=ground, up=up)
    assert not r.visibility["ground"] and r.visibility["kept_seen_from_above"] == 0
    np.testing.assert_array_equal(np.flatnonzero(r.flipped), [4, 5])


def _car() -> Soup:
    """A box on four wheels (z up), a third of its faces turned over: it stands on no ground."""
    body = trimesh.creation.box(extents=(4, 2, 1)).apply_translation((0, 0, 1.2))
    turn = trimesh.transformations.rotation_matrix(np.pi / 2, (1, 0, 0))
    wheels = [
        trimesh.creation.cylinder(0.4, 0.3, sections=12).apply_transform(turn).apply_translation((x, y, 0.4))
        for x, y in [(-1.5, -1), (-1.5, 1), (1.5, -1), (1.5, 1)]
    ]
    car = trimesh.util.concatenate([body, *wheels])
    faces = np.asarray(car.faces).copy()
    faces[::3] = faces[::3, ::-1]
    return Soup(np.asarray(car.vertices), faces)


@pytest.mark.parametrize("model", ["car", "courtyard along y"])
def test_with_no_ground_found_auto_is_the_default(model):
    """Where no ground is found, ``ground=None`` (``--ground auto``) gives the faces of the
    default ``ground=False``, the model seen from every direction."""
    soup, up = (_car(), None) if model == "car" else (_courtyard(0.1), "y")
    auto, default = orient(soup, seed=0, up=up, ground=None), orient(soup, seed=0, up=up)
    assert not auto.visibility["ground"]
    assert auto.flipped.any()  # there is something to agree on
    np.testing.assert_array_equal(auto.flipped, default.flipped)
    np.testing.assert_array_equal(auto.soup.faces, default.soup.faces)
    np.testing.assert_array_equal(auto.status, default.status)


@pytest.mark.parametrize("scale, shift", [(1e-6, 0.0), (1e6, 0.0), (1.0, 1e6)])
def test_the_courtyard_wall_keeps_its_patch_at_any_scale_and_far_away(scale, shift):
    soup = _courtyard(0.1)
    soup = Soup(soup.vertices * scale + shift, soup.faces)
    r = orient(soup, seed=0, ground=None)
    assert r.visibility["kept_seen_from_above"] == 2 and not r.flipped.any()
