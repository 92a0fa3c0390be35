"""One answer every way it is asked: the Python API and the command line give the same faces.

Each operation runs with default arguments on three small models of three formats (glTF,
OBJ, STL), once through its Python function and once through ``meshvis``; the per-face
decisions of the command's report must equal the function's.  The upper-hemisphere region
is asked on the glTF and the OBJ model too, where the up axis matters: both ways read it
from the model (y-up formats), which is shown to change the answer.
"""

from __future__ import annotations

import argparse
import json

import numpy as np
import pytest
from helpers import real_model

import meshvis
from meshvis.cli.main import build_parser, main
from meshvis.repair.operation import GROUND_CHOICES, default_options

#: small models of three formats: y-up glTF, y-up OBJ, z-up STL
MODELS = ["nested.glb", "wallhole.obj", "soup.stl"]


def _seen(report: dict) -> np.ndarray:
    return np.array(report["per_face"]["seen_front"], bool) | np.array(report["per_face"]["seen_back"], bool)


def _cli_report(argv: list[str], tmp_path) -> dict:
    rep = tmp_path / "report.json"
    assert main([*argv, "--report", str(rep), "-q", "--force"]) == 0
    return json.loads(rep.read_text())


@pytest.mark.slow
@pytest.mark.parametrize("name", MODELS)
def test_python_and_cli_give_the_same_faces(name, tmp_path):
    path = real_model(name)
    soup = meshvis.load(path)
    out = str(tmp_path / f"out{'.ply'}")

    r = meshvis.orient(soup)
    rep = _cli_report(["orient", path, "-o", out], tmp_path)
    np.testing.assert_array_equal(np.array(rep["per_face"]["flipped"], bool), r.flipped)
    assert meshvis.load(out).n_faces == r.soup.n_faces

    r = meshvis.remove_interior(soup)
    rep = _cli_report(["remove-interior", path, "-o", out], tmp_path)
    np.testing.assert_array_equal(np.array(rep["per_face"]["keep"], bool), r.keep)

    r = meshvis.layers(soup)
    rep = _cli_report(["layers", path, "-o", out], tmp_path)
    np.testing.assert_array_equal(np.array(rep["per_face"]["layer"]), r.layer)

    v = meshvis.visible_from(soup)
    rep = _cli_report(["visible", path], tmp_path)
    np.testing.assert_array_equal(_seen(rep), v.seen)


@pytest.mark.slow
@pytest.mark.parametrize("name", ["nested.glb", "wallhole.obj"])
def test_the_up_axis_is_the_models_both_ways(name, tmp_path):
    path = real_model(name)
    soup = meshvis.load(path)
    assert soup.up == (0.0, 1.0, 0.0)  # glTF and OBJ are y-up formats
    region = "upper-hemisphere"

    v = meshvis.visible_from(soup, region)
    rep = _cli_report(["visible", path, "--from", region], tmp_path)
    np.testing.assert_array_equal(_seen(rep), v.seen)
    z_up = meshvis.visible_from(soup, region, up="z")
    assert not np.array_equal(z_up.seen, v.seen)  # the up axis changes the answer here
    rep = _cli_report(["visible", path, "--from", region, "--up", "z"], tmp_path)
    np.testing.assert_array_equal(_seen(rep), z_up.seen)

    r = meshvis.remove_interior(soup, visibility="view", region=region)
    rep = _cli_report(
        ["remove-interior", path, "-o", str(tmp_path / "k.ply"), "--visibility", "view", "--from", region],
        tmp_path,
    )
    np.testing.assert_array_equal(np.array(rep["per_face"]["keep"], bool), r.keep)


def _options(parser: argparse.ArgumentParser, command: str) -> argparse.ArgumentParser:
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices[command]


#: the command line's words for library values
CLI_NAMES = {"up": {"auto": None}, "ground": GROUND_CHOICES}


@pytest.mark.parametrize("op", ["classify", "orient", "remove-interior", "layers"])
def test_cli_defaults_are_the_librarys(op):
    """Every option of a repair command defaults to the keyword default of the library."""
    args = build_parser(op).parse_args([op, "m.obj", *([] if op == "classify" else ["-o", "x.obj"])])
    for key, value in default_options(op).items():
        cli = getattr(args, key)
        if key in CLI_NAMES:  # options the command line names by words
            cli = CLI_NAMES[key].get(cli, cli)
        assert cli == value, key


def test_cli_defaults_follow_a_changed_library_default(monkeypatch):
    """A default changed in the library's signature reaches the command line and batch."""
    import inspect

    from meshvis.repair import operation, remove

    sig = inspect.signature(remove.remove_interior)
    changed = sig.replace(
        parameters=[p.replace(default=4) if p.name == "keep_border" else p for p in sig.parameters.values()]
    )
    monkeypatch.setattr(remove.remove_interior, "__signature__", changed, raising=False)
    operation._defaults.cache_clear()
    try:
        args = build_parser("remove-interior").parse_args(["remove-interior", "m.obj", "-o", "x.obj"])
        assert args.keep_border == 4
        assert operation.default_options("remove-interior")["keep_border"] == 4
    finally:
        monkeypatch.undo()
        operation._defaults.cache_clear()


def _help_lines(parser, name):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                yield from _help_lines(sub, f"{name} {sub_name}")
        elif action.option_strings and not isinstance(
            action, (argparse._HelpAction, argparse._VersionAction)
        ):
            flag = action.nargs == 0 or isinstance(action.default, bool) or action.required
            yield name, action, flag, parser.formatter_class(parser.prog)._get_help_string(action)


def test_every_help_text_shows_its_default():
    missing = [
        f"{name} {action.option_strings[0]}"
        for name, action, flag, text in _help_lines(build_parser(), "meshvis")
        if not flag and "default" not in text.lower()
    ]
    assert not missing


def test_a_reused_classification_with_another_budget_says_so(recwarn):
    """A classification made for orient gives the cut's sample points more rays than
    remove_interior's own cut: the faces kept can differ, and a warning says why."""
    from meshvis.eval import generators as g

    soup = g.overlapping_solids(subdivisions=2, cell=0.4).soup  # intersecting: sample points
    c = meshvis.classify(soup, seed=0)
    with pytest.warns(UserWarning, match="rays_per_point=8"):
        meshvis.remove_interior(soup, classification=c, seed=0, visibility="both")
    same = meshvis.classify(soup, seed=0, rays_per_point=8)  # the budget of the removal's own cut
    recwarn.clear()
    kept = meshvis.remove_interior(soup, classification=same, seed=0, visibility="both").keep
    assert not [w for w in recwarn if "rays_per_point" in str(w.message)]
    np.testing.assert_array_equal(kept, meshvis.remove_interior(soup, seed=0, visibility="both").keep)
