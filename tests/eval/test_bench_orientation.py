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
