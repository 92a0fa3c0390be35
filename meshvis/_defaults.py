"""The default of a library function's keyword, read from its source when that is enough.

The command line takes every default from the signature of the library function the
option is passed to (:func:`meshvis.repair.operation.library_default`), so each default is
written once.  Importing that function's module to read one would import what the module
runs on (numba, scipy, Embree: about half a second) before the command has even parsed
its arguments, and ``meshvis orient --help`` would pay it.  So the default is read from the
module's source instead: a literal, a module constant, a constant imported from another
module (``from m import NAME`` or ``m.NAME``), followed to where it is written.  Anything
else (a call, an expression, a decorated function, a name bound twice) is read the
ordinary way, by importing the module; a module imported already is always read that way.
"""

from __future__ import annotations

import ast
import functools
import importlib
import importlib.util
import inspect
import os
import sys
from typing import Any

#: returned by the source reader when the source does not settle the value
UNRESOLVED = object()
#: how many names a default may go through before the reader gives up (a cycle guard)
MAX_HOPS = 8


def signature_default(function: str, keyword: str) -> Any:
    """The default of ``keyword`` in the signature of ``function`` (``"module:name"``).

    Parameters
    ----------
    function : str
        ``"package.module:function"``.
    keyword : str
        A parameter of that function that has a default.

    Returns
    -------
    object
        Its default, equal to ``inspect.signature(function).parameters[keyword].default``.

    Examples
    --------
    >>> signature_default("meshvis.graphcut.classify:classify", "rays_per_node")
    32
    """
    module, _, name = function.partition(":")
    value = UNRESOLVED if module in sys.modules else source_default(module, name, keyword)
    if value is UNRESOLVED:
        fn = getattr(importlib.import_module(module), name)
        return inspect.signature(fn).parameters[keyword].default
    return value


def module_constant(constant: str) -> Any:
    """The module constant ``constant`` (``"module:NAME"``), read as :func:`signature_default` reads.

    Examples
    --------
    >>> module_constant("meshvis.limits:MAX_ZIP_ENTRIES") > 0
    True
    """
    module, _, name = constant.partition(":")
    value = UNRESOLVED if module in sys.modules else _constant(module, name, MAX_HOPS)
    if value is UNRESOLVED:
        return getattr(importlib.import_module(module), name)
    return value


def source_default(module: str, name: str, keyword: str) -> Any:
    """The default of ``keyword`` of the function ``name`` read from ``module``'s source.

    Returns :data:`UNRESOLVED` when the source alone does not settle it (see the module's
    description); the module itself is not imported (its parent packages are).
    """
    tree = _parse(module)
    if tree is None:
        return UNRESOLVED
    defs = [n for n in tree.body if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef)) and n.name == name]
    if len(defs) != 1 or defs[0].decorator_list or _bindings(tree).get(name, 0) != 1:
        return UNRESOLVED
    args = defs[0].args
    positional = args.posonlyargs + args.args
    pairs = list(zip(positional[len(positional) - len(args.defaults) :], args.defaults))
    pairs += [(a, d) for a, d in zip(args.kwonlyargs, args.kw_defaults) if d is not None]
    for arg, default in pairs:
        if arg.arg == keyword:
            return _value(module, default, MAX_HOPS)
    return UNRESOLVED


@functools.cache
def _parse(module: str) -> ast.Module | None:
    spec = _spec(module)
    if spec is None or not spec.origin or not spec.origin.endswith(".py"):
        return None
    with open(spec.origin, encoding="utf-8") as f:
        return ast.parse(f.read(), spec.origin)


def _bindings(tree: ast.Module) -> dict[str, int]:
    """How often each name is bound by a top-level statement of the module."""
    count: dict[str, int] = {}
    for node in tree.body:
        names: list[str] = []
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names = [node.name]
        elif isinstance(node, ast.Assign):
            names = [n.id for t in node.targets for n in ast.walk(t) if isinstance(n, ast.Name)]
        elif isinstance(node, (ast.AnnAssign, ast.AugAssign)) and isinstance(node.target, ast.Name):
            names = [node.target.id]
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names = [(a.asname or a.name).split(".")[0] for a in node.names]
        else:  # if / try / for / with blocks may bind anything: count every name they store
            names = [n.id for n in ast.walk(node) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)]
        for n in names:
            count[n] = count.get(n, 0) + 1
    return count


def _value(module: str, node: ast.expr, hops: int) -> Any:
    """The value of the expression ``node`` written at the top level of ``module``."""
    if hops <= 0:
        return UNRESOLVED
    try:
        return ast.literal_eval(node)
    except (ValueError, TypeError, SyntaxError, MemoryError, RecursionError):
        pass
    if isinstance(node, ast.Name):
        return _constant(module, node.id, hops - 1)
    if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
        target = _imported_module(module, node.value.id)
        if target is not None:
            return _constant(target, node.attr, hops - 1)
    if isinstance(node, (ast.Tuple, ast.List, ast.Dict)):
        return _container(module, node, hops)
    return UNRESOLVED


def _container(module: str, node: ast.Tuple | ast.List | ast.Dict, hops: int) -> Any:
    """A tuple, list or dictionary written with names, such as ``{"left": (WEST,)}``."""
    if isinstance(node, ast.Dict):
        keys = [k for k in node.keys if k is not None]
        if len(keys) < len(node.keys):  # a ``**mapping`` entry
            return UNRESOLVED
        items = [_value(module, e, hops - 1) for e in [*keys, *node.values]]
    else:
        items = [_value(module, e, hops - 1) for e in node.elts]
    if any(item is UNRESOLVED for item in items):
        return UNRESOLVED
    if isinstance(node, ast.Dict):
        half = len(node.keys)
        try:
            return dict(zip(items[:half], items[half:]))
        except TypeError:  # a key that cannot be one
            return UNRESOLVED
    return tuple(items) if isinstance(node, ast.Tuple) else items


def _constant(module: str, name: str, hops: int) -> Any:
    """The value of the top-level name ``name`` of ``module``, bound once by an assignment or import."""
    tree = _parse(module)
    if tree is None or _bindings(tree).get(name, 0) != 1:
        return UNRESOLVED
    for node in tree.body:
        if isinstance(node, ast.Assign) and len(node.targets) == 1:
            target = node.targets[0]
            if isinstance(target, ast.Name) and target.id == name:
                return _value(module, node.value, hops)
            if isinstance(target, ast.Tuple) and isinstance(node.value, ast.Tuple):
                # ``A, B = 0, 1``: the value at the name's place
                names = [t.id if isinstance(t, ast.Name) else None for t in target.elts]
                if name in names and len(names) == len(node.value.elts):
                    return _value(module, node.value.elts[names.index(name)], hops)
                if name in names:
                    return UNRESOLVED
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name) and node.target.id == name:
            return UNRESOLVED if node.value is None else _value(module, node.value, hops)
        elif isinstance(node, ast.ImportFrom):
            for alias in node.names:
                if (alias.asname or alias.name) == name:
                    source = _absolute(module, node)
                    if source is None or not _ours(source) or _is_submodule(source, alias.name):
                        return UNRESOLVED
                    return _constant(source, alias.name, hops - 1)
    return UNRESOLVED


def _imported_module(module: str, name: str) -> str | None:
    """The module that the top-level name ``name`` of ``module`` is bound to by an import, if any."""
    tree = _parse(module)
    if tree is None or _bindings(tree).get(name, 0) != 1:
        return None
    for node in tree.body:
        if isinstance(node, ast.ImportFrom):
            for alias in node.names:
                if (alias.asname or alias.name) == name:
                    source = _absolute(module, node)
                    ours = source is not None and _ours(source) and _is_submodule(source, alias.name)
                    return f"{source}.{alias.name}" if ours else None
        elif isinstance(node, ast.Import):
            for alias in node.names:
                if alias.asname == name or (alias.asname is None and alias.name == name):
                    return alias.name if _ours(alias.name) else None
    return None


def _absolute(module: str, node: ast.ImportFrom) -> str | None:
    """The absolute name of the module a ``from ... import`` statement of ``module`` reads."""
    if node.level == 0:
        return node.module
    tree_is_package = _parse_is_package(module)
    parts = module.split(".")
    base = parts if tree_is_package else parts[:-1]
    if node.level - 1 > len(base) - 1:
        return None
    base = base[: len(base) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _parse_is_package(module: str) -> bool:
    spec = _spec(module)
    return spec is not None and spec.submodule_search_locations is not None


def _ours(module: str) -> bool:
    """Whether the reader follows names into ``module``: meshvis' own modules only.

    Finding another package's module would import that package, which the reader avoids.
    """
    return module == "meshvis" or module.startswith("meshvis.")


def _is_submodule(package: str, name: str) -> bool:
    """Whether ``package.name`` is a module, found by its file (``package`` is not imported)."""
    spec = _spec(package)
    if spec is None or spec.submodule_search_locations is None:
        return False
    return any(
        os.path.isfile(os.path.join(folder, f"{name}.py")) or os.path.isdir(os.path.join(folder, name))
        for folder in spec.submodule_search_locations
    )


def _spec(module: str):
    """The module's spec, found without importing its parents below the top two levels.

    ``importlib.util.find_spec`` imports the parent package, and ``meshvis.visibility``
    or ``meshvis.labeling`` import numba when they are imported.
    """
    parent, _, name = module.rpartition(".")
    if parent.count(".") == 0 or parent in sys.modules:
        try:
            return importlib.util.find_spec(module)
        except (ImportError, ValueError):
            return None
    above = _spec(parent)
    for folder in (above.submodule_search_locations or []) if above is not None else []:
        package = os.path.join(folder, name, "__init__.py")
        if os.path.isfile(package):
            return importlib.util.spec_from_file_location(
                module, package, submodule_search_locations=[os.path.dirname(package)]
            )
        if os.path.isfile(os.path.join(folder, f"{name}.py")):
            return importlib.util.spec_from_file_location(module, os.path.join(folder, f"{name}.py"))
    return None
