"""Conservative from-point visibility on scenes whose answer is known by construction.

The conservative set must hold every face a point sees (nothing visible is ever left out)
and, on these scenes, nothing more than the construction says.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

import meshvis
from meshvis.cli.main import main
from meshvis.errors import ModelError, ParameterError
from meshvis.visibility.conservative import FrustumScene, conservative_from, sample_frusta, sample_views
from meshvis.visibility.viewpoints import parse_viewpoints

# the faces of these scenes are large: a few levels of frusta are enough, and fast
LEVEL = 7


def quad_x(x0, x1, y0, y1, z):
    """Two triangles sharing their diagonal: the rectangle [x0, x1] x [y0, y1] at height z, front +z."""
    a, b, c, d = (x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z)
    return [[a, b, c], [a, c, d]]


def soup_from(triangles) -> meshvis.Soup:
    """A soup whose faces share the corners they have in common (exact duplicates merged)."""
    tri = np.asarray(triangles, np.float64).reshape(-1, 3)
    vertices, faces = np.unique(tri, axis=0, return_inverse=True)
    return meshvis.Soup(vertices, faces.reshape(-1, 3))


def sides(result, scene_faces) -> np.ndarray:
    return result.visible_side[scene_faces]


@pytest.mark.slow
def test_a_point_in_a_closed_box_may_see_only_the_inner_sides(scenes):
    cube, _ = scenes.unit_cube()  # fronts out
    for point in ("0,0,0", "0.31,-0.2,0.07"):
        c = conservative_from(cube, f"points:{point}", max_level=LEVEL)
        assert c.visible_side[:, 1].all(), point  # every inner side
        assert not c.visible_side[:, 0].any(), point  # no outer side
        assert c.frusta["open"] == 0  # the walls block every frustum


def test_a_slit_shows_what_is_behind_it_and_the_wall_hides_the_rest():
    # a wall at z = 1 with a slit |x| < 0.1, and a back wall of strips 0.4 wide at z = 3
    wall = quad_x(-5, -0.1, -5, 5, 1) + quad_x(0.1, 5, -5, 5, 1)
    edges = np.arange(-5.0, 5.0 + 1e-9, 0.4)
    strips = [t for x0, x1 in zip(edges[:-1], edges[1:]) for t in quad_x(x0, x1, -5, 5, 3)]
    soup = soup_from(wall + strips)
    c = conservative_from(soup, "points:0,0,0", max_level=LEVEL)
    # rays through the slit reach the back wall at |x| < 0.3
    centre_x = soup.triangles[len(wall) :, :, 0].mean(axis=1)
    strip_lo = np.repeat(edges[:-1], 2)
    strip_hi = np.repeat(edges[1:], 2)
    behind_slit = (strip_hi > -0.3) & (strip_lo < 0.3)
    assert behind_slit.sum() == 6 and centre_x[behind_slit].max() < 0.6
    np.testing.assert_array_equal(c.visible[len(wall) :], behind_slit)
    assert c.visible[: len(wall)].all()
    # the point is below every face: it sees their backs (fronts face +z)
    assert not c.visible_side[:, 0].any()


def test_two_coplanar_triangles_sharing_an_edge_block_together_and_a_gap_between_them_does_not():
    blocker = quad_x(-1, 1, -1, 1, 1)  # the diagonal crosses the view's centre
    hidden = [[(-1.0, -1.0, 2.0), (1.6, -1.0, 2.0), (-1.0, 1.6, 2.0)]]  # all of it behind the square
    soup = soup_from(blocker + hidden)
    c = conservative_from(soup, "points:0,0,0", max_level=LEVEL)
    assert c.visible.tolist() == [True, True, False]
    assert not c.at_limit.any()  # blockers keep the square, nothing else is kept
    # the same square with a crack along its diagonal: the triangle is seen through it
    (a, b, cc), (a2, c2, d) = np.asarray(blocker)
    shift = np.array([-1e-3, 1e-3, 0.0])  # moves the second triangle off the diagonal
    cracked = soup_from([[a, b, cc], [a2 + shift, c2 + shift, d + shift]] + hidden)
    c = conservative_from(cracked, "points:0,0,0", max_level=LEVEL)
    assert c.visible.tolist() == [True, True, True]
    # only the frusta along the crack, at the subdivision limit, keep what is behind it
    assert c.at_limit.tolist() == [False, False, True]


# occluder fusion: a frustum at the subdivision limit without one connected blocker, covered
# by the union of the triangles that meet it.  Seen from the origin up +z; the far triangle
# spans x/z in [-0.3, 0.3] and y/z in [-0.1, 0.1]; the covers meet along x/z = 0.1 within
# one frustum of the limit, so no frustum there has a single blocker.
BEHIND = [[(-1.2, -0.4, 4.0), (1.2, -0.4, 4.0), (0.0, 0.4, 4.0)]]
LEFT = [(-10, -10, 1), (0.1, -10, 1), (0.1, 10, 1)]  # x/z up to 0.1


def strip(p, q):
    """Two triangles joining the lines (x0, y, z0) and (x1, y, z1), |y| <= 5."""
    (x0, z0), (x1, z1) = p, q
    a, b, c, d = (x0, -5, z0), (x1, -5, z1), (x1, 5, z1), (x0, 5, z0)
    return [[a, b, c], [a, c, d]]


def test_two_separate_triangles_that_cover_a_view_together_hide_what_is_behind_them():
    right = [(0.198, -10, 2), (20, 10, 2), (0.198, 10, 2)]  # from x/z = 0.099, further away
    soup = soup_from([LEFT, right] + BEHIND)
    c = conservative_from(soup, "points:0,0,0", max_level=LEVEL)
    assert c.visible.tolist() == [True, True, False]
    assert c.frusta["fused"] > 0 and c.parameters["fusion"]
    # without fusion the frusta along the seam keep it, as FastV does
    off = conservative_from(soup, "points:0,0,0", max_level=LEVEL, fusion=False)
    assert off.visible.tolist() == [True, True, True] and off.frusta["fused"] == 0
    assert off.frusta["open"] == c.frusta["open"]


def test_a_hairline_gap_between_two_triangles_shows_what_is_behind_it():
    # the second triangle starts 1e-13 after the first ends, in the same plane: rays pass
    # between them, however thin the gap (fusion's margins widen it, never close it)
    right = [(0.1 + 1e-13, -10, 1), (20, 10, 1), (0.1 + 1e-13, 10, 1)]
    soup = soup_from([LEFT, right] + BEHIND)
    c = conservative_from(soup, "points:0,0,0", max_level=LEVEL)
    assert c.visible.tolist() == [True, True, True]
    assert c.at_limit.tolist() == [False, False, True]


def test_a_part_folded_over_itself_hides_what_is_behind_the_fold():
    # one connected strip: near at z = 1 up to x/z = 0.2, folded back to x/z = 0.199, folded
    # again and on, further away: each fold is a silhouette that no blocker crosses
    fold = strip((-1, 1), (0.2, 1)) + strip((0.2, 1), (0.2985, 1.5)) + strip((0.2985, 1.5), (2, 2.5))
    soup = soup_from(fold + BEHIND)
    assert len(np.unique(soup.faces[:6])) == 8  # one part, its corners shared
    c = conservative_from(soup, "points:0,0,0", max_level=LEVEL)
    assert c.visible.tolist() == [True] * 6 + [False]
    assert c.frusta["fused"] > 0
    off = conservative_from(soup, "points:0,0,0", max_level=LEVEL, fusion=False)
    assert off.visible.tolist() == [True] * 7


@pytest.mark.slow
def test_a_grazing_view_over_a_floor_keeps_what_stands_on_it_and_not_what_lies_under_it():
    floor = quad_x(-100, 100, -100, 100, 0)
    above = [[(50, -1, 0.005), (51, 1, 0.005), (50, 1, 0.02)]]  # seen 0.01 below the horizon
    under = [[(50, -1, -0.01), (51, 1, -0.01), (50, 1, -0.005)]]  # a hair under the floor
    soup = soup_from(floor + above + under)
    c = conservative_from(soup, "points:0,0,0.01", max_level=10)
    assert c.visible.tolist() == [True, True, True, False]
    assert c.visible_side[:2].tolist() == [[True, False], [True, False]]
    # a point exactly in the floor's plane may see both of its sides
    c = conservative_from(soup, "points:0,0,0", max_level=8)
    assert c.visible_side[:2].all()


@pytest.mark.slow
def test_the_set_holds_every_face_that_random_rays_see(scenes):
    # random triangles: no connectivity, many small blockers, grazing overlaps
    rng = np.random.default_rng(7)
    centres = rng.uniform(-1, 1, (300, 1, 3))
    soup = soup_from(centres + 0.25 * rng.standard_normal((300, 3, 3)))
    scene = FrustumScene.build(soup)
    for point in ("0,0,0", "0.4,-0.3,0.2", "3,1,-2"):
        c = conservative_from(soup, f"points:{point}", max_level=9, scene=scene)
        seen = sample_views(scene, parse_viewpoints(f"points:{point}"), 200_000, rng)
        assert not (seen & ~c.visible_side).any(), point
        assert c.visible_side.sum() < 2 * len(c.area)  # something is hidden, each face once


@pytest.mark.parametrize("scale", [1e-6, 1.0, 1e6])
def test_the_answer_does_not_change_with_scale_or_a_far_translation(scenes, scale):
    cube, _ = scenes.unit_cube()
    wall = soup_from(quad_x(-5, -0.1, -5, 5, 1) + quad_x(0.1, 5, -5, 5, 1) + quad_x(-5, 5, -5, 5, 3))
    base = [conservative_from(s, "points:0.1,0.05,0.2", max_level=LEVEL).visible_side for s in (cube, wall)]
    for shift in (0.0, 1e7 * scale):
        for soup, expect in zip((cube, wall), base):
            moved = meshvis.Soup(soup.vertices * scale + shift, soup.faces)
            point = np.array([0.1, 0.05, 0.2]) * scale + shift
            c = conservative_from(moved, "points:" + ",".join(map(repr, point.tolist())), max_level=LEVEL)
            np.testing.assert_array_equal(c.visible_side, expect)


def test_a_point_a_hair_from_a_wall_keeps_the_walls_inner_sides_and_only_that_walls_outer_side(scenes):
    cube, names = scenes.unit_cube()
    c = conservative_from(cube, "points:0.1,0.2,0.4999999999", max_level=LEVEL)
    assert c.visible_side[:, 1].all()
    assert not c.visible_side[names != "+z", 0].any()  # the +z wall: within the margin, both sides


def test_a_camera_sees_only_what_is_in_its_view(tmp_path, scenes):
    cube, names = scenes.unit_cube()
    path = tmp_path / "cameras.json"
    path.write_text(json.dumps([{"position": [0, 0, 0], "target": [0, 0, 1], "fov": 60}, [0, 0, 0.3]]))
    views = parse_viewpoints(f"path:{path}")
    assert [v.everywhere for v in views] == [False, True]
    c = conservative_from(cube, f"path:{path}", max_level=LEVEL)
    np.testing.assert_array_equal(c.point_side(0)[:, 1], names == "+z")
    assert c.point_side(1)[:, 1].all() and c.visible_side[:, 1].all()


def test_same_input_same_output_whatever_the_threads(monkeypatch, scenes):
    soup, _, _ = scenes.slot_box()
    a = conservative_from(soup, "points:0.5,0.5,2;0.2,0.3,0.4", max_level=9)
    monkeypatch.setenv("MESHVIS_THREADS", "1")
    b = conservative_from(soup, "points:0.5,0.5,2;0.2,0.3,0.4", max_level=9)
    np.testing.assert_array_equal(a.visible_side, b.visible_side)
    for fa, fb in zip(a.point_faces, b.point_faces):
        np.testing.assert_array_equal(fa, fb)
    assert a.frusta["traced"] == b.frusta["traced"]


def test_regions_without_viewpoints_and_bad_levels_are_refused(scenes):
    cube, _ = scenes.unit_cube()
    for region in ("outside", "box:0,0,0,1,1,1", "upper-hemisphere"):
        with pytest.raises(ParameterError, match="points"):
            conservative_from(cube, region)
    with pytest.raises(ParameterError, match="max_level"):
        conservative_from(cube, "points:0,0,0", base_level=5, max_level=3)


def test_an_empty_model_is_refused_and_a_single_triangle_is_seen_from_its_side():
    with pytest.raises(ModelError):
        conservative_from((np.zeros((0, 3)), np.zeros((0, 3), np.int64)), "points:0,0,0")
    one = soup_from([[(0, 0, 1), (1, 0, 1), (0, 1, 1)]])
    assert conservative_from(one, "points:0.2,0.2,0", max_level=LEVEL).visible_side.tolist() == [
        [False, True]
    ]
    assert conservative_from(one, "points:0.2,0.2,2", max_level=LEVEL).visible_side.tolist() == [
        [True, False]
    ]


def test_visible_from_brackets_the_guided_search(scenes):
    soup, _, _ = scenes.slot_box()
    vis = meshvis.visible_from(soup, "points:0.5,0.5,1.5", conservative=True, budget=100_000)
    assert vis.conservative is not None
    assert not (vis.seen_side & ~vis.conservative.visible_side).any()
    r = vis.report(per_face=False)["conservative"]
    assert r["outside"] == 0 and r["conservative_faces"] >= r["sampled_faces"] > 0
    assert r["bracket_faces"] == r["conservative_faces"] - r["sampled_faces"]


def test_the_command_line_reports_the_bracket_and_removes_only_what_is_surely_hidden(tmp_path, scenes):
    cube, _ = scenes.unit_cube()
    inner = soup_from(np.asarray(cube.triangles) * 0.5)  # a smaller cube inside, hidden from outside
    both = meshvis.Soup.concatenate([cube, inner])
    src, out, rep = tmp_path / "two.ply", tmp_path / "out.ply", tmp_path / "r.json"
    meshvis.save(both, str(src))
    args = ["visible", str(src), "--from", "points:3,2,1", "--conservative", "--max-level", "8"]
    assert main([*args, "--report", str(rep), "-q"]) == 0
    r = json.loads(rep.read_text())["conservative"]
    assert r["outside"] == 0 and r["conservative_faces"] <= 12 and r["frusta"] > 0
    args = ["remove-interior", str(src), "-o", str(out), "--from", "points:3,2,1", "--conservative"]
    assert main([*args, "--report", str(rep), "-q", "--force"]) == 0
    r = json.loads(rep.read_text())
    assert r["visibility"] == "conservative" and r["removed_faces"] >= 12  # the inner cube at least
    assert main(["visible", str(src), "--from", "outside", "--conservative", "-q"]) == 2


def test_cameras_with_views_bracket_rays_in_their_views(tmp_path, scenes):
    cube, names = scenes.unit_cube()
    path = tmp_path / "cameras.json"
    path.write_text(json.dumps({"cameras": [{"position": [0, 0, 0], "target": [1, 0, 0], "fov": 40}]}))
    vis = meshvis.visible_from(cube, f"path:{path}", conservative=True, budget=20_000)
    assert vis.method == "random rays in the views" and vis.rays["total"] == 20_000
    np.testing.assert_array_equal(vis.seen, names == "+x")  # both +x triangles, nothing else
    assert vis.report(per_face=False)["conservative"]["outside"] == 0
    np.testing.assert_array_equal(vis.conservative.visible, names == "+x")


def test_a_sliver_thinner_than_the_margin_that_a_ray_hits_stays_in_the_set():
    # a sliver 1e-9 wide (far below the tests' margin of about 1e-5) facing the point, in front
    # of a back wall: a ray aimed at it hits it first, so it may be seen
    sliver = [[(-0.5, 0.0, 1.0), (0.5, 0.0, 1.0), (0.0, 1e-9, 1.0)]]
    soup = soup_from(sliver + quad_x(-5, 5, -5, 5, 3))
    scene = FrustumScene.build(soup)
    d = np.array([[0.0, 0.5e-9, 1.0]])
    assert int(scene.caster.intersect(np.zeros((1, 3)), d / np.linalg.norm(d)).face[0]) == 0
    c = conservative_from(soup, "points:0,0,0", max_level=LEVEL, scene=scene)
    assert c.visible_side[0, 1]  # its back side faces the point (its corners lie on one line: both)
    assert c.visible_side[1:, 1].all() and not c.visible_side[1:, 0].any()  # the wall around it


def test_a_tiny_face_seen_from_afar_nearly_in_its_plane_is_kept_with_both_sides():
    # a triangle 1e-4 across, 0.05 away, the point 4e-6 in front of its plane: rounding its
    # corners by the margin (about 5e-8 here) can tilt the plane past the point
    from meshvis.visibility.conservative import facing_sides

    tri = np.array([[[0.05, 0.0, 0.0], [0.05, 1e-4, 0.0], [0.05 + 1e-4, 0.0, 0.0]]])
    point = np.array([0.0, 0.0, 4e-6])
    assert facing_sides(tri, point, 5e-8).tolist() == [2]
    assert facing_sides(tri, np.array([0.0, 0.0, 0.01]), 5e-8).tolist() == [1]  # clearly off it


def test_rays_through_the_open_frusta_see_only_what_the_set_holds_and_repeat_with_the_seed():
    # a wall with a slit 0.02 wide: frusta along the slit's edges stay open at the limit
    wall = quad_x(-5, -0.01, -5, 5, 1) + quad_x(0.01, 5, -5, 5, 1)
    edges = np.arange(-5.0, 5.0 + 1e-9, 0.4)
    soup = soup_from(wall + [t for x0, x1 in zip(edges[:-1], edges[1:]) for t in quad_x(x0, x1, -5, 5, 3)])
    scene = FrustumScene.build(soup)
    c = conservative_from(soup, "points:0,0,0", max_level=LEVEL, scene=scene)
    roots, root, box = c.open_frusta[0]
    assert len(root) == c.frusta["open"] > 0 and box.shape == (len(root), 4)
    seen = [
        sample_frusta(scene, np.zeros(3), c.open_frusta[0], 4, np.random.default_rng(3)) for _ in range(2)
    ]
    assert (seen[0] == seen[1]).all()
    assert seen[0][len(wall) :].any()  # through the slit, the back wall
    assert not (seen[0] & ~c.visible_side).any()


def test_hits_are_counted_only_when_a_float64_trace_meets_the_same_face_first():
    from meshvis.visibility.conservative import confirm_hits

    # a near wall (faces 0, 1) in front of a far wall (faces 2, 3), seen from below
    soup = soup_from(quad_x(-1, 1, -1, 1, 1) + quad_x(-2, 2, -2, 2, 3))
    scene = FrustumScene.build(soup)
    d = np.array([[0.1, 0.2, 1.0], [0.3, -0.1, 1.0]])
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    face = scene.caster.intersect(np.zeros((2, 3)), d).face
    assert set(face.tolist()) <= {0, 1}
    seen = np.zeros((4, 2), bool)
    # the true hits, and the same rays claimed to reach the far wall (as a leak would)
    confirm_hits(scene, np.zeros(3), np.r_[d, d], np.r_[face, [2, 3]], np.ones(4, np.int64), seen)
    assert seen[:, 1].tolist() == [f in face for f in range(4)] and not seen[:, 0].any()
