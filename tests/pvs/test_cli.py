"""``meshvis pvs``: one summary line, its outputs, arguments refused before the model is read; and
``remove-interior --from cells:PVS.npz``."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

import meshvis
from meshvis.cli.main import main
from meshvis.viewcells import PVS


def _error(capsys, argv) -> str:
    assert main([str(a) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and err.startswith("meshvis: error: "), err
    return err


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--cells", "grid:2,2"], "grid:NX,NY,NZ"),
        (["--cells", "octree"], "unknown cells"),
        (["--cells", "missing.json"], "view cells file not found"),
        (["--view-space", "sphere"], "unknown view space"),
        (["--view-space", "box:0,0,0,1,1"], "expected 6"),
        (["--top-view", "{tmp}/top.gif"], "'.gif' pictures"),
    ],
)
def test_refused_before_the_model_is_read(capsys, tmp_path, extra, words):
    argv = [
        "pvs",
        "missing.obj",
        "-o",
        tmp_path / "p.npz",
        *[str(e).replace("{tmp}", str(tmp_path)) for e in extra],
    ]
    err = _error(capsys, argv)
    assert words in err and "missing.obj" not in err
    assert os.listdir(tmp_path) == []


def _closed_room(levels, tmp_path):
    """The split space and, beyond the view space, a closed box with a box inside it."""
    soup, idx = levels.split_space()
    outer, inner = (
        levels.box_quads((5, 0.5, 0.5), (6, 1.5, 1.5)),
        levels.box_quads((5.3, 0.8, 0.8), (5.7, 1.2, 1.2)),
    )
    groups = {name: soup.triangles[idx[name]].tolist() for name in idx}
    full, index = levels.soup_of({**groups, "shell": outer, "inside": inner})
    path = tmp_path / "level.obj"
    meshvis.save(full, str(path))
    return str(path), index


@pytest.mark.slow
def test_pvs_writes_its_outputs_and_prints_one_line(levels, tmp_path, capsys):
    model, _ = _closed_room(levels, tmp_path)
    out = tmp_path / "level.pvs.npz"
    argv = [
        "pvs",
        model,
        "-o",
        out,
        "--cells",
        "grid:2,1,1",
        "--view-space",
        "box:0,0,0,4,2,2",
        "--rays",
        "400000",
    ]
    argv += [
        "--report",
        tmp_path / "r.json",
        "--top-view",
        tmp_path / "top.png",
        "--cell-view",
        tmp_path / "cell.png",
    ]
    assert main([str(a) for a in argv]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert len(lines) == 1 and "pvs: 2 cells" in lines[0] and "stopped: budget" in lines[0]
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["cells"]["cells"] == 2 and report["rays"]["total"] >= 400_000
    assert set(report["left_out"]) >= {"faces_no_cell_sees", "tree_leaves_without_view_space"}
    assert (tmp_path / "top.png").stat().st_size > 0 and (tmp_path / "cell.png").stat().st_size > 0
    assert PVS.load(out, meshvis.load(model)).cells.n_cells == 2
    # an existing output is refused without --force
    err = _error(capsys, argv)
    assert "exists" in err


@pytest.mark.slow
def test_remove_interior_removes_what_no_cell_sees(levels, tmp_path, capsys):
    model, index = _closed_room(levels, tmp_path)
    out = tmp_path / "level.pvs.npz"
    argv = [
        "pvs",
        model,
        "-o",
        out,
        "--cells",
        "grid:2,1,1",
        "--view-space",
        "box:0,0,0,4,2,2",
        "--rays",
        "2000000",
    ]
    assert main([str(a) for a in argv]) == 0
    kept = tmp_path / "kept.obj"
    report = tmp_path / "removal.json"
    argv = [
        "remove-interior",
        model,
        "-o",
        kept,
        "--visibility",
        "view",
        "--from",
        f"cells:{out}",
        "--report",
        report,
    ]
    assert main([str(a) for a in argv]) == 0
    keep = np.asarray(json.loads(report.read_text())["per_face"]["keep"])
    # gone: the box inside the closed box, and the closed box's side facing away from the view space
    gone = set(np.flatnonzero(~keep))
    far_side = {f for f in index["shell"] if meshvis.load(model).normals[f][0] > 0.5}
    assert gone == set(index["inside"]) | far_side
    # a missing PVS file is refused before the model is read
    err = _error(
        capsys, ["remove-interior", "missing.obj", "-o", kept, "--force", "--from", "cells:none.npz"]
    )
    assert "PVS file not found" in err


@pytest.mark.slow
def test_bench_pvs_reports_cpu_seconds_and_reuses_its_cached_run(tmp_path, capsys):
    model = os.path.join(os.path.dirname(__file__), "..", "..", "models", "house.obj")
    argv = ["bench", "pvs", model, "--rays", "300000", "--cells", "grid:2,1,2", "--points", "8"]
    argv += ["--path", "4", "--size", "8", "--parts", "agvs,converged", "--gvs-cells", "1"]
    argv += ["--cache", str(tmp_path)]
    assert main([*argv, "--json", str(tmp_path / "a.json")]) == 0
    first = json.loads((tmp_path / "a.json").read_text())["results"][0]
    curve = [p["cpu_seconds"] for p in first["agvs_curve"]]
    assert curve == sorted(curve) and 0 < curve[-1] <= first["cpu_seconds"]
    g = first["gvs_converged"]
    assert g["extrapolated_cpu_seconds"] == pytest.approx(4 * g["cpu_seconds_per_cell"])
    assert (g["cpu_ratio"] is None) == (g["agvs_cpu_seconds_to_same_mean_pvs"] is None)
    assert "s CPU) for all cells" in capsys.readouterr().out
    # the second run reads the cached run: the same numbers
    assert main([*argv, "--json", str(tmp_path / "b.json")]) == 0
    second = json.loads((tmp_path / "b.json").read_text())["results"][0]
    assert second["agvs_curve"] == first["agvs_curve"] and second["rays"] == first["rays"]
    # with the filter: judged with and without the faces it added (a superset: never more wrong pixels)
    assert main([*argv, "--parts", "agvs", "--filter", "--json", str(tmp_path / "c.json")]) == 0
    fl = json.loads((tmp_path / "c.json").read_text())["results"][0]
    assert fl["filter"]["added"] > 0
    assert fl["mean_pvs"] == pytest.approx(fl["filter"]["mean_pvs_sampled"] + fl["filter"]["mean_added"])
    assert fl["final"]["mean"] <= fl["filter"]["sampled"]["mean"]
    assert fl["filter"]["mean_pvs_sampled"] == pytest.approx(first["mean_pvs"])


@pytest.mark.slow
def test_bench_pvs_curves_at_equal_cpu_seconds_cached_per_part(tmp_path):
    model = os.path.join(os.path.dirname(__file__), "..", "..", "models", "house.obj")
    argv = ["bench", "pvs", model, "--rays", "200000", "--cells", "grid:2,1,1", "--points", "8"]
    argv += ["--path", "4", "--size", "8", "--cache", str(tmp_path)]
    assert main([*argv, "--parts", "agvs,random", "--json", str(tmp_path / "a.json")]) == 0
    first = json.loads((tmp_path / "a.json").read_text())["results"][0]
    agvs, rnd = first["agvs_curve"], first["random_curve"]
    # a point of per-cell random sampling where AGVS had used as many CPU seconds (or just past it)
    assert len(rnd) == len(agvs)
    assert all(r["cpu_seconds"] >= a["cpu_seconds"] for r, a in zip(rnd, agvs))
    assert main([*argv, "--parts", "gvs", "--json", str(tmp_path / "b.json")]) == 0
    gvs = json.loads((tmp_path / "b.json").read_text())["results"][0]["gvs_curve"]
    assert [g["budget_per_cell"] for g in gvs] == [int(first["rays"] * s / 2) for s in (1 / 16, 0.25, 1.0)]
    # a last call reads both parts from the cache (the same numbers) and draws them
    png = tmp_path / "curve.png"
    argv += ["--parts", "agvs,random,gvs", "--curve", str(png), "--json", str(tmp_path / "c.json")]
    assert main(argv) == 0
    last = json.loads((tmp_path / "c.json").read_text())["results"][0]
    assert last["random_curve"] == rnd and last["gvs_curve"] == gvs
    assert png.stat().st_size > 1000
