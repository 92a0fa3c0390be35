"""Inside removal by sight: visibility object | view | both, levels, kept borders, reasons."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from meshvis.cli.main import main
from meshvis.errors import ParameterError
from meshvis.io import load, save
from meshvis.repair.remove import REASONS, remove_interior

MODELS = Path(__file__).resolve().parents[2] / "models"


def test_view_removes_exactly_the_sealed_pocket(scenes):
    soup, bottom, truth = scenes.sealed_pocket()
    r = remove_interior(soup, visibility="view", seed=0, budget=100_000)
    np.testing.assert_array_equal(r.keep, truth.any(axis=1))
    assert r.classification is None and r.removed.n_faces == len(bottom)
    assert set(r.reason) == {"kept: seen from the region", "removed: not seen from the region"}


def test_both_keeps_a_large_triangle_passing_into_a_closed_box(scenes):
    soup, truth = scenes.pierced_box()
    r = remove_interior(soup, visibility="both", seed=0, budget=100_000)
    assert r.keep[12]  # the triangle shows a tip outside the box
    assert r.keep.all()  # the box itself is all outside
    obj = remove_interior(soup, visibility="object", seed=0)
    assert not (r.keep < obj.keep).any()  # both never removes what object keeps


def test_view_is_the_default_of_the_library_cli_and_batch(scenes):
    import inspect

    from meshvis.repair.operation import default_options
    from meshvis.repair.remove_modes import DEFAULT_VISIBILITY

    assert DEFAULT_VISIBILITY == "view"
    assert inspect.signature(remove_interior).parameters["visibility"].default == DEFAULT_VISIBILITY
    assert default_options("remove-interior")["visibility"] == DEFAULT_VISIBILITY
    soup, _, _ = scenes.slot_box()
    a = remove_interior(soup, seed=0, budget=100_000)
    b = remove_interior(soup, seed=0, budget=100_000, visibility="view")
    np.testing.assert_array_equal(a.keep, b.keep)
    assert a.mode == "view" and a.visibility is not None and a.classification is None
    obj = remove_interior(soup, seed=0, visibility="object")
    assert obj.mode == "object" and obj.visibility is None


def test_part_level_keeps_a_part_with_one_seen_face(scenes):
    soup, bottom, truth = scenes.sealed_pocket()
    by_face = remove_interior(soup, visibility="view", seed=0, budget=100_000)
    by_part = remove_interior(soup, visibility="view", level="part", seed=0, budget=100_000)
    assert by_face.removed.n_faces == 2 and by_part.removed.n_faces == 0
    assert by_part.reason[bottom[0]] == "kept: its patch or part has a face that is kept"


def test_patch_level_and_keep_border(scenes):
    cube, names = scenes.unit_cube()
    # viewers at one point in front of +x see only that face; the rest is one welded patch
    r = remove_interior(cube, visibility="view", region="points:5,0,0", seed=0, budget=20_000)
    assert r.keep.sum() == 2
    assert remove_interior(cube, visibility="view", region="points:5,0,0", level="patch", seed=0).keep.all()
    ring = remove_interior(cube, visibility="view", region="points:5,0,0", keep_border=1, seed=0)
    # one ring: each of the 4 edges of the +x square borders one triangle of a side face
    assert ring.keep.sum() == 6 and not ring.keep[names == "-x"].any()
    two = remove_interior(cube, visibility="view", region="points:5,0,0", keep_border=2, seed=0)
    assert two.keep.sum() > 6
    assert "kept: next to a kept face (keep_border)" in ring.reason


def test_bad_removal_arguments(scenes):
    cube, _ = scenes.unit_cube()
    for kw in ({"visibility": "sight"}, {"level": "object"}, {"keep_border": -1}):
        with pytest.raises(ParameterError):
            remove_interior(cube, **kw)
    assert len(REASONS) == 11
    with pytest.raises(ParameterError, match="transparent"):
        remove_interior(cube, transparent="glass")
    with pytest.raises(ParameterError, match="check_rays"):
        remove_interior(cube, check_rays=-1)
    with pytest.raises(ParameterError, match="rescue_rays"):
        remove_interior(cube, rescue_rays=-1)


def test_cli_flags_of_remove_interior_and_visible(scenes, tmp_path, capsys):
    soup, bottom, truth = scenes.sealed_pocket()
    src = tmp_path / "pocket.obj"
    save(soup, str(src))
    out, rep = tmp_path / "kept.obj", tmp_path / "r.json"
    argv = ["remove-interior", str(src), "-o", str(out), "--report", str(rep), "-q", "--visibility", "view"]
    assert main(argv + ["--from", "outside", "--level", "face", "--keep-border", "0"]) == 0
    report = json.loads(rep.read_text())
    assert report["visibility"] == "view" and report["removed_faces"] == 2
    assert len(report["per_face"]["reason"]) == soup.n_faces
    assert load(str(out)).n_faces == soup.n_faces - 2
    assert main(argv + ["--level", "part", "--force"]) == 0
    assert json.loads(rep.read_text())["removed_faces"] == 0
    assert main(argv + ["--from", "box:1,2", "--force"]) == 2
    assert "expected 6 comma-separated numbers" in capsys.readouterr().err
    vis_rep, png = tmp_path / "v.json", tmp_path / "v.png"
    assert (
        main(
            ["visible", str(src), "--report", str(vis_rep), "--preview", str(png), "-q", "--budget", "50000"]
        )
        == 0
    )
    v = json.loads(vis_rep.read_text())
    seen = np.array(v["per_face"]["seen_front"]) | np.array(v["per_face"]["seen_back"])
    np.testing.assert_array_equal(seen, truth.any(axis=1))
    assert png.stat().st_size > 1000
    assert (
        main(["visible", str(src), "--from", "upper-hemisphere", "--up", "z", "--method", "random", "-q"])
        == 0
    )
    assert main(["visible", str(src), "--from", "nowhere", "-q"]) == 2


def test_both_searches_only_around_the_faces_the_cut_calls_hidden(scenes):
    soup, bottom, truth = scenes.sealed_pocket()
    r = remove_interior(soup, visibility="both", seed=0)
    by_cut = r.reason_code == REASONS.index("kept: an outside side by the cut")
    assert (~by_cut).any() and (r.visibility.seed_rays[by_cut] == 0).all()
    assert r.visibility.skipped["not asked about (no seed rays)"] == int(by_cut.sum())
    assert any(k.startswith("not propagated from") for k in r.visibility.skipped)
    # a cube the cut keeps whole: nothing to ask about, not one ray
    cube, _ = scenes.unit_cube()
    whole = remove_interior(cube, visibility="both", seed=0)
    assert whole.keep.all() and whole.visibility.rays["total"] == 0


def test_both_searches_the_cuts_scene_as_a_scene_of_its_own(monkeypatch):
    import meshvis.repair.remove as remove
    from meshvis.rays.caster import VISIBILITY_OFFSET
    from meshvis.visibility import visible_from

    used = []

    def spy(*args, **kwargs):
        used.append(kwargs["caster"])
        return visible_from(*args, **kwargs)

    monkeypatch.setattr(remove, "visible_from", spy)
    soup = load(MODELS / "assembly.obj")
    r = remove_interior(soup, seed=0, visibility="both")
    # the cut's Embree scene, with the search's own ray offset
    assert used[0]._scene is r.classification.caster._scene and used[0].offset == VISIBILITY_OFFSET
    by_cut = r.reason_code == REASONS.index("kept: an outside side by the cut")
    # a search of its own, on a scene built anew
    alone = visible_from(r.classification.soup, seed=0, faces=~by_cut)
    np.testing.assert_array_equal(r.visibility.seen_side, alone.seen_side)
    np.testing.assert_array_equal(r.visibility.rays_seen, alone.rays_seen)
    assert r.visibility.rays == alone.rays and r.visibility.rays["total"] > 0


def test_both_gives_the_cuts_sample_points_the_budget_of_a_one_face_side(scenes):
    soup, _ = scenes.pierced_box()  # the triangle crosses the box: flagged faces, sample points
    budget = {
        mode: remove_interior(soup, visibility=mode, seed=0, **kw).classification.params["rays_per_point"]
        for mode, kw in [("both", {}), ("object", {})]
    }
    assert budget == {"both": 8, "object": 32}  # 32 // 4 sample points; object keeps rays_per_node
    # a budget the caller sets wins, and the default follows rays_per_node and the samples
    given = remove_interior(soup, seed=0, visibility="both", rays_per_point=32).classification
    fewer = remove_interior(
        soup, seed=0, visibility="both", rays_per_node=16, samples_per_face=2
    ).classification
    assert given.params["rays_per_point"] == 32 and fewer.params["rays_per_point"] == 8


def test_both_casts_fewer_cut_rays_where_sample_points_need_refining():
    soup = load(MODELS / "assembly.obj")  # interpenetrating parts: many flagged faces
    default = remove_interior(soup, seed=0, visibility="both").classification
    full = remove_interior(soup, seed=0, visibility="both", rays_per_point=32).classification
    assert default.counts.rays < full.counts.rays
    assert default.params["rays_per_point"] == 8 and full.params["rays_per_point"] == 32


def test_the_command_gives_both_the_same_sample_point_budget(tmp_path):
    def budget(*flags):
        out, report = tmp_path / "out.obj", tmp_path / "r.json"
        argv = ["remove-interior", str(MODELS / "assembly.obj"), "-o", str(out), "--report", str(report)]
        assert main([*argv, "--force", "--quiet", *flags]) == 0
        return json.loads(report.read_text())["classification"]["params"]["rays_per_point"]

    assert budget("--visibility", "both") == 8
    assert budget("--visibility", "object") == 32
    assert budget("--visibility", "both", "--rays-per-point", "16") == 16
    assert budget("--visibility", "both", "--rays-per-node", "64") == 16


def test_remove_interior_budget_stops_the_search_for_views(tmp_path):
    """``--budget`` reaches the search of the default removal: a small budget ends it on the
    budget, the default on its stop rule."""
    src = MODELS / "house.obj"
    argv = ["remove-interior", str(src), "-o", str(tmp_path / "out.obj"), "-q", "--force"]
    rep = tmp_path / "r.json"
    assert main(argv + ["--report", str(rep), "--budget", "3000"]) == 0
    view = json.loads(rep.read_text())["view"]
    assert view["stopped"] == "budget" and 3000 <= view["rays"]["total"] < 2 * 3000
    assert main(argv + ["--report", str(rep)]) == 0
    assert json.loads(rep.read_text())["view"]["stopped"] != "budget"
    with pytest.raises(SystemExit) as exit_:
        main(argv + ["--budget", "0"])
    assert exit_.value.code == 2
