"""Error measures, baselines and the accuracy / compare benchmarks."""

import csv
import math
from pathlib import Path

import numpy as np
import pytest
import trimesh

from meshvis.errors import ParameterError
from meshvis.eval import baselines as B
from meshvis.eval import generators as gen
from meshvis.eval.generators import GroundTruth
from meshvis.eval.metrics import layer_accuracy, layer_error, orientation_error, removal_scores
from meshvis.soup import Soup


# ====================================================================== hand-made truth
def strip_truth():
    """Four separate right triangles in the plane z = 0 with areas 0.5, 2, 4.5 and 8.

    Face 0: visible, front outward; face 1: visible, front inward; face 2: hidden, layer 2,
    front outward; face 3: two-sided sheet.
    """
    tris = []
    for k, s in enumerate((1.0, 2.0, 3.0, 4.0)):
        x = 10.0 * k
        tris.append([[x, 0, 0], [x + s, 0, 0], [x, s, 0]])
    V = np.array(tris, float).reshape(-1, 3)
    F = np.arange(12).reshape(4, 3)
    return GroundTruth(
        soup=Soup(V, F),
        outside=[[True, False], [False, True], [False, False], [True, True]],
        layer=[1, 1, 2, 1],
        outward=[True, False, True, True],
        two_sided=[False, False, False, True],
    )


def test_areas_of_the_hand_made_truth():
    assert np.allclose(strip_truth().soup.areas, [0.5, 2, 4.5, 8])
    assert strip_truth().check() == []


def test_orientation_error_is_area_weighted_and_ignores_two_sided_orientation():
    t = strip_truth()
    total = 15.0
    # perfect repair: turn face 1 only; the sheet may go either way
    assert orientation_error(t, [False, True, False, False]) == 0.0
    assert orientation_error(t, [False, True, False, True]) == 0.0
    # nothing turned: face 1 (area 2) is wrong
    assert orientation_error(t, [False, False, False, False]) == pytest.approx(2 / total)
    # everything turned: faces 0, 2 wrong (0.5 + 4.5); the sheet still counts as correct
    assert orientation_error(t, [True, True, True, True]) == pytest.approx(5 / total)
    # on the hidden faces only
    assert orientation_error(t, [True, True, True, True], where=t.layer >= 2) == 1.0
    assert orientation_error(t, [False] * 4, where=t.layer >= 2) == 0.0


def test_orientation_error_leaves_out_ambiguous_faces():
    t = strip_truth()
    t.ambiguous[1] = True
    assert orientation_error(t, [False] * 4) == 0.0
    assert orientation_error(t, [True] * 4) == pytest.approx(5 / 13)
    t.ambiguous[:] = True
    assert orientation_error(t, [True] * 4) == 0.0  # nothing evaluated


def test_removal_precision_recall_and_error():
    t = strip_truth()
    # perfect: remove exactly the hidden face 2
    s = removal_scores(t, [True, True, False, True])
    assert (s.precision, s.recall, s.error) == (1.0, 1.0, 0.0)
    # remove faces 1 and 2: precision 4.5 / 6.5, recall 1, error 2 / 15
    s = removal_scores(t, [True, False, False, True])
    assert s.precision == pytest.approx(4.5 / 6.5)
    assert s.recall == 1.0
    assert s.error == pytest.approx(2 / 15)
    # remove nothing: precision 1 by convention, recall 0, error = hidden area
    s = removal_scores(t, [True] * 4)
    assert (s.precision, s.recall) == (1.0, 0.0)
    assert s.error == pytest.approx(4.5 / 15)
    # remove everything
    s = removal_scores(t, [False] * 4)
    assert s.precision == pytest.approx(4.5 / 15) and s.recall == 1.0
    assert s.error == pytest.approx(10.5 / 15)


def test_layer_accuracy_is_area_weighted():
    t = strip_truth()
    assert layer_accuracy(t, [1, 1, 2, 1]) == 1.0
    assert layer_accuracy(t, [1, 1, 1, 1]) == pytest.approx(10.5 / 15)
    assert layer_error(t, [2, 1, 2, 3]) == pytest.approx(8.5 / 15)
    assert layer_accuracy(t, [1, 1, 3, 1], where=t.layer == 1) == 1.0


def test_metrics_reject_wrong_lengths():
    t = strip_truth()
    with pytest.raises(ParameterError):
        orientation_error(t, [True, False])
    with pytest.raises(ParameterError):
        removal_scores(t, np.ones(5, bool))
    with pytest.raises(ParameterError):
        layer_accuracy(t, [[1, 1], [1, 1]])


# ====================================================================== baselines
def two_spheres():
    """A closed sphere with a smaller one inside, half of the faces flipped, as a truth."""
    a, b = trimesh.creation.icosphere(2), trimesh.creation.icosphere(1, radius=0.5)
    V = np.vstack([a.vertices, b.vertices])
    F = np.vstack([a.faces, b.faces + len(a.vertices)])
    t = GroundTruth(
        soup=Soup(V, F),
        outside=np.r_[[[True, False]] * len(a.faces), [[False, False]] * len(b.faces)],
        layer=np.r_[[1] * len(a.faces), [2] * len(b.faces)],
        outward=True,
    )
    return gen.soupify(t, flip=0.5, seed=3)


def test_turned_detects_reversed_rows_up_to_rotation():
    before = np.array([[0, 1, 2], [0, 1, 2], [3, 4, 5], [3, 4, 5]])
    after = np.array([[1, 2, 0], [0, 2, 1], [3, 4, 5], [5, 4, 3]])
    assert B._turned(before, after).tolist() == [False, True, False, True]


def test_welded_keeps_face_order_and_merges_corners():
    t = two_spheres()
    V, F = B.welded(t.soup)
    assert len(F) == t.n_faces
    assert len(V) == 162 + 42
    assert np.allclose(V[F], t.soup.triangles)


@pytest.mark.parametrize("name", ["libigl_reorient", "trimesh_fix_normals"])
def test_orientation_baselines_repair_a_flipped_soup(name):
    t = two_spheres()
    r = B.BASELINES[name].run(t.soup)
    assert r.ok and r.task == "orient" and r.seconds > 0
    assert r.values.shape == (t.n_faces,) and r.values.dtype == bool
    assert 0.3 * t.n_faces < r.values.sum() < 0.7 * t.n_faces  # about half was flipped
    assert orientation_error(t, r.values, where=t.layer == 1) == 0.0


def test_ambient_occlusion_front_only_and_both_sides():
    t = two_spheres()
    one = B.pymeshlab_ao(t.soup, rays=16)
    two = B.pymeshlab_ao(t.soup, rays=16, both_sides=True)
    assert one.ok and two.ok and one.method != two.method
    assert removal_scores(t, two.values).error == 0.0
    # front-only lighting removes the outer faces whose front points inward
    outer_in = (t.layer == 1) & ~t.outward
    assert not one.values[outer_in].any()


@pytest.mark.slow
def test_peel_gives_layers_and_reports_failures_instead_of_raising():
    t = two_spheres()
    r = B.libigl_peel(t.soup, timeout=60)
    assert r.ok, r.message
    assert layer_error(t, r.values) == 0.0
    bad = B.libigl_peel((np.zeros((0, 3)), np.zeros((0, 3), np.int64)))
    assert not bad.ok and bad.values is None and bad.message
    slow = B.libigl_peel(t.soup, timeout=1e-3)
    assert not slow.ok and "within" in slow.message


def test_library_exception_is_a_failed_result():
    r = B.trimesh_fix_normals("/nonexistent/model.obj")
    assert not r.ok and r.values is None and r.message


# ====================================================================== benchmarks
@pytest.mark.slow
def test_compare_one_case_and_its_checks():
    from meshvis.eval.bench import cases as C
    from meshvis.eval.bench import compare

    t = two_spheres()
    pts = compare.compare_case(t, "two_spheres", log=lambda *a: None, peel_timeout=60)
    methods = {(p.task, p.method) for p in pts}
    assert ("orient", "meshvis") in methods and ("orient", "libigl_reorient") in methods
    assert ("layers", "libigl_peel") in methods and ("remove", "pymeshlab_ao_2sided") in methods
    mv = {p.task: p for p in pts if p.method == "meshvis"}
    assert all(p.error == 0.0 for p in mv.values())
    lines = compare.checks(pts, "two_spheres")
    assert any("hidden shell correctly oriented: meshvis 100.00 %" in s for s in lines)
    assert any(s.startswith("speed:") for s in lines)
    text = compare.markdown(pts, [], C.machine(), "meshvis bench compare", 1.0)
    assert "| two_spheres |" in text and "## Targets" in text


REAL = Path(__file__).resolve().parents[3] / "shared" / "models" / "real"


@pytest.mark.slow
@pytest.mark.skipif(not REAL.is_dir(), reason="shared real models not present")
def test_accuracy_quick_writes_finite_errors(tmp_path):
    from meshvis.cli.main import main

    out = tmp_path / "acc"
    args = ["bench", "accuracy", "--quick", "--quiet", "--out", str(out), "--models", str(REAL)]
    assert main(args) == 0
    for name in (
        "accuracy.csv",
        "accuracy.md",
        "accuracy_orient.png",
        "accuracy_remove.png",
        "accuracy_layers.png",
    ):
        assert (out / name).stat().st_size > 0, name
    for task in ("orient", "remove", "layers"):
        assert (out / f"accuracy_{task}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with open(out / "accuracy.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert {r["task"] for r in rows} == {"orient", "remove", "layers"}
    assert {r["case"] for r in rows} == {"sphere_pair", "nested_shells", "cracked_box", "cow"}
    methods = {r["method"] for r in rows}
    assert {
        "meshvis",
        "meshvis_default",
        "libigl_reorient",
        "trimesh_fix_normals",
        "pymeshlab_ao",
        "libigl_peel",
    } <= methods
    rays = sorted({int(float(r["value"])) for r in rows if r["method"] == "meshvis"})
    assert rays == [1, 4, 16]
    for r in rows:
        assert float(r["load1"]) >= 0
        assert float(r["seconds"]) > 0
        if r["ok"] == "True":
            e = float(r["error"])
            assert math.isfinite(e) and 0.0 <= e <= 1.0, r
    ok_mv = [r for r in rows if r["method"].startswith("meshvis")]
    assert ok_mv and all(r["ok"] == "True" for r in ok_mv)
    # meshvis answers the hidden-shell inputs exactly
    for r in ok_mv:
        if r["case"] in ("sphere_pair", "nested_shells"):
            assert float(r["error"]) == 0.0, r
    from meshvis.eval.bench.accuracy import read_csv

    back = read_csv(str(out / "accuracy.csv"))
    assert len(back) == len(rows) and all(isinstance(p.ok, bool) and isinstance(p.faces, int) for p in back)
    text = (out / "accuracy.md").read_text()
    assert "## normal orientation" in text and "load average" in text
    assert "Where meshvis' curve is not at or below" in text
    # the results are not overwritten without --force (one-line error, status 2)
    assert main(["bench", "accuracy", "--quick", "--quiet", "--out", str(out)]) == 2
