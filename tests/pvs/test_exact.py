"""PVS with answers known by construction: a door between two rooms, a wall across the space, a seed."""

from __future__ import annotations

import numpy as np
import pytest

from meshvis.viewcells import pvs
from meshvis.viewcells.cells import ViewCells
from meshvis.viewcells.viewspace import default_view_space

pytestmark = pytest.mark.slow


def _rooms(levels, seed=0, budget=1_500_000):
    soup, idx = levels.two_rooms()
    vs = default_view_space(soup, levels.VIEW_SPACE)
    cells = ViewCells.from_boxes(vs, levels.CELLS)
    return soup, idx, pvs(soup, cells, view_space=vs, budget=budget, target_error=0, seed=seed)


def test_a_room_sees_the_other_only_through_the_door(levels):
    soup, idx, result = _rooms(levels)
    a, b = set(result.faces(0)), set(result.faces(1))
    # the box in the corner beside the door is seen from its own room, never from the other
    assert set(idx["hidden_in_b"]) & b and not set(idx["hidden_in_b"]) & a
    assert set(idx["hidden_in_a"]) & a and not set(idx["hidden_in_a"]) & b
    # the box in front of the door is seen from the other room, through the door
    assert set(idx["seen_in_b"]) & a and set(idx["seen_in_a"]) & b
    # the wall's far side is seen only from its own room
    assert not set(idx["wall_b"]) & a and not set(idx["wall_a"]) & b
    # every side of the boxes in its own room but the underside (seen from a 0.1 thin layer)
    assert {f for f in idx["seen_in_a"] if soup.normals[f][2] > -0.5} <= a


def test_the_wall_between_the_rooms_is_no_cell(levels):
    _, _, result = _rooms(levels, budget=300_000)
    assert result.cells.n_cells == 2
    assert result.report()["cells"]["leaves_without_view_space"] >= 1
    assert result.cells.locate(np.array([[2.2, 1.0, 1.0]])).tolist() == [-1]


def test_nothing_behind_a_wall_on_the_cells_boundary(levels):
    soup, idx = levels.split_space()
    result = pvs(soup, "grid:2,1,1", view_space="box:0,0,0,4,2,2", budget=600_000, target_error=0)
    left, right = set(result.faces(0)), set(result.faces(1))
    assert set(idx["left"]) <= left and not set(idx["left"]) & right
    assert set(idx["right"]) <= right and not set(idx["right"]) & left
    assert set(idx["sheet"]) <= left and set(idx["sheet"]) <= right
    assert result.parts(0) == ["sheet", "left"] and result.parts(1) == ["sheet", "right"]


def test_same_seed_same_pvs_other_seed_other_samples(levels):
    soup, _ = levels.split_space()

    def run(seed):
        return pvs(
            soup, "grid:2,2,1", view_space="box:0,0,0,4,2,2", budget=400_000, target_error=0, seed=seed
        )

    one, two, other = run(3), run(3), run(4)
    assert np.array_equal(one.bits, two.bits)
    for a, b in zip(one.log, two.log):
        assert np.array_equal(a, b)
    assert one.summary["rays"] == two.summary["rays"]
    assert one.summary["history"]["estimate_per_million"] == two.summary["history"]["estimate_per_million"]
    assert not all(np.array_equal(a, b) for a, b in zip(one.log, other.log))
