"""Broad phase, conservative triangle intersection and coplanarity tests (appendix H §2)."""

from __future__ import annotations

import numpy as np
import pytest

from meshvis.errors import ParameterError
from meshvis.geometry.intersect import EPS, candidate_pairs, intersection_flags, too_close


def soup(*triangles) -> tuple[np.ndarray, np.ndarray]:
    """Unwelded soup of the given (3, 3) triangles, in order."""
    v = np.asarray(triangles, float).reshape(-1, 3)
    return v, np.arange(len(v)).reshape(-1, 3)


def crossing_pair(offset) -> list[np.ndarray]:
    """A horizontal triangle and a vertical one piercing its interior."""
    o = np.asarray(offset, float)
    a = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float) + o
    b = np.array([[0.2, 0.2, -0.5], [0.3, 0.2, 0.5], [0.2, 0.3, 0.5]], float) + o
    return [a, b]


def pair_set(pairs: np.ndarray) -> set[tuple[int, int]]:
    return {tuple(p) for p in np.asarray(pairs).tolist()}


# --------------------------------------------------------------------------- broad phase
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_candidate_pairs_match_brute_force(seed):
    rng = np.random.default_rng(seed)
    m = 500
    centre = rng.random((m, 3)) * [1, 1, 0.05]  # flattish cloud, like a floor plan
    half = 10 ** rng.uniform(-4, -0.3, (m, 1)) * rng.random((m, 3))
    lo, hi = centre - half, centre + half
    lo[:3], hi[:3] = [-1, -1, -1], [2, 2, 2]  # three huge boxes overlapping everything
    lo[10:20], hi[10:20] = lo[10], hi[10]  # identical boxes
    hi[30:60, 0] = lo[30:60, 0]  # flat boxes: touching counts as overlapping
    got = candidate_pairs(lo, hi)
    i, j = np.triu_indices(m, 1)
    overlap = np.all((lo[i] <= hi[j]) & (lo[j] <= hi[i]), axis=1)
    assert np.array_equal(got, np.stack([i[overlap], j[overlap]], axis=1))


def test_candidate_pairs_small_inputs():
    assert candidate_pairs(np.zeros((1, 3)), np.ones((1, 3))).shape == (0, 2)
    # every box the same point
    got = candidate_pairs(np.zeros((3, 3)), np.zeros((3, 3)))
    assert pair_set(got) == {(0, 1), (0, 2), (1, 2)}


# --------------------------------------------------------------------------- intersections
def test_known_number_of_crossing_pairs():
    k = 5
    tris = [t for n in range(k) for t in crossing_pair([3.0 * n, 0, 0])]
    v, f = soup(*tris)
    d = intersection_flags(v, f)
    assert pair_set(d["intersect_pairs"]) == {(2 * n, 2 * n + 1) for n in range(k)}
    assert d["intersects"].all()
    assert not d["coplanar"].any()
    assert d["too_close"].all()


def test_pairs_sharing_an_edge_or_vertex_are_not_intersecting():
    # a fold (two faces on one edge at an angle) and a flat pair side by side
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.5, 0.5, 1.0], [1, 1, 0]], float)
    f = np.array([[0, 1, 2], [1, 0, 3], [1, 4, 2]])
    d = intersection_flags(v, f)
    assert not d["intersects"].any()
    assert not d["coplanar"].any()
    assert not d["too_close"].any()
    # the same with unwelded (but coincident) corners: welding makes them adjacent
    v2, f2 = soup(*v[f])
    d2 = intersection_flags(v2, f2)
    assert not (d2["intersects"] | d2["coplanar"] | d2["too_close"]).any()


def test_pair_sharing_one_vertex_crossing_beyond_it_is_reported():
    o, x, y = [0, 0, 0], [1, 0, 0], [0, 1, 0]
    crossing = [o, [0.5, 0.5, 1.0], [0.5, 0.5, -1.0]]  # contains the direction (1, 1, 0)
    apart = [o, [-0.5, -0.5, 1.0], [-0.5, -0.5, -1.0]]  # contains (-1, -1, 0) only
    v = np.array([o, x, y, *crossing[1:], *apart[1:]], float)
    f = np.array([[0, 1, 2], [0, 3, 4], [0, 5, 6]])
    d = intersection_flags(v, f)
    assert pair_set(d["intersect_pairs"]) == {(0, 1)}
    assert d["intersects"].tolist() == [True, True, False]


def test_cube_corner_fan_is_clean():
    import trimesh

    box = trimesh.creation.box()
    d = intersection_flags(box.vertices, box.faces)
    assert not (d["intersects"] | d["coplanar"] | d["too_close"]).any()


def test_near_miss_is_conservative():
    # bounding box [0,1]^3 whatever d: the absolute eps is EPS * sqrt(3)
    eps = EPS * np.sqrt(3)

    def pair(d):
        a = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
        b = [[0.2, 0.2, d], [0.4, 0.2, 1], [0.2, 0.4, 1]]  # lowest corner d above a
        return soup(a, b)

    far = intersection_flags(*pair(10 * eps))
    assert not far["intersects"].any() and not far["too_close"].any()
    close = intersection_flags(*pair(0.1 * eps))
    assert close["intersects"].all() and close["too_close"].all()
    touching = intersection_flags(*pair(0.0))
    assert touching["intersects"].all()
    # a larger "near" distance sees the far pair, without calling it intersecting
    wide = intersection_flags(*pair(10 * eps), near=100 * EPS)
    assert wide["too_close"].all() and not wide["intersects"].any()
    assert too_close(*pair(10 * eps), near=100 * EPS).all()


def test_parallel_planes_near_miss():
    eps = EPS * np.sqrt(3)

    def pair(d):
        a = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
        b = [[0.1, 0.1, d], [0.6, 0.1, d], [0.1, 0.6, d]]
        c = [[1, 1, 1], [1, 1, 1 - 1e-3], [1, 1 - 1e-3, 1]]  # fixes the bounding box
        return soup(a, b, c)

    far = intersection_flags(*pair(10 * eps))
    assert not (far["intersects"] | far["coplanar"] | far["too_close"]).any()
    close = intersection_flags(*pair(0.1 * eps))
    assert close["coplanar"].tolist() == [True, True, False]
    assert not close["intersects"].any()  # one plane: coplanar, not intersecting


def test_random_intersecting_pairs_are_never_missed():
    """Conservative: every pair that really crosses (an edge pierces the other) is flagged."""
    rng = np.random.default_rng(7)
    n = 300
    a = rng.random((n, 3, 3))
    b = a.mean(axis=1, keepdims=True) + rng.normal(scale=0.5, size=(n, 3, 3))
    crosses = np.array([_edges_pierce(a[k], b[k]) or _edges_pierce(b[k], a[k]) for k in range(n)])
    assert 50 < crosses.sum() < n  # both kinds are present
    for k in np.flatnonzero(crosses):
        d = intersection_flags(*soup(a[k], b[k]))
        assert d["intersects"].all() or d["coplanar"].all(), k
    # a pair moved apart along a separating plane's normal by 10 eps is not flagged
    for k in range(40):
        t1 = rng.random((3, 3))
        t2 = rng.random((3, 3))
        t2[:, 2] = t2[:, 2] * 0.5 + t1[:, 2].max() + 20 * EPS * 3  # above t1's z range
        d = intersection_flags(*soup(t1, t2))
        assert not d["intersects"].any()


def _edges_pierce(t, s) -> bool:
    """Does an edge of t cross the interior of triangle s? (reference, plain loops)"""
    n = np.cross(s[1] - s[0], s[2] - s[0])
    for i in range(3):
        p, q = t[i], t[(i + 1) % 3]
        dp, dq = n @ (p - s[0]), n @ (q - s[0])
        if dp * dq >= 0 or dp == dq:
            continue
        x = p + (q - p) * dp / (dp - dq)
        w = [np.cross(s[(k + 1) % 3] - s[k], x - s[k]) @ n for k in range(3)]
        if min(w) > 1e-9 * (n @ n):
            return True
    return False


# --------------------------------------------------------------------------- coplanarity
def test_coplanar_overlaps_and_duplicates():
    base = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], float)
    shifted = base + [0.3, 0.3, 0]  # same plane, overlapping, no shared corner
    beside = np.array([[1, 0, 0], [1, 1, 0], [0, 1, 0]], float)  # shares the long edge
    far = base + [5, 0, 0]
    v, f = soup(base, shifted, beside, far, far[[0, 2, 1]])  # last: reversed duplicate of far
    d = intersection_flags(v, f)
    # beside overlaps shifted (not base: they share the hypotenuse side by side)
    assert pair_set(d["coplanar_pairs"]) == {(0, 1), (1, 2), (3, 4)}
    assert d["coplanar"].tolist() == [True] * 5
    assert not d["intersects"].any()


def test_folded_pair_sharing_an_edge_is_coplanar():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.4, 0.4, 0]], float)
    f = np.array([[0, 1, 2], [1, 0, 3]])  # second face lies on top of the first
    d = intersection_flags(v, f)
    assert d["coplanar"].all()
    assert not d["intersects"].any()


def bent_quad(degrees: float) -> np.ndarray:
    """Corners a, b, c, d of a unit square bent along its diagonal ac by ``degrees``."""
    t = np.radians(degrees)
    # d rotates about the diagonal ac (through the origin, direction (1, 1, 0) / sqrt 2)
    axis = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    d0 = np.array([0.0, 1.0, 0.0])
    along = (d0 @ axis) * axis
    perp = d0 - along
    d = along + np.cos(t) * perp + np.sin(t) * np.cross(axis, perp)
    return np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], d], float)


@pytest.mark.parametrize("welded", [True, False])
def test_quad_stored_with_both_diagonals_planes_one_degree_apart_is_coplanar(welded):
    # abc + acd and abd + bcd cover the same bent quad twice; every pair shares an edge and
    # abc / abd (and acd / bcd ...) lie folded onto each other 1 degree apart
    q = bent_quad(1.0)
    f = np.array([[0, 1, 2], [0, 2, 3], [0, 1, 3], [1, 2, 3]])
    v, f = (q, f) if welded else soup(*q[f])
    d = intersection_flags(v, f)
    assert d["coplanar"].all()
    assert not d["intersects"].any()
    folded = pair_set(d["coplanar_pairs"])
    assert (0, 2) in folded and (1, 3) in folded
    assert (0, 1) not in folded  # abc and acd lie side by side on their diagonal


def test_fold_wider_than_the_fold_angle_is_not_coplanar():
    q = bent_quad(10.0)
    d = intersection_flags(q, np.array([[0, 1, 2], [0, 2, 3], [0, 1, 3], [1, 2, 3]]))
    assert not d["coplanar"].any()


# --------------------------------------------------------------------------- invariance
def mixed_scene():
    tris = crossing_pair([0, 0, 0]) + crossing_pair([3, 0, 0])
    base = np.array([[0, 0, 4], [1, 0, 4], [0, 1, 4]], float)
    tris += [base, base + [0.2, 0.1, 0]]  # coplanar overlap
    eps = EPS * 6.0  # roughly the diagonal of the scene times EPS
    tris += [
        np.array([[6, 0, 0], [7, 0, 0], [6, 1, 0]], float),
        np.array([[6.2, 0.2, 10 * eps], [6.4, 0.2, 1], [6.2, 0.4, 1]]),
    ]  # near miss
    tris += [
        np.array([[6, 3, 0], [7, 3, 0], [6, 4, 0]], float),
        np.array([[6.2, 3.2, 0.01 * eps], [6.4, 3.2, 1], [6.2, 3.4, 1]]),
    ]  # within eps
    return soup(*tris)


@pytest.mark.parametrize("scale, shift", [(1e-6, 0.0), (1e6, 0.0), (1.0, 1e6), (1e-3, 1e3)])
def test_flags_invariant_under_scaling_and_translation(scale, shift):
    v, f = mixed_scene()
    ref = intersection_flags(v, f)
    size = np.ptp(v, axis=0).max()
    w = v * scale + shift * size * scale
    got = intersection_flags(w, f)
    for key in ("intersects", "coplanar", "too_close"):
        assert np.array_equal(got[key], ref[key]), key
    for key in ("intersect_pairs", "coplanar_pairs", "close_pairs"):
        assert np.array_equal(got[key], ref[key]), key
    assert ref["intersects"].tolist() == [True] * 4 + [False] * 4 + [True] * 2
    assert ref["coplanar"].tolist() == [False] * 4 + [True] * 2 + [False] * 4


def test_parameters_are_checked():
    v, f = soup(*crossing_pair([0, 0, 0]))
    with pytest.raises(ParameterError):
        intersection_flags(v, f, eps=0.0)
    with pytest.raises(ParameterError):
        intersection_flags(v, f, eps=2.0)
    with pytest.raises(ParameterError):
        intersection_flags(v, f, angle_eps=-1.0)


def test_degenerate_faces_do_not_crash():
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0.2, 0.2, 0], [0.2, 0.2, 0], [0.2, 0.2, 0]], float)
    f = np.array([[0, 1, 2], [3, 4, 5], [0, 0, 1]])
    d = intersection_flags(v, f)
    assert d["intersects"].shape == (3,)
    assert not d["coplanar"].any()  # no normal, no coplanarity


# --------------------------------------------------------------------------- real model
def test_real_model_agrees_with_meshlab():
    """On cow.obj, every face MeshLab finds self-intersecting is flagged, and vice versa."""
    import os

    pymeshlab = pytest.importorskip("pymeshlab")
    path = os.path.join(os.path.dirname(__file__), "..", "..", "..", "shared", "models", "real", "cow.obj")
    if not os.path.exists(path):
        pytest.skip("real models not available")
    import trimesh

    from meshvis.geometry.adjacency import weld

    mesh = trimesh.load(path, process=False, force="mesh")
    v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    index, fw = weld(v, f)
    vw = np.zeros((fw.max() + 1, 3))
    vw[index[index >= 0]] = v[index >= 0]
    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(vw, fw))
    ms.compute_selection_by_self_intersections_per_face()
    meshlab = ms.current_mesh().face_selection_array()
    d = intersection_flags(v, f, faces_welded=fw)
    ours = d["intersects"] | d["coplanar"]
    assert meshlab.sum() > 10
    assert not (meshlab & ~ours).any()  # conservative: nothing missed
    assert (ours & ~meshlab).sum() <= 0.05 * meshlab.sum()


def test_flags_in_threads_are_those_of_one_call(monkeypatch):
    """The narrow phase and the face axes on slices in threads give the flags of one call."""
    import meshvis._threads as T
    import meshvis.geometry.intersect as I

    rng = np.random.default_rng(11)
    # small triangles in a box, many near each other, some stored twice (coplanar)
    tri = rng.random((3000, 1, 3)) + rng.normal(scale=0.03, size=(3000, 3, 3))
    tri[-300:] = tri[-600:-300]
    v, f = tri.reshape(-1, 3), np.arange(9000).reshape(-1, 3)
    monkeypatch.setattr(T, "THREAD_ROWS", 1 << 40)  # one call
    one = I.intersection_flags(v, f)
    monkeypatch.setattr(T, "THREAD_ROWS", 7)  # many uneven slices
    sliced = I.intersection_flags(v, f)
    assert 100 < one["intersects"].sum() < 2400 and one["coplanar"].sum() >= 600
    for key, flags in one.items():
        assert np.array_equal(np.asarray(flags), np.asarray(sliced[key])), key


def test_the_grid_sorts_cell_keys_as_a_stable_argsort():
    from meshvis.geometry.intersect import _BITS, _stable_key_order

    rng = np.random.default_rng(5)
    for span in (1, 7, 1 << 10, 1 << 21):  # the last spans too many cells for the plain sort
        c = rng.integers(0, span, (3000, 3))
        c[:1000, 0] = c[0, 0]  # runs of equal keys
        c[1000:1500] = c[1000]
        key = (c[:, 0] << (2 * _BITS)) | (c[:, 1] << _BITS) | c[:, 2]
        assert np.array_equal(_stable_key_order(key), np.argsort(key, kind="stable"))
    assert len(_stable_key_order(np.zeros(0, np.int64))) == 0
