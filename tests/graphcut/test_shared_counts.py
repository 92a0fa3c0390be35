"""``meshvis info`` and the classification report the same defect counts (one shared pass)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from meshvis.geometry.diagnostics import diagnose
from meshvis.graphcut.classify import classify
from meshvis.io import load
from meshvis.soup import Soup

REAL = Path(__file__).resolve().parents[3] / "shared" / "models" / "real"

KEYS = (
    "degenerate_faces",
    "collapsed_faces",
    "duplicate_faces",
    "intersecting_faces",
    "coplanar_faces",
    "too_close_faces",
)
#: real models small enough for a test (every real model: ``meshvis bench scale``'s check)
SMALL = ("CesiumMilkTruck.glb", "boolean.glb", "cow.obj", "pins.glb", "suzanne.obj", "teapot.obj", "soup.stl")


def assert_same_counts(soup: Soup) -> dict:
    info = diagnose(soup)
    report = classify(soup, rays_per_node=4, seed=0).report(per_face=False)
    assert {k: info[k] for k in KEYS} == {k: report[k] for k in KEYS}
    return info


@pytest.mark.parametrize("name", SMALL)
def test_info_and_classify_agree_on_real_models(name):
    path = REAL / name
    if not path.exists():
        pytest.skip(f"{path} is not there")
    assert_same_counts(load(path))


def test_info_and_classify_agree_on_every_kind_of_defect():
    # a clean triangle, a duplicate of it, a sliver (degenerate), a collapsed face, two crossing
    v = np.array(
        [
            [0, 0, 0], [1, 0, 0], [0, 1, 0],  # 0-2 triangle
            [3, 0, 0], [4, 0, 0], [5, 0, 1e-12],  # 3-5 degenerate sliver
            [6, 0, 0], [6 + 3e-7, 0, 0], [6, 1, 0],  # 6-8 collapsed by welding (not a sliver)
            [0, 3, -1], [1, 3, 1], [0.5, 4, 0],  # 9-11 crossing 12-14
            [0, 3.5, 1], [1, 3.5, -1], [0.5, 2.8, 0],
        ],
        float,
    )  # fmt: skip
    f = np.array([[0, 1, 2], [0, 2, 1], [3, 4, 5], [6, 7, 8], [9, 10, 11], [12, 13, 14]])
    info = assert_same_counts(Soup(v, f))
    assert info["duplicate_faces"] == 1
    assert info["degenerate_faces"] == 1
    assert info["collapsed_faces"] == 1
    assert info["intersecting_faces"] == 2
