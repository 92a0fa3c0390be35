"""``meshvis bench real`` end to end on small real models."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from meshvis.cli.main import main

REAL = Path(__file__).resolve().parents[3] / "shared" / "models" / "real"


@pytest.mark.slow
@pytest.mark.skipif(not (REAL / "pins.glb").is_file(), reason="shared real models not present")
def test_bench_real_judges_the_default_removal_at_every_seed_and_the_layers(tmp_path, capsys):
    out, curve = tmp_path / "r.json", tmp_path / "c.png"
    argv = [
        "bench",
        "real",
        "--models",
        str(REAL),
        "--only",
        str(REAL / "pins.glb"),
        "--cache",
        str(tmp_path),
    ]
    argv += [
        "--views",
        "16",
        "--size",
        "64",
        "--seeds",
        "0,1",
        "--hidden-searches",
        "2",
        "--hidden-rays",
        "300000",
    ]
    assert main(argv + ["--json", str(out), "--curve", str(curve), "--worst", str(tmp_path / "w")]) == 0
    r = json.loads(out.read_text())["results"][0]
    assert [x["seed"] for x in r["default"]] == [0, 1]
    for x in r["default"]:
        assert x["stopped"] and 0 <= x["check_area"] <= 1 and x["check_faces_seen"] >= 0
        # by sight every face kept was seen: once the faces the searches saw are out of the
        # estimate, the default removes all of it
        assert (
            x["hidden_removed_all_searches"] == 1.0
            and x["hidden_removed_all_searches"] >= x["hidden_removed"]
        )
    assert r["layers"]["layer1_hidden_share_all_searches"] == 0.0
    rows = r["default"] + r["rows"] + [r["layers"]["layer1"]]
    for row in rows:
        assert 0 <= row["removed_area"] <= 1 and 0 <= row["hidden_removed"] <= 1
        assert row["false_pixels_worst"] >= row["false_pixels_mean"] >= 0
    assert [x["method"] for x in r["rows"]][:3] == [
        "object (graph cut)",
        "both",
        "random, rays of the default",
    ]
    # the hidden estimate: what neither the reference nor the long searches saw, cached
    assert r["hidden_searches"] == 2 and all(0 < x <= 300_000 + 64 * 2**15 for x in r["hidden_rays"])
    assert r["hidden_area"] <= r["reference_hidden_area"]
    assert (tmp_path / "pins.seed0.npz").is_file() and (tmp_path / "pins.hidden2x300000.npz").is_file()
    # layer 1 by sight is what the default removal keeps at the same seed
    assert r["layers"]["layer1_is_default"] and r["layers"]["layers"] >= 1
    assert 0 <= r["layers"]["layer1_hidden_share"] <= 1
    sweep = r["budget_sweep"]
    assert [x["share_of_rays"] for x in sweep] == [0.125, 0.25, 0.5, 1.0]
    assert sweep[-1]["false_pixels_mean"] == r["default"][0]["false_pixels_mean"]
    assert r["default_over_object_time"] > 0 and curve.stat().st_size > 1000
    printed = capsys.readouterr().out
    assert "pins" in printed and "models meet every target" in printed
    # a second run reads the cached estimate: same numbers; --default-only leaves out the rest
    assert main(argv + ["--json", str(out), "--default-only"]) == 0
    again = json.loads(out.read_text())["results"][0]
    assert again["hidden_area"] == r["hidden_area"] and again["hidden_rays"] == r["hidden_rays"]
    assert [x["false_pixels_mean"] for x in again["default"]] == [
        x["false_pixels_mean"] for x in r["default"]
    ]
    assert not {"layers", "rows", "default_over_object_time"} & set(again)
    assert "models meet every target" in capsys.readouterr().out
