"""From-region visibility on scenes whose answer is known by construction."""

from __future__ import annotations

import json

import numpy as np
import pytest

import meshvis
from meshvis.errors import ParameterError
from meshvis.visibility import parse_region, visible_from
from meshvis.visibility.regions import Box, CameraPath, Outside, Points, UpperHemisphere


def test_guided_sampling_sees_every_inner_side_through_a_slot_and_not_the_tops_underside(scenes):
    soup, strip, truth = scenes.slot_box()
    vis = visible_from(soup, seed=0, budget=200_000, per_side=True)
    np.testing.assert_array_equal(vis.seen_side, truth)
    assert vis.seen_side[strip, 1].all()  # the strip seen only at grazing angles
    # per face (the default) it stops early, and never claims an unseen side
    fast = visible_from(soup, seed=0, budget=200_000)
    assert fast.seen.all() and not (fast.seen_side & ~truth).any()
    assert fast.rays["total"] < vis.rays["total"]


def test_the_slot_strip_is_found_by_propagation_with_few_seed_rays(scenes):
    soup, strip, truth = scenes.slot_box()
    vis = visible_from(soup, seed=3, budget=20_000, per_side=True)
    assert vis.seen_side[strip, 1].all()
    assert vis.rays["border"] > 0


def test_a_large_triangle_passing_into_a_closed_box_is_seen_on_both_sides(scenes):
    soup, truth = scenes.pierced_box()
    for method in ("guided", "random"):
        vis = visible_from(soup, seed=1, method=method, budget=100_000, per_side=True)
        np.testing.assert_array_equal(vis.seen_side, truth)


def test_a_sealed_pocket_between_parts_is_never_seen(scenes):
    soup, bottom, truth = scenes.sealed_pocket()
    vis = visible_from(soup, seed=0, budget=100_000, per_side=True)
    np.testing.assert_array_equal(vis.seen_side, truth)
    assert not visible_from(soup, seed=0, budget=100_000).seen[bottom].any()


def test_outside_sees_the_front_of_every_cube_face_and_no_back(scenes):
    cube, _ = scenes.unit_cube()
    vis = visible_from(cube, "outside", seed=0, per_side=True, budget=20_000)
    assert vis.seen_side[:, 0].all() and not vis.seen_side[:, 1].any()
    assert vis.stopped in ("few new faces", "few unseen pixels", "all seen", "budget", "rounds done")


def test_upper_hemisphere_does_not_see_the_bottom(scenes):
    cube, names = scenes.unit_cube()
    vis = visible_from(cube, "upper-hemisphere", up=(0, 0, 1), seed=0, budget=50_000)
    np.testing.assert_array_equal(vis.seen_side[:, 0], names != "-z")
    assert not vis.seen_side[:, 1].any()
    # the up vector may also come with the text, here +x: the -x face is the bottom
    vis = visible_from(cube, "upper-hemisphere:1,0,0", seed=0, budget=50_000)
    np.testing.assert_array_equal(vis.seen_side[:, 0], names != "-x")


def test_a_box_region_inside_a_closed_cube_sees_only_inner_sides(scenes):
    cube, _ = scenes.unit_cube()
    vis = visible_from(cube, "box:-0.2,-0.2,-0.2,0.2,0.2,0.2", seed=0, per_side=True)
    assert vis.seen_side[:, 1].all() and not vis.seen_side[:, 0].any()


def test_faces_inside_a_box_region_are_seen_without_rays(scenes):
    cube, names = scenes.unit_cube()
    vis = visible_from(cube, "box:0.4,-1,-1,1,1,1", seed=0, budget=10_000)
    inside = names != "-x"  # every face but -x reaches into the box
    assert vis.seen_side[inside].all()
    assert vis.skipped["inside the region (seen without rays)"] == 10


def test_a_point_in_front_of_one_face_sees_that_face_only(scenes):
    cube, names = scenes.unit_cube()
    vis = visible_from(cube, "points:5,0,0", seed=0, budget=20_000)
    np.testing.assert_array_equal(vis.seen_side[:, 0], names == "+x")
    assert not vis.seen_side[:, 1].any()
    assert vis.rays["reverse"] == 0  # a fixed point cannot move


def test_a_camera_path_around_a_corner_sees_the_two_faces_it_passes(scenes, tmp_path):
    cube, names = scenes.unit_cube()
    path = tmp_path / "path.json"
    path.write_text(json.dumps([{"position": [5, 0, 0]}, {"position": [0, 5, 0]}]))
    vis = visible_from(cube, f"path:{path}", seed=0, budget=20_000)
    np.testing.assert_array_equal(vis.seen_side[:, 0], np.isin(names, ["+x", "+y"]))


def test_same_seed_gives_identical_results_and_the_history_grows(scenes):
    soup, _, _ = scenes.slot_box()
    a = visible_from(soup, seed=5, budget=30_000)
    b = visible_from(soup, seed=5, budget=30_000)
    np.testing.assert_array_equal(a.seen_side, b.seen_side)
    np.testing.assert_array_equal(a.rays_seen, b.rays_seen)
    assert a.rays == b.rays and a.history["rays"] == b.history["rays"]
    assert np.all(np.diff(a.history["rays"]) >= 0) and np.all(np.diff(a.history["visible_area"]) >= 0)
    assert a.rays["total"] <= 30_000 + 64 * 200  # the budget, give or take one propagation batch


def test_the_budget_is_respected_and_said(scenes):
    soup, _, _ = scenes.slot_box()
    vis = visible_from(soup, seed=0, budget=50, method="random")
    assert vis.rays["total"] <= 50 and vis.stopped == "budget"


def test_region_parsing():
    assert isinstance(parse_region("outside"), Outside)
    assert isinstance(parse_region("upper-hemisphere"), UpperHemisphere)
    box = parse_region("box:0,1,2,3,4,5")
    assert isinstance(box, Box) and box.lo.tolist() == [0, 1, 2] and box.hi.tolist() == [3, 4, 5]
    assert isinstance(parse_region("points:1,2,3"), Points)
    for bad in (
        "inside",
        "box:1,2,3",
        "box:1,1,1,0,0,0",
        "points:",
        "path:/nonexistent.json",
        "upper-hemisphere:0,0,0",
    ):
        with pytest.raises(ParameterError):
            parse_region(bad)
    assert issubclass(CameraPath, Points)


def test_bad_arguments_are_parameter_errors(scenes):
    cube, _ = scenes.unit_cube()
    with pytest.raises(ParameterError):
        visible_from(cube, method="exact")
    with pytest.raises(ParameterError):
        visible_from(cube, budget=-1)


def test_public_api():
    assert meshvis.visible_from is visible_from
    assert meshvis.parse_region is parse_region


def test_the_default_budget_is_a_cap_that_the_stop_rule_ends_before(scenes, monkeypatch):
    from meshvis import limits
    from meshvis.visibility.visible import DEFAULT_MIN_BUDGET, MAX_RAYS_PER_FACE, default_budget

    assert default_budget(10) == DEFAULT_MIN_BUDGET
    assert default_budget(10_000) == MAX_RAYS_PER_FACE * 10_000
    assert default_budget(10**9) == limits.MAX_RAYS
    monkeypatch.setattr(limits, "MAX_RAYS", 1000)
    assert default_budget(10) == 1000  # the cap is read at call time
    monkeypatch.undo()
    soup, strip, truth = scenes.slot_box()
    vis = visible_from(soup, seed=0, per_side=True)
    assert vis.stopped in ("few new faces", "little new area", "few unseen pixels", "all seen")
    np.testing.assert_array_equal(vis.seen_side, truth)


def test_every_round_seeds_the_unseen_faces_in_a_random_order():
    """A random order makes every window of the stop rule a fair sample of its round, whatever
    the size of the faces (an order by size judged rounds by their largest faces)."""
    from meshvis.visibility.visible import _round_order, _State

    soup = meshvis.as_soup((np.random.default_rng(0).random((300, 3)), np.arange(300).reshape(100, 3)))
    state = _State(soup, 100, 50.0, 1e-4)
    rng = np.random.default_rng(0)
    todo = np.ones(100, bool)
    todo[::7] = False
    orders = [_round_order(state, rng, todo, r) for r in (1, 1, 2)]
    for order in orders:
        assert sorted(order.tolist()) == np.flatnonzero(todo).tolist()
    assert orders[0].tolist() != orders[1].tolist()
    by_size = np.argsort(-soup.areas[orders[0]])
    assert by_size.tolist() != list(range(len(by_size)))


def test_the_stop_rule_is_confirmed_on_the_next_rounds_largest_faces(monkeypatch):
    import trimesh

    from meshvis.visibility import visible

    # a ball of 80 faces sealed in a cube: the ball is never seen, so the stop rule ends the
    # search, and it holds first in the round of 256 seeds per face (not the last round)
    cube, ball = trimesh.creation.box(extents=(2, 2, 2)), trimesh.creation.icosphere(1, radius=0.5)
    soup = meshvis.as_soup(trimesh.util.concatenate([cube, ball]))
    inner = np.arange(12, soup.n_faces)
    monkeypatch.setattr(visible, "LINES_PER_SEED_RAY", 0)  # the seeds' own rule, without view lines
    once = {}
    for confirm in (False, True):
        monkeypatch.setattr(visible, "CONFIRM_NEXT_ROUND", confirm)
        once[confirm] = visible_from(soup, seed=3)
    first, confirmed = once[False], once[True]
    assert first.stopped in ("few new faces", "little new area") and confirmed.stopped == first.stopped
    assert (first.seed_rays[inner] < sum(visible.SEED_ROUNDS)).all()
    # the confirmed search is the first one and then the next round's first window
    assert confirmed.rays["total"] > first.rays["total"]
    assert (confirmed.seed_rays[inner] > first.seed_rays[inner]).all()
    seen = first.first_seen >= 0
    np.testing.assert_array_equal(confirmed.first_seen[seen], first.first_seen[seen])
    assert confirmed.seen[:12].all() and not confirmed.seen[inner].any()


def test_view_lines_are_framed_on_the_bounding_box_and_start_in_a_box_region():
    import trimesh

    from meshvis.visibility.sampling import view_lines

    rng = np.random.default_rng(0)
    square = trimesh.Trimesh([[0, 0, 0], [10, 0, 0], [10, 10, 0], [0, 10, 0.0]], [[0, 1, 2], [0, 2, 3]])
    flat = meshvis.as_soup(square)
    region = parse_region("outside").bind(flat)
    found, hits = view_lines(meshvis.RayCaster(flat), region, 4000, rng)
    # a flat square fills much of its box's shadow; the bounding sphere's disk it fills to a third
    assert hits > 0.6 * 4000 and len(found.face) == hits
    box = parse_region("box:1,1,1,2,2,2").bind(flat)
    origin, direction = box.view_lines(100, rng)
    assert ((origin >= 1) & (origin <= 2)).all() and np.allclose(np.linalg.norm(direction, axis=1), 1)


def test_view_lines_end_the_search_when_they_find_few_unseen_faces():
    import trimesh

    cube, ball = trimesh.creation.box(extents=(2, 2, 2)), trimesh.creation.icosphere(2, radius=0.5)
    sealed = visible_from(meshvis.as_soup(trimesh.util.concatenate([cube, ball])), seed=0)
    assert sealed.stopped == "few unseen pixels" and sealed.rays["lines"] > 0
    assert sealed.seen[:12].all() and not sealed.seen[12:].any()


class _Stop(Exception):
    pass


def test_the_search_by_sight_reports_progress_and_stops_when_told(scenes, tmp_path):
    """remove_interior's default search tells its progress (through the library call and the
    command's operation), never going back, and an exception from the callback stops it."""
    from meshvis.repair.operation import run_operation

    soup, _, _ = scenes.slot_box()
    told: list[tuple[str, float]] = []
    meshvis.remove_interior(soup, seed=0, progress=lambda stage, f: told.append((stage, f)))
    assert told and {stage for stage, _ in told} == {"sight"}
    fractions = [f for _, f in told]
    assert fractions == sorted(fractions) and fractions[0] >= 0 and fractions[-1] <= 1
    by_command: list[str] = []
    out = str(tmp_path / "kept.obj")
    run_operation(
        "remove-interior", soup, {"output": out}, progress=lambda stage, f: by_command.append(stage)
    )
    assert "sight" in by_command

    def stop(stage, fraction):
        raise _Stop

    with pytest.raises(_Stop):
        meshvis.remove_interior(soup, seed=0, progress=stop)
