# SPDX-License-Identifier: GPL-3.0-or-later
"""The library's defaults and choices, read from its source without importing it.

Blender registers the add-on's properties, with their defaults, when it starts; importing
meshvis' repairs then (numba, SciPy, Embree) would add seconds to every start.  The
defaults are written once, in the library's signatures and constants, so they are read
from there: the source files are parsed (:mod:`ast`), not run.
"""

from __future__ import annotations

import ast
import importlib.util
import os
from functools import cache
from typing import Any


@cache
def _tree(module: str) -> ast.Module:
    with open(source_file(module), encoding="utf-8") as fh:
        return ast.parse(fh.read())


def source_file(module: str) -> str:
    """The file of a meshvis module, found without importing it or its packages.

    An installed meshvis has every module under its folder; a source checkout installed
    in development mode keeps ``labeling/`` and ``cli/`` beside ``meshvis/``.
    """
    top, *parts = module.split(".")
    spec = importlib.util.find_spec(top)  # a top-level name: nothing is imported
    if spec is None or spec.origin is None:
        raise ImportError(f"{top} is not installed")
    folder = os.path.dirname(spec.origin)
    for root in (folder, os.path.dirname(folder)):
        base = os.path.join(root, *parts)
        for path in (base + ".py", os.path.join(base, "__init__.py")):
            if os.path.isfile(path):
                return path
    raise ImportError(f"no source file of {module} under {folder}")


def keyword_default(module: str, function: str, keyword: str) -> Any:
    """The default of ``keyword`` in the signature of ``module.function``.

    Examples
    --------
    >>> keyword_default("meshvis.repair.remove", "remove_interior", "level")
    'face'
    """
    tree = _tree(module)
    for node in tree.body:
        if isinstance(node, ast.FunctionDef) and node.name == function:
            a = node.args
            positional = a.posonlyargs + a.args
            pairs = list(zip(positional[len(positional) - len(a.defaults) :], a.defaults))
            pairs += [(k, d) for k, d in zip(a.kwonlyargs, a.kw_defaults) if d is not None]
            for arg, default in pairs:
                if arg.arg == keyword:
                    return _value(module, default)
            raise KeyError(f"{module}.{function} has no default for {keyword}")
    raise KeyError(f"{module} has no function {function}")


def constant(module: str, name: str) -> Any:
    """The value of the module-level constant ``name`` of ``module`` (a literal).

    Examples
    --------
    >>> constant("meshvis.repair.remove_modes", "LEVELS")
    ('face', 'patch', 'part')
    """
    for node in _tree(module).body:
        target = node.target if isinstance(node, ast.AnnAssign) else None
        if isinstance(node, ast.Assign) and len(node.targets) == 1:
            target = node.targets[0]
        if isinstance(target, ast.Name) and target.id == name and node.value is not None:
            return _value(module, node.value)
    return _imported(module, name)


def _imported(module: str, name: str) -> Any:
    """The constant ``name`` that ``module`` imports from another meshvis module."""
    for stmt in _tree(module).body:
        if isinstance(stmt, ast.ImportFrom) and stmt.module and not stmt.level:
            for alias in stmt.names:
                if (alias.asname or alias.name) == name:
                    return constant(stmt.module, alias.name)
    raise KeyError(f"{module} has no constant {name}")


def _value(module: str, node: ast.expr) -> Any:
    """A literal, or a module-level constant of ``module`` or of a module it imports it from."""
    if isinstance(node, ast.Name):
        return constant(module, node.id)
    return ast.literal_eval(node)


#: where the library defines what the add-on offers
REMOVE = "meshvis.repair.remove"
REMOVE_MODES = "meshvis.repair.remove_modes"
LAYOUTS = "meshvis.labeling.candidates"


def removal() -> dict[str, Any]:
    """The choices and defaults of :func:`meshvis.remove_interior` that the add-on offers."""
    return {
        "visibility": keyword_default(REMOVE, "remove_interior", "visibility"),
        "visibility_modes": tuple(constant(REMOVE_MODES, "VISIBILITY_MODES")),
        "level": keyword_default(REMOVE, "remove_interior", "level"),
        "levels": tuple(constant(REMOVE_MODES, "LEVELS")),
        "transparent": keyword_default(REMOVE, "remove_interior", "transparent"),
    }


def labeling() -> dict[str, Any]:
    """The layouts of :func:`meshvis.labeling.layout` and its default."""
    names = [k.value for k in _dict_keys(LAYOUTS, "LAYOUTS")]
    return {
        "layout": keyword_default("meshvis.labeling.pipeline", "layout", "layout"),
        "layouts": tuple(names),
    }


def _dict_keys(module: str, name: str) -> list[ast.Constant]:
    for node in _tree(module).body:
        target = node.target if isinstance(node, ast.AnnAssign) else None
        if isinstance(target, ast.Name) and target.id == name and isinstance(node.value, ast.Dict):
            return [k for k in node.value.keys if isinstance(k, ast.Constant)]
    raise KeyError(f"{module} has no dictionary {name}")
