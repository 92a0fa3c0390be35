"""The PVS file, the judge, the pixel-error estimate and the mixture."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from meshvis.errors import ModelError
from meshvis.viewcells import PVS, pvs
from meshvis.viewcells.estimate import ErrorEstimate, rays_needed
from meshvis.viewcells.judge import pixel_errors, render_views, summary
from meshvis.viewcells.mixture import FLOOR, UNIFORM_FLOOR, Mixture
from meshvis.viewcells.strategies import MutationBuffer


@pytest.fixture(scope="module")
def split(levels):
    """The split space's PVS on 2 x 2 cells, computed once for the module."""
    soup, idx = levels.split_space()
    return soup, idx, pvs(soup, "grid:2,2,1", view_space="box:0,0,0,4,2,2", budget=300_000, target_error=0)


def test_a_pvs_file_reads_back_the_same_sets(split, tmp_path):
    soup, _, result = split
    path = tmp_path / "level.pvs.npz"
    result.save(path)
    back = PVS.load(path, soup)
    assert np.array_equal(back.bits, result.bits)
    assert np.array_equal(back.sides, result.sides)
    assert back.cells.kind == "grid:2,2,1" and back.cells.n_cells == 4
    assert [back.parts(c) for c in range(4)] == [result.parts(c) for c in range(4)]
    # without the model the parts come from the file
    alone = PVS.load(path)
    assert alone.part_id is None and alone.parts(0) == result.parts(0)
    assert alone.summary["rays"] == result.summary["rays"]


def test_a_pvs_file_of_another_model_or_no_pvs_file_is_refused(split, tmp_path):
    soup, _, result = split
    path = tmp_path / "level.pvs.npz"
    result.save(path)
    with pytest.raises(ModelError, match="another model"):
        PVS.load(path, trimesh.creation.box())
    moved = type(soup)(soup.vertices + 1.0, soup.faces)
    with pytest.raises(ModelError, match="another model"):
        PVS.load(path, moved)
    junk = tmp_path / "junk.npz"
    junk.write_bytes(b"not a zip")
    with pytest.raises(ModelError, match="not a PVS file"):
        PVS.load(junk)
    other = tmp_path / "other.npz"
    np.savez(other, a=np.zeros(3))
    with pytest.raises(ModelError, match="not a PVS file"):
        PVS.load(other)


def test_the_history_rebuilds_every_earlier_pvs(split):
    _, _, result = split
    last = len(result.batches["rays"]) - 1
    assert np.array_equal(result.bits_at(last), result.bits)
    sizes = [int(np.unpackbits(result.bits_at(b).view(np.uint8)).sum()) for b in range(last + 1)]
    assert sizes == sorted(sizes) and sizes[0] > 0
    assert result.summary["history"]["rays"][-1] == result.summary["rays"]["total"]


def test_the_judge_counts_pixels_whose_face_is_not_in_the_cells_pvs(split):
    soup, idx, result = split
    table = render_views(soup, result.cells.view_space, points=16, path=4, size=24, seed=0)
    assert table.n_views == 16 * 6 + 4
    full = np.full_like(result.bits, np.iinfo(np.uint64).max)
    assert pixel_errors(table, result.cells, full).max() == 0
    empty = np.zeros_like(result.bits)
    shown = np.bincount(table.view, weights=table.pixels, minlength=table.n_views)
    assert np.allclose(pixel_errors(table, result.cells, empty), shown / 24**2 * 1e6)
    s = summary(pixel_errors(table, result.cells, result.bits), table)
    assert s["views"] == table.n_views and 0 <= s["mean"] <= s["worst"]


def test_the_estimate_takes_the_rays_eq5_asks_for():
    est = ErrorEstimate()
    est.add(1000, 500)
    assert est.per_million == pytest.approx(5e5) and est.enough
    assert rays_needed(1e-5) == pytest.approx((1 - 1e-5) / (0.25 * 1e-5 * 0.1))
    slow = ErrorEstimate()
    for _ in range(10):
        slow.add(1_000_000, 2)
    # two per million needs 20 M rays: all ten batches, and still not enough
    assert slow.window == 10_000_000 and not slow.enough and slow.per_million == pytest.approx(2.0)


def test_the_mixture_follows_contribution_per_ray_with_floors():
    mix = Mixture(("uniform", "two-point", "border"))
    avail = {"uniform": True, "two-point": True, "border": True}
    assert mix.probabilities(avail) == pytest.approx({"uniform": 1 / 3, "two-point": 1 / 3, "border": 1 / 3})
    mix.update("uniform", 0, 1000)
    mix.update("two-point", 10, 1000)
    mix.update("border", 990, 1000)
    p = mix.probabilities(avail)
    assert p["uniform"] == pytest.approx(UNIFORM_FLOOR) and p["two-point"] == pytest.approx(FLOOR)
    assert sum(p.values()) == pytest.approx(1.0)
    assert mix.probabilities({"uniform": True})["border"] == 0.0


def test_the_buffer_hands_out_the_least_mutated_newest_first():
    buf = MutationBuffer(("x",), capacity=5)
    buf.add(x=np.arange(3))
    assert buf.take(2)["x"].tolist() == [1, 2]
    buf.add(x=np.arange(10, 14))  # over capacity: the most mutated (1, 2) go first
    assert len(buf) == 5
    assert sorted(buf.take(5)["x"].tolist()) == [0, 10, 11, 12, 13]
    assert buf.take(0) is None


def test_wall_points_lie_on_the_cells_walls_pushed_off_to_either_side():
    from meshvis.viewcells.cells import ViewCells
    from meshvis.viewcells.strategies import CellWalls
    from meshvis.viewcells.viewspace import ViewSpace

    vc = ViewCells.grid(ViewSpace(np.zeros(3), np.array([4.0, 1, 1])), (2, 1, 1))
    x = CellWalls(vc, push=1e-3).draw(4000, np.random.default_rng(0))
    # the distance to the nearest plane x = 0, 2, 4 or y, z = 0, 1 is the push (10 x 1e-3)
    planes = np.stack(
        [
            np.abs(x[:, :1] - [0.0, 2.0, 4.0]).min(axis=1),
            np.abs(x[:, 1:] - [[0.0]]).min(axis=1),
            np.abs(x[:, 1:] - [[1.0]]).min(axis=1),
        ],
        axis=1,
    ).min(axis=1)
    # (or less, for the few drawn within the push of another plane)
    assert np.all(planes <= 1e-2 + 1e-12) and np.isclose(planes, 1e-2).mean() > 0.95
    # only the points inside the view space are kept (half of those pushed off the outside)
    assert vc.view_space.contains(x).all() and 1500 < len(x) < 2500
    # the wall at x = 2 is drawn from both cells: both sides of it by area
    mid = np.abs(x[:, 0] - 2.0) < 0.02
    assert 0.4 < (x[mid, 0] > 2.0).mean() < 0.6


def test_adjacent_cell_mutations_aim_from_a_neighbour_at_the_face_it_has_not_seen():
    from meshvis.soup import Soup
    from meshvis.viewcells.cells import ViewCells
    from meshvis.viewcells.strategies import SurfacePoints, adjacent_cell
    from meshvis.viewcells.viewspace import ViewSpace

    soup = Soup(np.array([[5.0, 0, 0], [5, 1, 0], [5, 0, 1]]), np.array([[0, 1, 2]]))
    vc = ViewCells.grid(ViewSpace(np.zeros(3), np.array([3.0, 1, 1])), (3, 1, 1))
    bits = np.zeros((3, 1), np.uint64)
    bits[[0, 2], 0] = 1  # cells 0 and 2 see the face, cell 1 does not
    buf = MutationBuffer(("face", "cell"))
    buf.add(face=np.zeros(200, np.int64), cell=np.r_[np.zeros(100, np.int64), np.full(100, 2)])
    s = adjacent_cell(buf, 200, np.random.default_rng(0), bits, vc.adjacent(), vc, SurfacePoints(soup))
    # every entry's only unseeing neighbour is cell 1: all samples start in its closed box,
    # about three in four on the wall it shares with the cell that saw the face
    assert len(s.origin) == 200
    x = s.origin[:, 0]
    assert np.all((x >= 1.0) & (x <= 2.0))
    on_wall = (x == 1.0) | (x == 2.0)
    assert 120 <= on_wall.sum() <= 180
    assert vc.locate(s.origin[~on_wall]).tolist() == [1] * int((~on_wall).sum())
    t = (5.0 - s.origin[:, 0]) / s.direction[:, 0]
    hit = s.origin + t[:, None] * s.direction
    assert (
        np.all(hit[:, 1] >= -1e-9)
        and np.all(hit[:, 2] >= -1e-9)
        and np.all(hit[:, 1] + hit[:, 2] <= 1 + 1e-9)
    )
    bits[1, 0] = 1  # now every cell has it: nothing to aim at
    buf.add(face=np.zeros(10, np.int64), cell=np.ones(10, np.int64))
    again = adjacent_cell(buf, 10, np.random.default_rng(0), bits, vc.adjacent(), vc, SurfacePoints(soup))
    assert len(again.origin) == 0
