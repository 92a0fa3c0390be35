"""The view space: the box above the ground of a scene standing on one."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from meshvis.errors import ParameterError
from meshvis.soup import Soup
from meshvis.viewcells.viewspace import ViewSpace, check_view_space, default_view_space


def _floor_on_a_pillar() -> Soup:
    """A floor at z = 1 over 0..4 x 0..4 facing up, a pillar under it (z 0..1) and a block on it."""
    floor = [[(0, 0, 1), (4, 0, 1), (4, 4, 1)], [(0, 0, 1), (4, 4, 1), (0, 4, 1)]]
    pillar = trimesh.creation.box(bounds=[[1, 1, 0], [2, 2, 1]])
    block = trimesh.creation.box(bounds=[[1, 1, 1], [2, 2, 2]])
    tri = np.concatenate([np.asarray(floor, float), pillar.triangles, block.triangles])
    return Soup(tri.reshape(-1, 3), np.arange(3 * len(tri)).reshape(-1, 3))


def test_a_scene_on_a_floor_has_its_view_space_above_it():
    vs = default_view_space(_floor_on_a_pillar())
    assert vs.ground is not None and vs.kind == "auto"
    assert vs.contains(np.array([[3.5, 3.5, 0.5], [3.5, 3.5, 1.5], [1.5, 1.5, 0.5]])).tolist() == [
        False,
        True,
        True,
    ]
    # under the floor only the pillar's columns are left: 16 x 1 above it and 1 x 1 x 2 down the pillar
    assert vs.volume_share(vs.lo[None], vs.hi[None])[0] == pytest.approx(17 / 32)
    pts = vs.sample(2000, np.random.default_rng(0))
    assert vs.contains(pts).all()
    assert (pts[:, 2] < 1).mean() == pytest.approx(1 / 17, abs=0.02)


def test_a_closed_box_stands_on_no_ground():
    vs = default_view_space(trimesh.creation.box())
    assert vs.ground is None
    assert vs.contains(np.array([[0.0, 0.0, -0.49]])).tolist() == [True]


def test_view_space_texts():
    soup = _floor_on_a_pillar()
    assert default_view_space(soup, "box").ground is None
    vs = default_view_space(soup, "box:0,0,0,1,2,3")
    assert vs.lo.tolist() == [0, 0, 0] and vs.hi.tolist() == [1, 2, 3] and vs.kind == "region"
    for bad in ("sphere", "box:0,0,0,1,1", "box:0,0,0,0,1,1", "outside"):
        with pytest.raises(ParameterError):
            check_view_space(bad)


def test_a_flat_model_has_no_volume_to_stand_in():
    flat = Soup(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    with pytest.raises(ParameterError, match="no volume"):
        default_view_space(flat)
    assert default_view_space(flat, "box:-1,-1,-1,1,1,1").diagonal == pytest.approx(2 * np.sqrt(3))


def test_the_ground_follows_the_up_axis():
    soup = _floor_on_a_pillar()
    turned = Soup(soup.vertices[:, [1, 2, 0]], soup.faces, up=(0.0, 1.0, 0.0))
    vs = default_view_space(turned)
    assert vs.up_axis == 1 and vs.ground is not None
    assert vs.contains(np.array([[3.5, 0.5, 3.5], [3.5, 1.5, 3.5]])).tolist() == [False, True]


def test_view_space_arrays_round_trip():
    vs = default_view_space(_floor_on_a_pillar())
    back = ViewSpace.from_arrays(vs.arrays())
    assert np.array_equal(back.ground, vs.ground) and back.up_axis == vs.up_axis and back.kind == vs.kind
