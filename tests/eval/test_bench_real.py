"""``meshvis bench real`` end to end on one small real model."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from meshvis.cli.main import main

REAL = Path(__file__).resolve().parents[3] / "shared" / "models" / "real"


@pytest.mark.skipif(not (REAL / "nested.glb").is_file(), reason="shared real models not present")
def test_bench_real_judges_every_method_on_a_small_model(tmp_path, capsys):
    out, curve = tmp_path / "r.json", tmp_path / "c.png"
    argv = ["bench", "real", "--only", str(REAL / "nested.glb"), "--cache", str(tmp_path)]
    argv += ["--views", "16", "--size", "64"]
    assert main(argv + ["--json", str(out), "--curve", str(curve), "--worst", str(tmp_path / "w")]) == 0
    r = json.loads(out.read_text())["results"][0]
    methods = [row["method"] for row in r["rows"]]
    assert methods[:6] == [
        "reference (dense random)",
        "object (graph cut)",
        "view (guided, outside)",
        "both",
        "view converged (5 faces, seed+1)",
        "random, rays of view",
    ]
    assert 0 <= r["view_removes_of_converged"] <= 1 and r["view_stopped"] and r["converged_stopped"]
    for row in r["rows"]:
        assert 0 <= row["removed_area"] <= 1 and row["false_pixels_worst"] >= row["false_pixels_mean"] >= 0
    ref = r["rows"][0]
    assert ref["reference_hidden_removed"] == 1.0
    # what no search saw shrinks with every search added; the reference and the first
    # converged search each removed all of it (they saw none of it)
    assert r["searches"] == 3 and len(r["converged_rays"]) == 3
    assert r["unseen_area"] == sorted(r["unseen_area"], reverse=True)
    assert ref["unseen_removed"] == 1.0 and r["rows"][4]["unseen_removed"] == 1.0
    for shares in r["unseen_removed_by_k"].values():
        assert len(shares) == 3 and all(0 <= x <= 1 for x in shares)
    assert curve.stat().st_size > 1000 and (tmp_path / "nested.seed0.npz").is_file()
    assert "nested" in capsys.readouterr().out
    assert r["rays_per_point"] == 32  # the default: rays_per_node
    assert r["rays_per_point_both"] == 8  # both's default: rays_per_node // samples_per_face


@pytest.mark.skipif(not (REAL / "pins.glb").is_file(), reason="shared real models not present")
def test_bench_real_passes_the_sample_points_budget_to_the_cut(tmp_path):
    out = tmp_path / "r.json"
    argv = ["bench", "real", "--only", str(REAL / "pins.glb"), "--cache", str(tmp_path), "--searches", "1"]
    argv += ["--views", "8", "--size", "32", "--json", str(out)]
    assert main(argv) == 0
    assert main(argv[:-1] + [str(tmp_path / "r8.json"), "--rays-per-point", "2"]) == 0
    full = json.loads(out.read_text())["results"][0]
    few = json.loads((tmp_path / "r8.json").read_text())["results"][0]
    assert (full["rays_per_point"], few["rays_per_point"]) == (32, 2)
    assert (full["rays_per_point_both"], few["rays_per_point_both"]) == (8, 2)
    rays = {r["method"]: r["rays"] for r in full["rows"]}, {r["method"]: r["rays"] for r in few["rows"]}
    assert rays[1]["object (graph cut)"] < rays[0]["object (graph cut)"]
