"""Repair reports: schema version, the JSON Schema in docs/, status names, --per-face, --report -."""

import json
import os

import jsonschema
import numpy as np
import pytest
import trimesh

from meshvis.cli.main import main
from meshvis.io import save

SCHEMA = os.path.join(os.path.dirname(__file__), "..", "..", "docs", "report.schema.json")


@pytest.fixture(scope="module")
def ball(tmp_path_factory):
    sphere = trimesh.creation.icosphere(subdivisions=2)
    path = tmp_path_factory.mktemp("ball") / "ball.obj"
    save((sphere.vertices, sphere.faces), str(path))
    return str(path), len(sphere.faces)


def _validator():
    with open(SCHEMA) as fh:
        schema = json.load(fh)
    jsonschema.Draft202012Validator.check_schema(schema)
    return jsonschema.Draft202012Validator(schema)


@pytest.mark.parametrize("op", ["classify", "orient", "remove-interior", "layers"])
def test_reports_follow_the_documented_schema(op, ball, tmp_path):
    path, m = ball
    rep = tmp_path / "r.json"
    args = [op, path, "--report", str(rep), "-q"] + (
        [] if op == "classify" else ["-o", str(tmp_path / "o.obj")]
    )
    assert main(args) == 0
    report = json.loads(rep.read_text())
    _validator().validate(report)
    assert report["schema"] == 1
    assert all(len(v) == m for v in report["per_face"].values())
    if op == "orient":
        assert set(report["per_face"]["status"]) <= {
            "one-sided",
            "two-sided",
            "hidden",
            "conflict",
            "degenerate",
        }


def test_a_report_that_breaks_the_schema_is_caught(ball, tmp_path):
    path, _ = ball
    rep = tmp_path / "r.json"
    assert main(["orient", path, "-o", str(tmp_path / "o.obj"), "--report", str(rep), "-q"]) == 0
    report = json.loads(rep.read_text())
    report["per_face"]["status"][0] = 2  # a code instead of a name
    with pytest.raises(jsonschema.ValidationError):
        _validator().validate(report)


def test_per_face_arrays_go_to_npz(ball, tmp_path):
    path, m = ball
    rep, npz = tmp_path / "r.json", tmp_path / "faces.npz"
    assert (
        main(
            [
                "orient",
                path,
                "-o",
                str(tmp_path / "o.obj"),
                "--report",
                str(rep),
                "--per-face",
                str(npz),
                "-q",
            ]
        )
        == 0
    )
    report = json.loads(rep.read_text())
    _validator().validate(report)
    arrays = np.load(npz)
    assert report["per_face"]["file"] == "faces.npz"
    assert set(arrays) == set(report["per_face"]["arrays"]) >= {"status", "flipped"}
    assert arrays["status"].dtype.kind == "U" and len(arrays["flipped"]) == m
    assert rep.stat().st_size < 20000  # the numbers are not in the JSON


def test_report_to_standard_output(ball, tmp_path, capsys):
    path, m = ball
    assert main(["remove-interior", path, "-o", str(tmp_path / "o.obj"), "--report", "-"]) == 0
    report = json.loads(capsys.readouterr().out)
    _validator().validate(report)
    assert report["kept_faces"] == m
