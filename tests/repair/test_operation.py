"""The shared repair operation takes the library's keywords; the command line maps its flags onto them."""

from __future__ import annotations

import numpy as np

from meshvis.eval import generators as g
from meshvis.graphcut.classify import classify
from meshvis.repair.operation import CLASSIFY_DEFAULTS, classify_kwargs, run_operation


def test_options_are_classify_keywords():
    kw = classify_kwargs({"use_filter": False, "progressive": False})
    assert kw["use_filter"] is False and kw["progressive"] is False
    assert classify_kwargs({})["use_filter"] is True and classify_kwargs({})["progressive"] is True
    assert not any(k.startswith("no_") for k in CLASSIFY_DEFAULTS)


def test_run_operation_matches_classify():
    soup = g.sphere_pair(subdivisions=2).soup
    report = run_operation("classify", soup, {"use_filter": False, "progressive": False, "rays_per_node": 8})
    c = classify(soup, use_filter=False, progressive=False, rays_per_node=8, seed=0)
    np.testing.assert_array_equal(
        report["per_face"]["outside_front"], c.report()["per_face"]["outside_front"]
    )


def test_cli_flags_map_onto_keywords():
    from meshvis.cli.main import build_parser

    args = build_parser().parse_args(
        ["classify", "m.obj", "--no-filter", "--no-progressive", "--inside-point", "0,0,0"]
    )
    assert args.use_filter is False and args.progressive is False and args.inside_points == [(0.0, 0.0, 0.0)]
    args = build_parser().parse_args(["orient", "m.obj", "-o", "x.obj"])
    assert args.use_filter is True and args.progressive is True and args.inside_boxes == []
