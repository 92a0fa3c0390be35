"""A feature whose optional dependency is missing fails at once with one line naming the
extra that installs it: MissingExtraError in the library, exit status 2 in the command."""

from __future__ import annotations

import sys

import pytest

from meshvis._extras import EXTRA_OF, import_extra
from meshvis.cli.main import main
from meshvis.errors import MeshvisError, MissingExtraError
from meshvis.eval import generators as G
from meshvis.io import save


def _block(monkeypatch, module: str) -> None:
    """Make ``import module`` fail as if it were not installed (None in sys.modules)."""
    for name in list(sys.modules):
        if name == module or name.startswith(module + "."):
            monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, module, None)


@pytest.mark.parametrize("module", sorted(EXTRA_OF))
def test_import_extra_names_the_extra(monkeypatch, module):
    _block(monkeypatch, module)
    with pytest.raises(MissingExtraError) as info:
        import_extra(module, "this feature")
    err = info.value
    assert isinstance(err, MeshvisError) and isinstance(err, ImportError)
    assert str(err) == (
        f'this feature needs {module}, which is not installed: pip install "meshvis[{EXTRA_OF[module]}]"'
    )


def test_import_extra_returns_the_module():
    import numpy

    assert EXTRA_OF and import_extra("numpy", "x") is numpy


def test_extras_are_declared_in_pyproject():
    """Every extra named in an error message exists in the installed metadata."""
    from importlib.metadata import metadata

    provided = set(metadata("meshvis").get_all("Provides-Extra") or [])
    assert set(EXTRA_OF.values()) <= provided


def test_library_baseline_raises(monkeypatch):
    from meshvis.eval import baselines

    _block(monkeypatch, "pymeshlab")
    with pytest.raises(MissingExtraError, match=r"meshvis\[bench\]"):
        baselines.pymeshlab_reorient(G.overlapping_solids(subdivisions=1, cell=0.5).soup)


@pytest.fixture
def model(tmp_path):
    path = tmp_path / "solids.obj"
    save(G.overlapping_solids(subdivisions=1, cell=0.5).soup, str(path))
    return str(path)


def _one_line_error(capsys, extra: str) -> None:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith("meshvis: error: ")
    assert f'pip install "meshvis[{extra}]"' in err


def test_cli_graphml_needs_graphml_extra(monkeypatch, capsys, model, tmp_path):
    _block(monkeypatch, "networkx")
    out = tmp_path / "g.graphml"
    assert main(["classify", model, "--graphml", str(out), "-q"]) == 2
    _one_line_error(capsys, "graphml")
    assert not out.exists()


@pytest.mark.parametrize("bench", ["compare", "accuracy"])
def test_cli_bench_baselines_need_bench_extra(monkeypatch, capsys, tmp_path, bench):
    _block(monkeypatch, "pymeshlab")
    args = ["bench", bench, "--quick", "--quiet"] + (
        ["--out", str(tmp_path / "o")] if bench == "accuracy" else []
    )
    assert main(args) == 2
    _one_line_error(capsys, "bench")


def test_cli_bench_labeling_needs_bench_extra(monkeypatch, capsys):
    _block(monkeypatch, "adjustText")
    assert main(["bench", "labeling"]) == 2
    _one_line_error(capsys, "bench")


def test_cli_batch_dask_needs_dask_extra(monkeypatch, capsys, model, tmp_path):
    _block(monkeypatch, "distributed")
    code = main(
        ["batch", model, "--op", "orient", "--out", str(tmp_path / "o"), "--dask-scheduler", "x:1", "-q"]
    )
    assert code == 2
    _one_line_error(capsys, "dask")
