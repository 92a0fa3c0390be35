"""View cells: the kD-tree of a grid and of boxes, locating points, the compressed PVS, the walk."""

from __future__ import annotations

import json

import numpy as np
import pytest

from meshvis.errors import ParameterError
from meshvis.viewcells import _kernels
from meshvis.viewcells.cells import ViewCells, grid_shape, parse_cells, read_boxes
from meshvis.viewcells.viewspace import ViewSpace

UNIT = ViewSpace(np.zeros(3), np.array([4.0, 3.0, 2.0]))


def test_a_grid_has_its_cells_boxes_and_volumes():
    vc = ViewCells.grid(UNIT, (4, 3, 2))
    assert vc.n_cells == 24
    assert np.allclose(vc.cell_hi - vc.cell_lo, 1.0)
    assert np.allclose(vc.volume, 1 / 24)
    # every cell's centre is located in that cell
    centre = 0.5 * (vc.cell_lo + vc.cell_hi)
    assert vc.locate(centre).tolist() == list(range(24))
    assert vc.locate(np.array([[5.0, 1, 1], [-0.1, 1, 1]])).tolist() == [-1, -1]


def test_boxes_that_tile_part_of_the_space_leave_the_rest_out():
    boxes = [[0, 0, 0, 1, 3, 2], [1, 0, 0, 4, 1, 2], [3, 1, 0, 4, 3, 1]]
    vc = ViewCells.from_boxes(UNIT, boxes)
    assert vc.n_cells == 3
    assert np.allclose(np.concatenate([vc.cell_lo, vc.cell_hi], axis=1), boxes)
    assert vc.locate(
        np.array([[0.5, 2, 1], [2, 0.5, 1], [3.5, 2, 0.5], [2, 2, 1], [3.5, 2, 1.5]])
    ).tolist() == [
        0,
        1,
        2,
        -1,
        -1,
    ]
    assert vc.describe()["leaves_without_view_space"] >= 2


@pytest.mark.parametrize(
    "boxes",
    [
        [[0, 0, 0, 2, 2, 2], [1, 1, 1, 3, 3, 2]],  # overlapping
        # a pinwheel: four boxes round a centre, no cut separates them
        [[0, 0, 0, 3, 1, 2], [3, 0, 0, 4, 2, 2], [1, 2, 0, 4, 3, 2], [0, 1, 0, 1, 3, 2]],
    ],
)
def test_boxes_that_no_cut_separates_are_refused(boxes):
    with pytest.raises(ParameterError, match="kD partition"):
        ViewCells.from_boxes(UNIT, boxes)


def test_a_cells_file_is_read_and_checked(tmp_path):
    good = tmp_path / "cells.json"
    good.write_text(json.dumps({"cells": [[0, 0, 0, 2, 3, 2], [2, 0, 0, 4, 3, 2]]}))
    assert read_boxes(str(good)).shape == (2, 6)
    assert parse_cells(str(good), UNIT).n_cells == 2
    bad = tmp_path / "bad.json"
    for text, message in (
        ("[[0, 0, 0, 1, 1]]", "expected a list of boxes"),
        ("[[0, 0, 0, 1, 1, 0]]", "x0 < x1"),
        ("not json", "not a JSON file"),
    ):
        bad.write_text(text)
        with pytest.raises(ParameterError, match=message):
            read_boxes(str(bad))
    with pytest.raises(ParameterError, match="not found"):
        read_boxes(str(tmp_path / "missing.json"))


def test_cell_texts():
    assert parse_cells("auto", UNIT) == ("auto", 64)
    assert parse_cells("auto:12", UNIT) == ("auto", 12)
    assert parse_cells("grid:2,1,1", UNIT).n_cells == 2
    for text in ("grid:2,2", "auto:x", "auto:0", "cubes", "grid:0,1,1"):
        with pytest.raises(ParameterError):
            parse_cells(text, UNIT)


def test_grid_shape_makes_near_cubes_of_exactly_n_cells():
    assert grid_shape(UNIT, 24) == (4, 3, 2)
    shape = grid_shape(ViewSpace(np.zeros(3), np.array([10.0, 1.0, 10.0])), 64)
    assert np.prod(shape) == 64 and shape[1] == 1


def test_compression_stores_what_siblings_share_at_their_parent():
    vc = ViewCells.grid(UNIT, (2, 2, 1))
    rng = np.random.default_rng(0)
    bits = rng.integers(0, 2**63, size=(4, 3), dtype=np.int64).astype(np.uint64)
    shared = np.uint64(0xF0F0)
    bits |= shared  # every cell sees these faces: they go to the root
    stored = vc.compress(bits)
    assert np.array_equal(vc.expand(stored), bits)
    assert ((stored[0] & shared) == shared).all()
    leaves = vc.cell_node
    assert not (stored[leaves] & shared).any()
    # what is stored is less than the cells' lists
    assert _kernels.count_rows(stored).sum() < _kernels.count_rows(bits).sum()


def test_the_walk_visits_exactly_the_cells_each_segment_pierces():
    vc = ViewCells.grid(UNIT, (4, 3, 2))
    rng = np.random.default_rng(1)
    n = 400
    origin = rng.uniform(-1, 5, (n, 3))
    direction = rng.standard_normal((n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    t_back, t_fwd = rng.uniform(0, 3, n), rng.uniform(0, 3, n)
    t_fwd[:50] = np.inf  # misses: the segment runs to the box's wall
    face = np.arange(n, dtype=np.int64)  # one face per segment: bit (c, k) says segment k met cell c
    bits = np.zeros((vc.n_cells, -(-n // 64)), np.uint64)
    out = [np.empty(n, np.int32), np.empty(n, np.int32), np.empty(n, np.int8), np.empty(n, np.int8)]
    log = np.empty(n * vc.n_cells + 64, np.int32)
    scratch = np.empty(len(log), np.int64), np.empty(len(log)), np.empty(len(log))
    _kernels.walk(
        vc.tree_arrays(),
        origin,
        direction,
        t_back,
        t_fwd,
        np.full(n, -1, np.int64),
        face,
        out[0],
        bits,
        np.zeros(vc.n_cells, np.int64),
        out[1],
        out[2],
        out[3],
        np.empty((n, 2)),
        log,
        log.copy(),
        0,
        0,
        *scratch,
        0,
    )
    got = np.unpackbits(bits.view(np.uint8), axis=1, bitorder="little")[:, :n].astype(bool)
    # brute force: the segment's part inside each cell's box, by slabs, with a margin
    for c in range(vc.n_cells):
        lo, hi = vc.cell_lo[c], vc.cell_hi[c]
        with np.errstate(divide="ignore", invalid="ignore"):
            a, b = (lo - origin) / direction, (hi - origin) / direction
        near = np.minimum(a, b).max(axis=1)
        far = np.maximum(a, b).min(axis=1)
        t0, t1 = np.maximum(near, -t_back), np.minimum(far, t_fwd)
        surely = t1 - t0 > 1e-9
        surely_not = t1 - t0 < -1e-9
        assert got[c][surely].all() and not got[c][surely_not].any()
    # the point of each segment inside the space lies in the cell the walk gave it
    inside = vc.locate(origin)
    assert np.array_equal(out[0][inside >= 0], inside[inside >= 0])


def test_adjacent_cells_share_a_piece_of_wall():
    vc = ViewCells.grid(UNIT, (4, 3, 2))
    ptr, nbr = vc.adjacent()
    lo = vc.cell_lo
    for c in range(vc.n_cells):
        got = set(nbr[ptr[c] : ptr[c + 1]].tolist())
        # in a grid of unit cubes the neighbours are the cells one step away along one axis
        want = {d for d in range(vc.n_cells) if np.abs(lo[d] - lo[c]).sum() == 1.0}
        assert got == want
    # boxes of different sizes: [0,1]x[0,3] touches [1,4]x[0,1]; [3,4]x[1,3] touches [1,4]x[0,1]
    # only along an edge at y = 1 for x in [3, 4] (z overlaps 0..1): a piece of wall
    boxes = ViewCells.from_boxes(UNIT, [[0, 0, 0, 1, 3, 2], [1, 0, 0, 4, 1, 2], [3, 1, 0, 4, 3, 1]])
    ptr, nbr = boxes.adjacent()
    pairs = {(c, int(d)) for c in range(boxes.n_cells) for d in nbr[ptr[c] : ptr[c + 1]]}
    box = {tuple(np.r_[boxes.cell_lo[c], boxes.cell_hi[c]].tolist()): c for c in range(boxes.n_cells)}
    a, b, c = box[(0, 0, 0, 1, 3, 2)], box[(1, 0, 0, 4, 1, 2)], box[(3, 1, 0, 4, 3, 1)]
    assert pairs == {(a, b), (b, a), (b, c), (c, b)}
