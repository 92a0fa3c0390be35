"""What a command imports before it works: the start-up cost of ``meshvis`` kept down.

``meshvis info`` on a small STL needs numpy alone: not numba (its numpy kernels stand in for
the compiled ones below ``SMALL_MODEL_FACES`` faces), scipy, trimesh or Embree; on a larger
model it loads numba's compiled kernels and still no scipy module of its own.  A command's
parser needs no numerical module beyond numpy.  Each check runs in a fresh interpreter, as
the command does.
"""

from __future__ import annotations

import inspect
import subprocess
import sys

import pytest
from helpers import real_model

from meshvis._defaults import UNRESOLVED, module_constant, signature_default, source_default
from meshvis.repair import operation

#: modules ``meshvis info`` on an STL does without, whatever its size (numba, when a larger
#: model loads it, imports scipy itself, and scipy's BLAS wrappers, so those are not listed)
NOT_FOR_INFO = (
    "scipy.sparse",
    "scipy.spatial",
    "trimesh",
    "embreex",
    "matplotlib",
    "PIL",
    "rich",
    "igl",
    "maxflow",
)
#: modules no command's parser imports
NOT_FOR_A_PARSER = ("numba", "scipy", "trimesh", "embreex", "matplotlib", "PIL", "igl", "maxflow")
#: the commands whose parsers are held to that (label, view and bench read the labeling
#: package's tables and import every benchmark)
LIGHT_PARSERS = (
    "info",
    "render",
    "classify",
    "orient",
    "remove-interior",
    "layers",
    "visible",
    "batch",
    "demo",
)


def imported_after(code: str, names: tuple[str, ...]) -> set[str]:
    """The modules of ``names`` in ``sys.modules`` after running ``code`` in a fresh interpreter."""
    probe = f"{code}\nimport sys\nprint(' '.join(n for n in {names!r} if n in sys.modules))"
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    return set(out.split())


def info_imports(model: str, small_model_faces: int | None = None) -> set[str]:
    """The heavy modules ``meshvis info MODEL`` imports, with the small-model threshold set."""
    code = "import contextlib, io\nfrom meshvis.cli.main import main\n"
    if small_model_faces is not None:
        code += f"import meshvis.geometry._vectorised as v\nv.SMALL_MODEL_FACES = {small_model_faces}\n"
    code += f"with contextlib.redirect_stdout(io.StringIO()):\n    assert main(['info', {model!r}]) == 0"
    return imported_after(code, (*NOT_FOR_INFO, "numba", "scipy"))


def test_info_on_a_small_stl_imports_neither_numba_nor_scipy():
    model = real_model("soup.stl")
    assert info_imports(model) == set()


def test_info_on_a_larger_model_loads_the_compiled_kernels_and_nothing_else_heavy():
    # soup.stl (100 faces) made "larger" by a threshold of 10 faces
    assert info_imports(real_model("soup.stl"), small_model_faces=10) == {"numba", "scipy"}


@pytest.mark.parametrize("command", LIGHT_PARSERS)
def test_a_parser_imports_no_numerical_module(command):
    code = (
        "import contextlib, io\nfrom meshvis.cli.main import build_parser\n"
        f"with contextlib.suppress(SystemExit), contextlib.redirect_stdout(io.StringIO()):\n"
        f"    build_parser({command!r}).parse_args([{command!r}, '--help'])"
    )
    assert imported_after(code, NOT_FOR_A_PARSER) == set()


def cli_defaults() -> list[tuple[str, str]]:
    """Every (function, keyword) whose default the command line reads, with a default."""
    functions = {operation.CLASSIFY, "meshvis.rays.render:render", "meshvis.visibility.visible:visible_from"}
    functions |= {"meshvis.geometry.diagnostics:diagnose"}
    functions |= {fn for options in operation.OPERATION_OPTIONS.values() for fn, _ in options.values()}
    out = []
    for function in sorted(functions):
        module, _, name = function.partition(":")
        fn = getattr(__import__(module, fromlist=[name]), name)
        out += [
            (function, k) for k, p in inspect.signature(fn).parameters.items() if p.default is not p.empty
        ]
    return out


def test_every_cli_default_is_read_from_the_source_as_the_signature_has_it():
    pairs = cli_defaults()
    assert len(pairs) > 40
    for function, keyword in pairs:
        module, _, name = function.partition(":")
        fn = getattr(__import__(module, fromlist=[name]), name)
        expected = inspect.signature(fn).parameters[keyword].default
        value = source_default(module, name, keyword)
        assert value is not UNRESOLVED, (function, keyword)
        assert value == expected and type(value) is type(expected), (function, keyword)
        assert signature_default(function, keyword) == expected


def test_what_the_source_does_not_settle_is_imported(tmp_path, monkeypatch):
    (tmp_path / "meshvis_probe_mod.py").write_text(
        "import math\nLIMIT = 3\nTWICE = LIMIT * 2\n"
        "def f(a, b=LIMIT, c=math.pi, d=TWICE, *, e=(1, 'x')):\n    return a\n"
        "def g(a=LIMIT):\n    return a\ng = staticmethod(g)\n"
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    assert source_default("meshvis_probe_mod", "f", "b") == 3
    assert source_default("meshvis_probe_mod", "f", "e") == (1, "x")
    for keyword in ("c", "d"):  # another package's constant, an expression
        assert source_default("meshvis_probe_mod", "f", keyword) is UNRESOLVED
    assert source_default("meshvis_probe_mod", "g", "a") is UNRESOLVED  # g is bound twice
    assert "meshvis_probe_mod" not in sys.modules
    assert signature_default("meshvis_probe_mod:f", "d") == 6  # read by importing
    assert module_constant("meshvis_probe_mod:TWICE") == 6
    monkeypatch.delitem(sys.modules, "meshvis_probe_mod")


def test_the_program_exits_with_mains_status_and_skips_the_last_collection(tmp_path):
    model = real_model("soup.stl")
    probe = (
        "import atexit, gc, sys\n"
        "atexit.register(lambda: print('frozen', gc.get_freeze_count() > 0))\n"
        "sys.argv = ['meshvis', *sys.argv[1:]]\n"
        "from meshvis.cli.main import program\nprogram()"
    )
    ok = subprocess.run([sys.executable, "-c", probe, "info", model], capture_output=True, text=True)
    assert ok.returncode == 0 and ok.stdout.strip().endswith("frozen True")
    bad = subprocess.run(
        [sys.executable, "-m", "meshvis", "info", str(tmp_path / "none.stl")], capture_output=True
    )
    assert bad.returncode == 2
    assert subprocess.run([sys.executable, "-m", "meshvis", "--version"], capture_output=True).returncode == 0
