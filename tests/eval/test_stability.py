"""Stability benchmark: the quick run through the command line, and the trickiest cases directly."""

import argparse
import json

import numpy as np
import pytest
import trimesh

from meshvis.cli.main import main as cli_main
from meshvis.errors import ModelError
from meshvis.eval import generators
from meshvis.eval.bench import stability as st
from meshvis.eval.bench import stability_cases as cases
from meshvis.eval.bench import stability_models as stressed
from meshvis.graphcut.classify import classify
from meshvis.graphcut.mincut import min_cut, rounding_bound


@pytest.mark.slow
def test_quick_run_passes_through_the_command_line(tmp_path, capsys):
    out = tmp_path / "stability.json"
    assert cli_main(["bench", "stability", "--quick", "--json", str(out)]) == 0
    printed = capsys.readouterr().out.splitlines()
    result = json.loads(out.read_text())
    assert result["failed"] == 0 and result["passed"] == len(result["cases"]) >= 20
    assert {c["group"] for c in result["cases"]} == {"similarity", "degenerate", "cracks", "weights", "tiny"}
    # one PASS/FAIL line per case, then the count
    assert sum(line.startswith(("PASS", "FAIL")) for line in printed) == len(result["cases"])
    assert printed[-1].startswith(f"stability (quick): {result['passed']} of {result['passed']} cases passed")


def test_main_returns_1_when_a_case_fails(monkeypatch, capsys):
    def fake_run(quick, seed, rays_per_node, progress):
        bad = cases.CaseResult("tiny", "broken on purpose", False, "figure 0")
        progress(bad)
        return {"quick": quick, "passed": 0, "failed": 1, "seconds": 0.0, "cases": [bad.__dict__]}

    monkeypatch.setattr(st, "run", fake_run)
    assert st.main(argparse.Namespace(quick=True, seed=0, rays_per_node=4, json=None)) == 1
    assert capsys.readouterr().out.startswith("FAIL  [tiny] broken on purpose: figure 0")


def test_area_agreement_weights_faces_by_area():
    ref = np.array([[True, False], [True, False], [False, False]])
    other = np.array([[True, False], [True, True], [False, False]])
    assert cases.area_agreement(ref, other, np.array([1.0, 3.0, 6.0])) == pytest.approx(0.7)
    assert cases.area_agreement(ref, ref, np.zeros(3)) == 1.0


def test_nonfinite_finds_a_nan_in_the_weights_and_the_report():
    c = classify(trimesh.creation.icosphere(1), rays_per_node=4, seed=0)
    assert cases.nonfinite(c) == []
    c.graph.weights.cap_in[0] = np.nan
    c.outside[0, 0] = np.inf
    bad = cases.nonfinite(c)
    assert any(b.startswith("weights.cap_in") for b in bad)
    assert any(b.startswith("report.per_face.outside_front") for b in bad)


def test_slivers_reach_the_requested_aspect_ratio_and_keep_area_and_normals():
    soup = generators.nested_shells(1, subdivisions=2).soup
    s, parent = stressed.split_into_slivers(soup, fraction=0.3, t_min=1e-6, seed=1)
    assert cases.aspect_ratios(s).max() > 5e5
    assert np.bincount(parent, s.areas, minlength=soup.n_faces) == pytest.approx(soup.areas, rel=1e-9)
    assert np.allclose(s.normals, soup.normals[parent], atol=1e-6)


def test_stressed_copies_keep_the_original_faces_first():
    soup = generators.nested_shells(1, subdivisions=1).soup
    m = soup.n_faces
    for s in (
        stressed.add_zero_area(soup),
        stressed.add_duplicates(soup),
        stressed.add_near_coplanar(soup, 1e-7),
    ):
        assert s.n_faces > m
        assert np.array_equal(s.triangles[:m], soup.triangles)
    assert (
        stressed.add_zero_area(soup).areas[m:] < 1e-15 * soup.diagonal**2
    ).all()  # round-off of collinear corners
    near = stressed.add_near_coplanar(soup, 1e-7)
    shift = np.abs(
        np.einsum(
            "ij,ij->i",
            near.triangles[m:, 0]
            - soup.triangles[:, 0][
                np.argmin(
                    np.linalg.norm(near.triangles[m:, None, 0] - soup.triangles[None, :, 0], axis=2), axis=1
                )
            ],
            near.normals[m:],
        )
    )
    assert np.allclose(shift, 1e-7 * soup.diagonal, rtol=1e-3)


@pytest.mark.slow
def test_far_translation_and_extreme_scales_give_identical_labels():
    soup = generators.cracked_box(cell=0.1, crack_width=1e-3).soup
    ref = classify(soup, rays_per_node=8, seed=3)
    for s in (
        stressed.similarity(soup, "translate", 1e6),
        stressed.similarity(soup, "scale", 1e-6),
        stressed.similarity(soup, "scale", 1e6),
        stressed.similarity(soup, "rotate", seed=2),
    ):
        c = classify(s, rays_per_node=8, seed=3)
        assert cases.area_agreement(ref.side_outside, c.side_outside, soup.areas) >= cases.AGREEMENT


@pytest.mark.slow
def test_crack_leaks_only_above_the_opening_share():
    rows = cases.crack_sweep([3e-2, 1e-4], cell=0.1, rays_per_node=16, seed=0, share_rays=100_000)
    wide, hairline = rows
    # a slit of 3e-2 x size is an opening: its escape share exceeds the opening threshold
    assert wide["share_measured"] > 0.05 and wide["inner_outside"] == 1.0
    # a hairline crack keeps the interior inside; its share is far below the threshold
    assert hairline["share_measured"] < 0.005 and hairline["inner_outside"] == 0.0
    assert hairline["box_inner_side_outside"] == 0.0
    # the paper's unfaded prior keeps even the wide slit closed
    assert wide["paper_inner_outside"] == 0.0
    assert not wide["nonfinite"] and not hairline["nonfinite"]


def test_float32_scene_closes_slits_of_about_1e_7_of_the_diagonal():
    rows = cases.slit_transmission([1e-5, 1e-8], positions=(0.9,), n_rays=2000)
    assert rows[0]["transmitted"] > 0.9
    assert rows[1]["transmitted"] == 0.0


def test_solvers_agree_within_the_rounding_bound_on_weights_spanning_12_orders():
    c = classify(stressed.tiny_beside_huge(), rays_per_node=8, seed=0)
    r = cases.compare_solvers(c)
    assert r["edge_weight_orders"] >= 12
    assert r["value_pymaxflow"] > 0  # the cracked outer sphere makes the cut non-trivial
    assert r["difference"] <= r["bound"]
    assert r["capacities_rounded_to_zero"] > 0  # the integer solver does lose the tiny ones
    assert r["agreement"] >= cases.AGREEMENT and r["area_differing"] < 1e-8
    # the compiled solver finds the same maximum flow, and its labels are a cut of that value
    assert r["value_bk"] == pytest.approx(r["value_pymaxflow"], rel=1e-9)
    assert r["bk_labels_cut"] == pytest.approx(r["value_pymaxflow"], rel=1e-9)


def _stiff_graph(seed: int, n: int, k: int):
    """Random edges (repeated pairs stay: parallel edges add up) with capacities spanning
    12 orders of magnitude; half the terminal links are 0."""
    rng = np.random.default_rng(seed)
    i, j = rng.integers(0, n, k), rng.integers(0, n, k)
    keep = i != j
    i, j = i[keep], j[keep]
    caps = [10.0 ** rng.uniform(-12, 0, size) for size in (len(i), len(i), n, n)]
    for c in caps[2:]:
        c[rng.random(n) < 0.5] = 0.0
    return i, j, caps


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_compiled_solver_equals_pymaxflow_on_capacities_spanning_12_orders(seed):
    n = 200
    i, j, caps = _stiff_graph(seed, n, 1000)
    pm = min_cut(n, i, j, *caps, solver="pymaxflow")
    bk = min_cut(n, i, j, *caps, solver="bk")
    assert np.array_equal(bk.outside, pm.outside)
    assert bk.value == pytest.approx(pm.value, rel=1e-12)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_rounding_bound_holds_on_random_graphs_with_extreme_capacities(seed):
    n = 60
    i, j, caps = _stiff_graph(seed, n, 300)
    pm = min_cut(n, i, j, *caps, solver="pymaxflow")
    sc = min_cut(n, i, j, *caps, solver="scipy")
    crossing = max(int(np.sum(o[i] != o[j])) + n for o in (pm.outside, sc.outside))
    assert abs(sc.value - pm.value) <= rounding_bound(crossing, sc.scale) + 1e-12 * pm.value


def test_pymaxflow_cut_of_an_empty_graph():
    e, f = np.zeros(0, np.int64), np.zeros(0)
    cut = min_cut(0, e, e, f, f, f, f, solver="pymaxflow")
    assert cut.outside.shape == (0,) and cut.value == 0.0


@pytest.mark.parametrize(
    "text, problem",
    [
        ("", "the file is empty"),
        ("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "degenerate"),
    ],
)
def test_empty_and_degenerate_files_fail_cleanly_naming_the_file(tmp_path, capsys, text, problem):
    path = tmp_path / "model.obj"
    path.write_text(text)
    with pytest.raises(ModelError, match=problem) as info:
        classify(str(path), rays_per_node=4)
    assert str(path) in str(info.value)
    # on the command line: exit status 2 and one line naming the file, no traceback
    assert cli_main(["classify", str(path), "--report", str(tmp_path / "report.json")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(path) in err[0] and problem in err[0]


def test_lone_sheets_are_seen_from_both_sides():
    results = cases.tiny_cases(rays_per_node=4, seed=0)
    assert [r.name for r in results if not r.passed] == []
    assert {r.name for r in results} >= {"one triangle", "one quad", "empty file", "one zero-area triangle"}


def test_sample_origin_next_to_a_perpendicular_wall_stays_on_its_side():
    # Regression (found by the sliver case): a sample point of face A (plane x = 0) lies
    # 1e-5 from a perpendicular partner wall B (plane y = 0).  The normals cannot say on
    # which side of B the origin belongs; it must stay on the point's own side (y > 0)
    # instead of being pushed through B.
    from meshvis.graphcut.nodes import _pushed_origins

    tri = np.array([[[0, 0, 0], [0, 1, 0], [0, 0, 1]], [[-1, 0, -1], [1, 0, -1], [0, 0, 2]]], float)
    nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    assert np.allclose(nrm, [[1, 0, 0], [0, -1, 0]])
    pos = np.array([[0.0, 1e-5, 0.3]])
    offset = 1e-4
    for side in (0, 1):
        o = _pushed_origins(
            pos,
            np.array([0]),
            side,
            tri,
            nrm,
            np.array([0, -1]),
            np.array([[0, 1]]),
            np.array([0, 1]),
            offset,
            2 * offset,
        )
        assert o[0, 1] > 0  # still in front of the wall
        assert o[0, 0] == pytest.approx(offset if side == 0 else -offset)
