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


@pytest.mark.parametrize("scale, shift", [(1e-6, 0.0), (1e6, 0.0), (1.0, 1e6), (3.7, -2.5e3)])
def test_the_wall_holds_at_any_scale_and_place(levels, scale, shift):
    soup, idx = levels.split_space()
    moved = type(soup)(soup.vertices * scale + shift, soup.faces)
    lo, hi = np.zeros(3) * scale + shift, np.array([4.0, 2.0, 2.0]) * scale + shift
    box = "box:" + ",".join(f"{x:.17g}" for x in np.concatenate([lo, hi]))
    result = pvs(moved, "grid:2,1,1", view_space=box, budget=600_000, target_error=0)
    left, right = set(result.faces(0)), set(result.faces(1))
    assert set(idx["left"]) <= left and not set(idx["left"]) & right
    assert set(idx["right"]) <= right and not set(idx["right"]) & left
    assert np.isfinite(result.summary["estimate"]["per_million"])


def test_one_triangle_and_no_faces():
    from meshvis.errors import ModelError, ParameterError
    from meshvis.soup import Soup

    one = Soup(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    with pytest.raises(ParameterError, match="no volume"):
        pvs(one, "grid:1,1,1")
    result = pvs(one, "grid:2,2,2", view_space="box:-1,-1,-1,2,2,2", budget=100_000, target_error=0)
    assert result.sizes().tolist() == [1] * 8
    with pytest.raises(ModelError, match="no faces"):
        pvs(Soup(np.zeros((0, 3)), np.zeros((0, 3), np.int64)), "grid:1,1,1", view_space="box:0,0,0,1,1,1")


def test_every_distribution_is_drawn_and_counted(levels):
    soup, _ = levels.two_rooms()
    result = pvs(soup, "grid:2,1,1", view_space=levels.VIEW_SPACE, budget=2_500_000, target_error=0)
    stats = result.summary["strategies"]
    assert set(stats) == {
        "uniform",
        "object",
        "two-point",
        "mutation",
        "silhouette",
        "border",
        "adjacent",
        "wall",
    }
    assert all(s["rays"] > 0 for s in stats.values()), stats
    assert sum(s["contribution"] for s in stats.values()) == int(result.sizes().sum())
    assert sum(s["rays"] for s in stats.values()) == result.summary["rays"]["total"]
