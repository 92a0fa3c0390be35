"""The compiled kernels of from-region visibility give the bits of the numpy code they replace."""

from __future__ import annotations

import numpy as np
import pytest

from meshvis.rays import _kernels as ray_kernels
from meshvis.rays.samples import uniform_in_triangles, uniform_sphere
from meshvis.visibility import _kernels

#: rows per check: enough to meet every rounding case of the summation orders
ROWS = 20_000


def _bytes_equal(a: np.ndarray, b: np.ndarray) -> None:
    assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.fixture
def data():
    rng = np.random.default_rng(7)
    # spread over many magnitudes so that the order of additions matters
    x = rng.normal(size=(ROWS, 3)) * np.exp(rng.normal(size=(ROWS, 3)) * 3)
    y = rng.normal(size=(ROWS, 3)) * np.exp(rng.normal(size=(ROWS, 3)) * 3)
    tri = rng.normal(size=(500, 3, 3)) * 10
    face = rng.integers(0, len(tri), ROWS)
    return x, y, tri, face


def test_points_in_faces_are_uniform_in_triangles(data):
    _, _, tri, face = data
    expected = uniform_in_triangles(tri[face], np.random.default_rng(1))
    rng = np.random.default_rng(1)
    ru, rv = rng.random(len(face)), rng.random(len(face))
    _bytes_equal(ray_kernels.points_in_faces(tri, face, ru, rv), expected)


def test_unit_rows_far_origins_and_aimed_directions(data):
    x, y, _, _ = data
    _bytes_equal(
        ray_kernels.unit_rows(np.random.default_rng(2).normal(size=(ROWS, 3))),
        uniform_sphere(ROWS, np.random.default_rng(2)),
    )
    center, margin = np.array([0.3, -2.0, 5.0]), 1.05 * 17.0
    reach = np.linalg.norm(x - center, axis=1) + margin
    _bytes_equal(_kernels.far_origins(x, y, center, margin), x - y * reach[:, None])
    d = y - x
    _bytes_equal(_kernels.aimed_from(x, y), d / np.linalg.norm(d, axis=1, keepdims=True))


def test_facing_sides_follow_einsum(data):
    x, _, _, face = data
    normals = np.random.default_rng(3).normal(size=(500, 3))
    expected = (np.einsum("ij,ij->i", x, normals[face]) >= 0).astype(np.int8)
    _bytes_equal(_kernels.facing_sides(x, normals, face), expected)


def test_seed_segments_are_push_off_then_segment_queries(data):
    x, y, _, face = data
    normals = np.random.default_rng(4).normal(size=(500, 3))
    side = (face % 2).astype(np.int8)
    center, scale, offset, diagonal = np.array([1.0, 2.0, 3.0]), 0.0123, 1e-6, 81.3
    sign = np.where(side == 0, 1.0, -1.0)
    pushed = x + normals[face] * (sign * offset * diagonal)[:, None]
    expected = ray_kernels.segment_queries(pushed, y, center, scale, offset)
    got = _kernels.seed_segments(x, normals, face, side, y, center, scale, offset, diagonal)
    for a, b in zip(got, expected):
        _bytes_equal(a, b)


def test_hit_rows_and_split_segments(data):
    x, y, _, face = data
    face = np.where(face % 3 == 0, -1, face).astype(np.int64)
    side = (face % 2).astype(np.int8)
    distance = np.abs(x[:, 0])
    hit = face >= 0
    expected = (face[hit], side[hit], x[hit], y[hit], x[hit] + y[hit] * distance[hit, None])
    for a, b in zip(_kernels.hit_rows(x, y, face, side, distance), expected):
        _bytes_equal(a, b)
    owner = np.arange(ROWS, dtype=np.int64)
    b_face = np.roll(face, 1)
    split = (face != b_face) & (np.linalg.norm(y - x, axis=1) > 1.0)
    kept = [v[split] for v in (owner, x, y, face, b_face)]
    got = _kernels.split_segments(owner, x, y, face, b_face, 1.0)
    for a, b in zip(got, [*kept, 0.5 * (kept[1] + kept[2])]):
        _bytes_equal(a, b)
