"""The docstring examples of every module of the installed package run and give what they show.

The modules are found with pkgutil from the installed ``meshvis`` (so ``meshvis.labeling`` and
``meshvis.cli``, which live in other folders of the repository, are included), not from the
source tree.
"""

from __future__ import annotations

import doctest
import importlib
import pkgutil

import pytest

#: packages whose folders are walked: in an editable install meshvis.labeling and
#: meshvis.cli are mapped from other folders and are not under meshvis.__path__
ROOTS = ("meshvis", "meshvis.labeling", "meshvis.cli")


def _modules() -> list[str]:
    names = set(ROOTS)
    for root in ROOTS:
        package = importlib.import_module(root)
        for _, name, _ in pkgutil.walk_packages(package.__path__, prefix=root + "."):
            names.add(name)
    return sorted(n for n in names if not n.endswith("__main__"))


MODULES = _modules()
FLAGS = doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE
#: examples that take more than about half a second
SLOW = {"meshvis.eval.reference"}


def _examples() -> list:
    finder = doctest.DocTestFinder(exclude_empty=True)
    found = []
    for name in MODULES:
        module = importlib.import_module(name)
        for test in finder.find(module, name):
            if test.examples and test.name.startswith(name):
                marks = [pytest.mark.slow] if test.name in SLOW else []
                found.append(pytest.param(test, id=test.name, marks=marks))
    return found


EXAMPLES = _examples()


def test_modules_found():
    """The walk reaches the folders installed under other names."""
    assert {"meshvis.labeling", "meshvis.cli.main", "meshvis.io.obj", "meshvis.rays.caster"} <= set(MODULES)
    assert len(EXAMPLES) >= 10


@pytest.mark.parametrize("test", EXAMPLES)
def test_docstring_example(test, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # examples that write files write them here
    report: list[str] = []
    result = doctest.DocTestRunner(optionflags=FLAGS).run(test, out=report.append)
    if result.failed:
        pytest.fail("".join(report), pytrace=False)
