"""The report of ``meshvis bench orientation``: with ``--confirm`` every error is read two ways."""

from __future__ import annotations

from meshvis.eval.bench.orientation import METHODS, Run, markdown


def _runs(confirmed: bool) -> list[Run]:
    extra = {"error_confirmed": 0.0002} if confirmed else {}
    runs = [Run("m.obj", kind, 10, "input", 0, 0.0, 0.5, **extra) for kind in ("as is", "soup")]
    for kind in ("as is", "soup"):
        runs += [Run("m.obj", kind, 10, method, 0, 1.0, 0.001, **extra) for method in METHODS]
    return runs


def test_markdown_reads_the_error_on_confirmed_faces_only_when_recounted():
    machine = {
        "cpu": "x",
        "cores": 1,
        "os": "o",
        "python": "3",
        "meshvis": "0",
        "versions": {},
        "load_average": (0, 0, 0),
    }
    plain = markdown(_runs(False), machine, "cmd", 1.0)
    both = markdown(_runs(True), machine, "cmd", 1.0)
    assert "0.100 % (1.000 s)" in plain and " % / " not in plain
    assert "0.100 % / 0.020 % (1.000 s)" in both and "recount confirms" in both


def test_the_soup_input_keeps_the_models_up_axis():
    import numpy as np

    from meshvis.eval.bench.orientation import FLIP, soup_of
    from meshvis.soup import Soup

    model = Soup(np.eye(3), np.array([[0, 1, 2]] * 10), up=(0.0, 1.0, 0.0))
    soup, turned = soup_of(model, seed=1)
    assert soup.up == (0.0, 1.0, 0.0)
    assert turned.sum() == round(FLIP * 10) and soup.n_vertices == 30


def test_from_above_reports_the_back_facing_pixels_before_and_after(tmp_path):
    """``--elevations``: one row per model and elevation, input and both outputs."""
    import csv

    from helpers import REAL

    from meshvis.cli.main import main

    out = tmp_path / "out"
    argv = ["bench", "orientation", "--out", str(out), "--models", str(REAL), "--quiet"]
    assert main([*argv, "--only", "wallhole", "--elevations", "20", "60"]) == 0
    rows = list(csv.DictReader(open(out / "from_above.csv")))
    assert [float(r["elevation"]) for r in rows] == [20.0, 60.0]
    assert all(r["model"] == "wallhole.obj" and r["ground_found"] == "True" for r in rows)
    assert all(0.0 <= float(r[k]) <= 1.0 for r in rows for k in ("input", "default", "ground_auto"))
    assert "| wallhole.obj | 66 | 60° |" in (out / "from_above.md").read_text()
