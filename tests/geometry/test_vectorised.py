"""The numpy formulations of the geometry kernels give the compiled kernels' answers, bit for bit.

A small model is analysed by :mod:`meshvis.geometry._vectorised` (no numba), a larger one by
:mod:`meshvis.geometry._kernels`; the threshold is moved here to run both on the same input.
"""

from __future__ import annotations

import numpy as np
import pytest
from helpers import real_model

from meshvis.geometry import _kernels as K
from meshvis.geometry import _vectorised as V
from meshvis.geometry import adjacency, intersect
from meshvis.io import load

#: the arrays of the analysis compared between the two formulations
FLAGS = ("intersects", "coplanar", "too_close", "intersect_pairs", "coplanar_pairs", "close_pairs")


def analysis(vertices: np.ndarray, faces: np.ndarray) -> dict[str, np.ndarray]:
    """Every output of the analysis ``meshvis info`` runs that goes through the kernels."""
    groups = adjacency.group_vertices(vertices, faces)
    index, fw = adjacency.weld(vertices, faces)
    table = adjacency.edges(fw)
    _, label = adjacency.components(len(faces), adjacency.face_adjacency(table, manifold_only=False))
    flags = intersect.intersection_flags(vertices, faces, faces_welded=fw)
    out = {
        "group": groups.group,
        "first": groups.first,
        "index": index,
        "degenerate": adjacency.degenerate_faces(vertices, faces, tol=1e-9, zero_area=True),
        "flat": adjacency.degenerate_faces(vertices, faces, tol=1e-9),
        "label": label,
        "normalised": intersect._normalised(vertices, faces, np.arange(len(faces)))[0],
    }
    return out | {k: flags[k] for k in FLAGS}


def both_ways(monkeypatch, vertices, faces) -> tuple[dict, dict]:
    """The analysis by the compiled kernels, then by the numpy formulations."""
    monkeypatch.setattr(V, "SMALL_MODEL_FACES", -1)
    compiled = analysis(vertices, faces)
    monkeypatch.setattr(V, "SMALL_MODEL_FACES", 10**12)
    return compiled, analysis(vertices, faces)


def assert_same(a: dict, b: dict) -> None:
    for key in a:
        assert a[key].dtype == b[key].dtype and np.array_equal(a[key], b[key]), key


@pytest.mark.parametrize("name", ["wallhole.obj", "suzanne.obj", "CesiumMilkTruck.glb"])
def test_real_models_are_analysed_alike(monkeypatch, name):
    soup = load(real_model(name))
    a, b = both_ways(monkeypatch, soup.vertices, soup.faces)
    assert_same(a, b)
    assert a["intersects"].any()  # the narrow phase had something to find


def awkward_model(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """Faces that meet every branch of the tests: copies either way round, faces folded over
    an edge, crossing beyond a shared corner, coplanar overlaps, slivers, collapsed and
    zero-area faces, corners 1e-12 apart (welded) and signed zeros."""
    v = rng.random((60, 3)).round(1)  # shared coordinates: coplanar and touching faces
    v[:6] = [[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.5, 0.5, 1e-3], [0.5, 0.5, 0], [0.3, 0.3, 0.0]]
    f = rng.integers(0, 60, (150, 3))
    extra = [
        [0, 1, 2], [0, 2, 1], [0, 1, 2],  # a face and its copies, either winding
        [0, 1, 3], [1, 0, 4],  # on one edge: folded over, and lying flat
        [2, 5, 3], [0, 5, 1],  # one shared corner
        [0, 0, 1], [0, 1, 4], [5, 5, 5],  # collapsed, three collinear corners, a point
    ]  # fmt: skip
    v = np.vstack([v, v[:6] + 1e-12, [[-0.0, 0.0, -0.0], [0.0, -0.0, 0.0]]])
    f = np.vstack([f, extra, [[60, 61, 62], [63, 64, 65], [66, 67, 1]]])
    return v, f


@pytest.mark.parametrize("seed", range(4))
def test_awkward_faces_are_analysed_alike(monkeypatch, seed):
    v, f = awkward_model(np.random.default_rng(seed))
    a, b = both_ways(monkeypatch, v, f)
    assert_same(a, b)
    assert a["coplanar"].any() and a["intersects"].any()


def test_near_labels_component_labels_and_groups_alike():
    rng = np.random.default_rng(3)
    for trial in range(40):
        n = int(rng.integers(2, 200))
        p = rng.random((n, 3))
        p[: n // 3] = p[rng.integers(0, n, n // 3)] + rng.normal(0, 1, (n // 3, 3)) * 1e-7
        if trial % 4 == 0:
            p[:, 0] = 0.25  # one coordinate shared by every point
        r = 10.0 ** rng.uniform(-8, -1)
        assert np.array_equal(V.near_labels(p, r), K.near_labels(p, r))
        a, b = rng.integers(0, n, (2, int(rng.integers(0, 2 * n))))
        assert np.array_equal(V.component_labels(n, a, b), K.component_labels(n, a, b))
        bits = rng.integers(0, 4, (n, 3)).astype(np.uint64)
        hashed = adjacency._hash_rows(bits)
        for x, y in zip(V.exact_groups(bits, hashed), K.exact_groups(bits, hashed)):
            assert np.array_equal(x, y)
    p = rng.random((5, 3))
    assert np.array_equal(V.near_labels(p, np.inf), K.near_labels(p, np.inf))


def test_the_small_model_threshold_chooses_the_module():
    assert V.kernels(V.SMALL_MODEL_FACES) is V
    assert V.kernels(V.SMALL_MODEL_FACES + 1) is K
