"""Sample points of flagged faces by their size: counts, layout, snapping and labels."""

import numpy as np
import pytest
import trimesh

from meshvis import classify
from meshvis.errors import ParameterError
from meshvis.graphcut.nodes import sample_counts, sample_patterns
from meshvis.graphcut.sampling import snap_to_points
from meshvis.rays.samples import sample_scheme_barycentric
from meshvis.repair.orient import POINT_AREA, classify_for_orient, orient


def _coarse_through_fine():
    """A coarse ball (large faces) through a fine one (small faces): both kinds get flagged."""
    fine = trimesh.creation.icosphere(4)
    coarse = trimesh.creation.icosphere(1)
    coarse.vertices = coarse.vertices * 0.9 + [0.8, 0.1, 0.05]
    v = np.vstack([fine.vertices, coarse.vertices])
    f = np.vstack([fine.faces, coarse.faces + len(fine.vertices)])
    return v, f, len(fine.faces)


def test_counts_follow_the_area_relative_to_the_mean_face():
    areas = np.array([0.0, 0.01, 1.0, 2.5, 100.0])  # mean of the faces with an area: 25.8775
    flagged = np.array([True, True, True, True, True])
    assert sample_counts(areas, flagged, 4, 0.04).tolist() == [1, 1, 1, 3, 4]
    assert sample_counts(areas, flagged, 4, None).tolist() == [4] * 5
    # scale-free: the same counts for the model at another size
    assert np.array_equal(
        sample_counts(areas * 1e-12, flagged, 4, 0.04), sample_counts(areas, flagged, 4, 0.04)
    )
    assert sample_counts(areas, np.zeros(5, bool), 4, 1.0).tolist() == []


def test_patterns_are_the_scheme_of_each_count():
    table = sample_patterns(4, 2)
    for c in range(1, 5):
        assert np.array_equal(table[c - 1, :c], sample_scheme_barycentric(c, 2))
        assert not table[c - 1, c:].any()


def test_large_faces_keep_every_point_and_small_ones_one():
    v, f, n_fine = _coarse_through_fine()
    c = classify((v, f), seed=0, point_area=POINT_AREA)
    nodes = c.nodes
    big = nodes.flagged >= n_fine  # the coarse ball's faces: about 10x the mean area
    assert big.any() and (~big).any()
    assert (nodes.point_count[big] == 4).all() and (nodes.point_count[~big] == 1).all()
    assert nodes.n_points == nodes.point_count.sum() == nodes.point_start[-1]
    assert c.report(per_face=False)["sample_points_left_out"] == 4 * len(nodes.flagged) - nodes.n_points > 0
    # every point lies on its face, a one-point face's at its centroid
    one = np.flatnonzero(nodes.point_count == 1)
    tri = c.soup.triangles[nodes.flagged[one]]
    assert np.allclose(nodes.point_pos[nodes.point_start[one]], tri.mean(axis=1))
    # points_of lists each face's points in order
    q = np.array([one[0], np.flatnonzero(big)[0]])
    assert nodes.points_of(q).tolist() == [
        nodes.point_start[q[0]],
        *range(nodes.point_start[q[1]], nodes.point_start[q[1]] + 4),
    ]
    # the answer: the fine ball's part inside the coarse one is hidden, and so is the other way round
    full = classify((v, f), seed=0, point_area=None)
    assert full.nodes.n_points == 4 * len(nodes.flagged)
    agree = c.side_outside == full.side_outside
    assert (c.soup.areas[:, None] * agree).sum() / (2 * c.soup.total_area) > 0.99
    again = classify((v, f), seed=0, point_area=POINT_AREA)
    assert np.array_equal(again.outside, c.outside)  # same input and seed, same output


def test_hits_snap_to_their_faces_own_points():
    v, f, _ = _coarse_through_fine()
    nodes = classify((v, f), seed=0, point_area=POINT_AREA).nodes
    rng = np.random.default_rng(2)
    q = rng.integers(0, len(nodes.flagged), 500)
    pick = rng.integers(0, 1 << 20, 500) % nodes.point_count[q]  # one of the face's points
    p = nodes.point_start[q] + pick
    table = nodes.sample_bary
    bary = table[nodes.point_count[q] - 1, pick][:, 1:]  # the point's own (u, v): it snaps to itself
    assert np.array_equal(snap_to_points(nodes, nodes.flagged[q], bary), p)


def test_point_area_is_checked():
    with pytest.raises(ParameterError, match="point_area"):
        classify(trimesh.creation.icosphere(1), point_area=0.0)
    with pytest.raises(ParameterError, match="point_area"):
        classify(trimesh.creation.icosphere(1), point_area=float("nan"))


def test_classify_keeps_every_point_by_default():
    """``classify``'s default (the cut of the removals and layers) is the full count: every
    flagged face carries ``samples_per_face`` points, with the same labels and rays as
    ``point_area=None``; only orient's cut samples by size."""
    v, f, _ = _coarse_through_fine()
    default, full = classify((v, f), seed=0), classify((v, f), seed=0, point_area=None)
    assert default.nodes.n_points == 4 * len(default.nodes.flagged) > 0
    assert default.report(per_face=False)["sample_points_left_out"] == 0
    for name in ("outside", "side_outside", "flagged"):
        assert np.array_equal(getattr(default, name), getattr(full, name)), name
    assert default.n_rays == full.n_rays and np.array_equal(default.counts.cast, full.counts.cast)
    # the sizes matter on this model: sampled by size, the graph and the rays differ
    by_size = classify((v, f), seed=0, point_area=POINT_AREA)
    assert by_size.nodes.n_points < default.nodes.n_points and by_size.n_rays != default.n_rays
    # orient's cut samples by size, unless told otherwise
    assert classify_for_orient((v, f), seed=0).nodes.n_points == by_size.nodes.n_points
    assert classify_for_orient((v, f), seed=0, point_area=None).nodes.n_points == default.nodes.n_points
    assert orient((v, f), seed=0).flipped.shape == (len(f),)


def test_hits_on_a_face_with_no_node_are_discarded():
    """A face that has neither a cluster node nor sample points (degenerate after welding,
    yet thick enough for Embree to hit) tells nothing: rays that hit it are discarded, not
    linked to another face's sample point."""
    import dataclasses

    from meshvis.graphcut.sampling import VisibilityCounts, sample_round
    from meshvis.rays.caster import RayCaster

    v, f, _ = _coarse_through_fine()
    c = classify((v, f), seed=0)
    nodes = c.nodes
    clustered = np.flatnonzero(nodes.side_node[:, 0] >= 0)
    lost = clustered[np.argmax(c.soup.areas[clustered])]
    side_node = nodes.side_node.copy()
    side_node[lost] = -1
    without = dataclasses.replace(nodes, side_node=side_node)
    caster = RayCaster(c.soup)
    per = np.full(nodes.n, 8, np.int64)
    before = sample_round(caster, nodes, per, np.random.default_rng(1), VisibilityCounts(nodes.n))
    after = sample_round(caster, without, per, np.random.default_rng(1), VisibilityCounts(nodes.n))
    assert after.discarded.sum() > before.discarded.sum()
    assert after.escaped.sum() == before.escaped.sum()
    assert after.hits.sum() + after.discarded.sum() + after.escaped.sum() == after.cast.sum()
