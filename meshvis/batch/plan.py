"""Which files a batch reads and where their results go: discovery and output names."""

from __future__ import annotations

import glob
import os
import warnings
from collections.abc import Sequence

from meshvis.errors import ParameterError
from meshvis.io import READ_FORMATS, WRITE_FORMATS
from meshvis.io.mtl import inside_folder
from meshvis.repair.operation import check_options

from .tasks import DEFAULT_RUNNER, OPERATIONS, FileTask


def _is_output_name(filename: str) -> bool:
    """True for files a batch writes (``x.<op>.<ext>``): never picked up as inputs."""
    stem = os.path.splitext(filename)[0]
    return any(stem.endswith("." + op) or stem.endswith(f".{op}.report") for op in OPERATIONS)


def _is_model_name(filename: str) -> bool:
    return (
        not filename.startswith(".")
        and os.path.splitext(filename)[1].lower() in READ_FORMATS
        and not _is_output_name(filename)
    )


def _walk(folder: str) -> list[str]:
    """Model files below ``folder``, sorted, hidden files and folders skipped."""
    found = []
    for root, dirs, files in os.walk(folder):
        dirs[:] = sorted(d for d in dirs if not d.startswith("."))
        found += [os.path.join(root, f) for f in sorted(files) if _is_model_name(f)]
    return found


def _glob_base(pattern: str) -> str:
    """The leading folders of a glob pattern that hold no wildcard."""
    parts = pattern.split(os.sep)
    keep = []
    for p in parts[:-1]:
        if glob.has_magic(p):
            break
        keep.append(p)
    return os.sep.join(keep) if keep else "."


def discover(inputs: Sequence[str]) -> list[tuple[str, str]]:
    """Expand files, folders and glob patterns into model files.

    Parameters
    ----------
    inputs : sequence of str
        Paths of files (taken as they are, whatever their extension), folders
        (searched recursively for files with a known model extension) and glob patterns
        (``*``, ``?``, ``[...]``; ``**`` spans folders).  Hidden files and folders, and
        files named like batch outputs (``*.orient.*``, ``*.remove-interior.*``,
        ``*.layers.*``), are skipped in folders and patterns, and so, with a warning, are
        files found there that lie outside the folder or the pattern's fixed leading
        folders (a symbolic link out of it, a pattern climbing out with ``..``).

    Returns
    -------
    list of (path, relative path)
        In input order, each folder's files sorted, duplicates (same real file) dropped.
        The relative path is the file name for a file, the path below the folder for a
        folder, and the path below the pattern's fixed leading folders for a pattern.

    Raises
    ------
    ParameterError
        An input that is neither a file nor a folder nor a pattern matching a model file.
    """
    out: list[tuple[str, str]] = []
    seen: set[str] = set()

    def add(path: str, rel: str, folder: str | None = None) -> None:
        key = os.path.realpath(path)
        if folder is not None and not inside_folder(path, folder):
            # a link out of the folder, or a pattern climbing out with "..": neither is read,
            # and the output name would leave --out
            warnings.warn(f"{path}: lies outside {folder} (a link or '..'); skipped", stacklevel=3)
        elif key not in seen:
            seen.add(key)
            out.append((path, rel))

    for spec in inputs:
        spec = os.fspath(spec)
        if os.path.isdir(spec):
            files = _walk(spec)
            if not files:
                raise ParameterError(
                    f"{spec}: no model files in this folder "
                    f"(known extensions: {', '.join(sorted(READ_FORMATS))})"
                )
            for f in files:
                add(f, os.path.relpath(f, spec), spec)
        elif os.path.lexists(spec):
            add(spec, os.path.basename(spec))
        elif glob.has_magic(spec):
            base = _glob_base(spec)
            matched = False
            for m in sorted(glob.glob(spec, recursive=True)):
                files = _walk(m) if os.path.isdir(m) else [m] if _is_model_name(os.path.basename(m)) else []
                for f in files:
                    add(f, os.path.relpath(f, base), base)
                matched = matched or bool(files)
            if not matched:
                raise ParameterError(f"{spec}: the pattern matches no model file")
        else:
            raise ParameterError(f"{spec}: no such file or folder")
    return out


def output_extension(path: str, op: str) -> str:
    """Extension of the output of ``op`` for input ``path``: the input's, unless it cannot hold the result.

    3MF (no writer) becomes ``.glb``, which keeps parts and materials; layers of an STL
    or OFF file become ``.ply``, whose face properties hold the layer of every face.
    """
    ext = os.path.splitext(path)[1]
    low = ext.lower()
    if low in READ_FORMATS and low not in WRITE_FORMATS:
        return ".glb"
    if op == "layers" and low in (".stl", ".off"):
        return ".ply"
    return ext


def plan(
    inputs: Sequence[str], op: str, out_dir: str, options: dict | None = None, runner: str = DEFAULT_RUNNER
) -> list[FileTask]:
    """Make the tasks of a batch: which file goes where.

    Output names are ``<relative path without extension>.<op>.<ext>`` (see
    :func:`discover`, :func:`output_extension`).  When two inputs would share an output
    name only because their extensions differ (``x.obj`` and ``x.stl``), both keep their
    extension in the name (``x.obj.<op>.obj``); any other clash (``a/y.obj`` and ``b/y.obj``
    given as files) gets ``-2``, ``-3``, ... in input order.

    Raises
    ------
    ParameterError
        Unknown operation, options that every file would fail on
        (:func:`meshvis.repair.operation.check_options`),
        inputs not found (see :func:`discover`), or an output that would overwrite one of
        the inputs.
    """
    if op not in OPERATIONS:
        raise ParameterError(f"unknown operation {op!r}; choose one of {', '.join(OPERATIONS)}")
    check_options(op, options or {})  # every file would fail on a bad option
    found = discover(inputs)
    if not found:
        raise ParameterError("no model file to run on: every file found lies outside its folder")
    names = [os.path.splitext(rel)[0] for _, rel in found]
    count: dict[str, int] = {}
    for key in [n.casefold() for n in names] + [rel.casefold() for _, rel in found]:
        count[key] = count.get(key, 0) + 1
    # x.obj next to x.stl: keep the extensions in the names; the same name twice: numbered below
    names = [
        rel if count[n.casefold()] > 1 and count[rel.casefold()] == 1 else n
        for n, (_, rel) in zip(names, found)
    ]
    used: set[str] = set()
    tasks = []
    in_paths = {os.path.realpath(p) for p, _ in found}
    for (path, _), name in zip(found, names):
        base, k = name, 1
        while name.casefold() in used:
            k += 1
            name = f"{base}-{k}"
        used.add(name.casefold())
        stem = os.path.join(out_dir, f"{name}.{op}")
        task = FileTask(
            input=path,
            name=name,
            output=stem + output_extension(path, op),
            report=stem + ".report.json",
            op=op,
            options=dict(options or {}),
            runner=runner,
        )
        for p in (task.output, task.report):
            if os.path.realpath(p) in in_paths:
                raise ParameterError(
                    f"{p}: the output of {path} would overwrite an input file; choose another --out"
                )
        tasks.append(task)
    return tasks


def default_jobs(n_tasks: int) -> int:
    """Worker processes by default: one per core, no more than there are files."""
    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return max(1, min(cores, n_tasks))
