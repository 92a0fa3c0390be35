"""The package tree is the architecture: no import cycles, each layer imports only the layers
below it, and no library module imports the command line."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
#: source folder -> the package it installs as (pyproject's package-dir)
FOLDERS = {"meshvis": "meshvis", "labeling": "meshvis.labeling", "cli": "meshvis.cli"}
#: layer of each subpackage; a module may import its own layer and the ones below
LAYERS = {
    "meshvis._version": 0,
    "meshvis.errors": 0,
    "meshvis._extras": 0,
    "meshvis.soup": 0,
    "meshvis.limits": 0,
    "meshvis._validate": 0,
    "meshvis._threads": 0,
    "meshvis._defaults": 0,
    "meshvis.io": 1,
    "meshvis.rays": 2,
    "meshvis.geometry": 2,
    "meshvis.graphcut": 3,
    "meshvis.visibility": 3,
    "meshvis.viewcells": 4,
    "meshvis.repair": 4,
    "meshvis.batch": 5,
    "meshvis.labeling": 5,
    "meshvis.eval": 6,
    "meshvis.cli": 7,
    "meshvis.__main__": 7,
    "meshvis": 7,  # the package's __init__: lazy re-exports of the public API
}


def _modules() -> dict[str, Path]:
    out = {}
    for folder, package in FOLDERS.items():
        for path in (ROOT / folder).rglob("*.py"):
            parts = list(path.relative_to(ROOT / folder).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join([package, *parts])] = path
    return out


MODULES = _modules()


def _imports(name: str, path: Path) -> set[str]:
    """Every meshvis module that ``name`` imports, at module level or inside functions."""
    package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            # `from package import module` depends on the module, not on the package's __init__
            candidates = [
                f"{target}.{a.name}" if f"{target}.{a.name}" in MODULES else target for a in node.names
            ]
        elif isinstance(node, ast.Import):
            candidates = [a.name for a in node.names]
        else:
            continue
        found.update(c for c in candidates if c in MODULES and c != name)
    return found


GRAPH = {name: _imports(name, path) for name, path in MODULES.items()}


def _layer(name: str) -> int:
    best = max((k for k in LAYERS if name == k or name.startswith(k + ".")), key=len)
    return LAYERS[best]


def test_every_module_has_a_layer():
    assert all(any(m == k or m.startswith(k + ".") for k in LAYERS) for m in MODULES)


def test_no_import_cycles():
    # Tarjan's strongly connected components; a component of two or more modules is a cycle
    index, low, stack, on_stack, cycles = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in GRAPH[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                cycles.append(sorted(comp))

    for v in sorted(GRAPH):
        if v not in index:
            visit(v)
    assert cycles == []


@pytest.mark.parametrize("name", sorted(MODULES))
def test_imports_only_its_own_layer_and_below(name):
    upward = sorted(t for t in GRAPH[name] if _layer(t) > _layer(name))
    assert upward == [], f"{name} (layer {_layer(name)}) imports {upward}"


def test_the_library_never_imports_the_command_line():
    library = [m for m in MODULES if not m.startswith("meshvis.cli") and m != "meshvis.__main__"]
    assert [m for m in library if any(t.startswith("meshvis.cli") for t in GRAPH[m])] == []
