"""The weld's pairing of close points (a hashed grid) against a k-d tree and scipy's components."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from meshvis.geometry import adjacency
from meshvis.geometry._kernels import near_labels


def reference(points: np.ndarray, radius: float) -> np.ndarray:
    """Components of the points within ``radius`` of each other, by k-d tree and csgraph."""
    pairs = cKDTree(points).query_pairs(radius, output_type="ndarray")
    n = len(points)
    g = coo_matrix((np.ones(len(pairs), np.int8), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    return connected_components(g, directed=False)[1]


def clustered(rng: np.random.Generator, n: int, grid: bool, flat: bool) -> np.ndarray:
    """Random points, a third of them moved close to another point (chains and clusters)."""
    p = rng.random((n, 3))
    if grid:  # many coordinates on the same planes, some on cell borders
        p = np.round(p * 7) / 7
    if flat:  # an axis-aligned plane: one coordinate shared by every point
        p[:, 0] = 0.25
    k = n // 3
    p[:k] = p[rng.integers(0, n, k)] + rng.normal(0, 1, (k, 3)) * 10.0 ** rng.uniform(-9, -1)
    return p


@pytest.mark.parametrize("scale, shift", [(1.0, 0.0), (1e-6, 0.0), (1e6, 0.0), (1.0, 1e6), (1e3, -1e6)])
def test_near_labels_are_the_k_d_trees_components(scale, shift):
    rng = np.random.default_rng(int(scale * 7 + shift) % 1000)
    for trial in range(30):
        p = clustered(rng, int(rng.integers(2, 300)), trial % 3 == 0, trial % 4 == 0) * scale + shift
        radius = 10.0 ** rng.uniform(-8, -0.5) * scale
        assert np.array_equal(near_labels(p, radius), reference(p, radius)), (trial, radius)


def test_near_labels_at_the_radius_and_beyond():
    p = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 3, 4.0]])
    assert near_labels(p, 1.0).tolist() == [0, 0, 0, 1]  # a distance equal to the radius links
    assert near_labels(p, np.nextafter(1.0, 0)).tolist() == [0, 1, 2, 3]
    assert near_labels(p, 5.0).tolist() == [0, 0, 0, 0]
    assert near_labels(p, np.inf).tolist() == [0, 0, 0, 0]
    assert near_labels(p[:1], 1.0).tolist() == [0]
    assert near_labels(np.zeros((0, 3)), 1.0).tolist() == []


def test_components_number_by_smallest_face():
    pairs = np.array([[3, 4], [1, 4], [0, 2]])
    n, label = adjacency.components(6, pairs)
    assert n == 3 and label.tolist() == [0, 1, 0, 1, 1, 2]
    assert adjacency.components(0, np.zeros((0, 2)))[0] == 0
