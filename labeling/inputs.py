"""What the labeling reads: models of named parts, cameras and optional label texts.

A model is a :class:`~meshvis.soup.Soup` whose ``part_id``/``part_names`` name the objects to
label (glTF nodes, OBJ objects or groups, ...).  Several files are combined into one soup
(:meth:`Soup.concatenate`); a file that holds a single unnamed part takes the file's
stem as its name, so ``skin.stl skull.stl`` label as "skin" and "skull".

Cameras come from a JSON file of one camera (:func:`read_camera`) or of a list of them
(:func:`read_camera_path`, at most ``MAX_FRAMES`` of :mod:`meshvis.limits`).

Label texts default to the part names and can be overridden by a JSON object
(``{"part name": "label text"}``) or a two-column CSV file (``part name,label text``); an
empty text means "do not label this part".  Keys may also be part indices.  A text holds
at most :data:`MAX_TEXT_CHARS` characters.

Every problem found in one of these files is a :class:`~meshvis.errors.ParameterError`
whose message starts with the file's name.
"""

from __future__ import annotations

import csv
import os
from collections.abc import Mapping, Sequence
from typing import Any

from meshvis import _validate
from meshvis.errors import ModelError, ParameterError
from meshvis.io import as_soup, one_line, unique_names
from meshvis.io.jsonfile import read_json
from meshvis.rays.camera import Camera
from meshvis.soup import Soup

#: characters of one label text: a label is one line next to the model
MAX_TEXT_CHARS = 1_000


def _generic(name: str, index: int) -> bool:
    return not name or name == f"part{index}"


def load_models(model: Any) -> Soup:
    """One soup from a model, a path, or a list of them.

    Parameters
    ----------
    model : Soup, trimesh object, (vertices, faces), path, or a sequence of these

    Returns
    -------
    Soup
        Parts of later inputs follow those of earlier ones; a single-part input whose part
        has a generated name (``part0``) is renamed after its file stem.
    """
    if isinstance(model, (str, os.PathLike, Soup)) or not isinstance(model, (list, tuple)):
        items = [model]
    elif (
        len(model) == 2 and not isinstance(model[0], (str, os.PathLike, Soup)) and hasattr(model[0], "shape")
    ):
        items = [model]  # a (vertices, faces) pair
    else:
        items = list(model)
    if not items:
        raise ModelError("no model given")
    soups = []
    for item in items:
        soup = as_soup(item)
        if isinstance(item, (str, os.PathLike)) and soup.n_parts == 1 and _generic(soup.part_names[0], 0):
            soup = soup.copy()
            soup.part_names = [os.path.splitext(os.path.basename(os.fspath(item)))[0]]
        soups.append(soup)
    if len(soups) == 1:
        return soups[0]
    out = Soup.concatenate(soups)
    out.part_names = unique_names(out.part_names, "part")
    return out


def _side_file(path: str | os.PathLike, what: str) -> Any:
    """The JSON value of a side file, or a :class:`ParameterError` naming it."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ParameterError(
            f"{path}: {what} file not found" + ("" if not os.path.exists(path) else " (not a file)")
        )
    try:
        return read_json(path)
    except (OSError, ValueError) as exc:
        raise ParameterError(f"{path}: cannot read the {what}: {one_line(exc)}") from None


def read_camera(path: str | os.PathLike) -> Camera:
    """The camera of a JSON file holding one camera object (the keys of :meth:`Camera.to_json`).

    Raises
    ------
    ParameterError
        The file is missing, is not JSON, or does not hold a valid camera; the message
        starts with the file's name.
    """
    data = _side_file(path, "camera")
    try:
        return Camera.from_json(data)
    except (ParameterError, TypeError) as exc:
        raise ParameterError(f"{os.fspath(path)}: {one_line(exc)}") from None


def read_camera_path(path: str | os.PathLike) -> list[Camera]:
    """Cameras from a JSON file: a list of camera objects, or ``{"cameras": [...]}``.

    Each camera object has the keys of :meth:`Camera.to_json` (``position``, ``target``,
    optional ``up``, ``fov``, ``orthographic``, ``ortho_height``).

    Raises
    ------
    ParameterError
        The file is missing or not JSON, holds no camera or more than ``MAX_FRAMES`` of
        :mod:`meshvis.limits`, or a camera is not valid; the message starts with the file's
        name (and names the camera).
    """
    path = os.fspath(path)
    data = _side_file(path, "camera path")
    if isinstance(data, Mapping) and "cameras" in data:
        data = data["cameras"]
    if isinstance(data, Mapping):
        data = [data]
    if not isinstance(data, list) or not data:
        raise ParameterError(f"{path}: expected a list of cameras")
    try:
        _validate.frames(len(data))
    except ParameterError as exc:
        raise ParameterError(f"{path}: {exc}") from None
    cams = []
    for i, d in enumerate(data):
        try:
            cams.append(Camera.from_json(d))
        except (ParameterError, TypeError) as exc:
            raise ParameterError(f"{path}: camera {i}: {one_line(exc)}") from None
    return cams


def read_texts(path: str | os.PathLike, part_names: Sequence[str] | None = None) -> dict[str, str]:
    """Read a label-text map from a ``.json`` object or a two-column ``.csv`` file.

    Parameters
    ----------
    path : str or path-like
        The file.
    part_names : sequence of str, optional
        The model's parts: when given, every key must name one (by name or index).

    Raises
    ------
    ParameterError
        The file is missing or does not parse, a text is longer than
        :data:`MAX_TEXT_CHARS`, or a key names no part; the message starts with the file's
        name.
    """
    path = os.fspath(path)
    if path.lower().endswith(".json"):
        data = _side_file(path, "label texts")
        if not isinstance(data, dict):
            raise ParameterError(f"{path}: expected a JSON object mapping part names to texts")
        out = {str(k): "" if v is None else str(v) for k, v in data.items()}
    else:
        out = _csv_texts(path)
    for key, text in out.items():
        if len(text) > MAX_TEXT_CHARS:
            raise ParameterError(
                f"{path}: the label text of {key[:40]!r} has {len(text)} characters (at most {MAX_TEXT_CHARS})"
            )
    if part_names is not None:
        try:
            label_texts(part_names, out)
        except ParameterError as exc:
            raise ParameterError(f"{path}: {exc}") from None
    return out


def _csv_texts(path: str) -> dict[str, str]:
    """The rows ``part name,label text`` of a CSV file (``#`` lines are comments)."""
    if not os.path.isfile(path):
        raise ParameterError(f"{path}: label texts file not found")
    out = {}
    try:
        with open(path, encoding="utf-8-sig", newline="") as fh:
            reader = csv.reader(fh)
            for row in reader:
                if not row or row[0].startswith("#"):
                    continue
                if len(row) < 2:
                    raise ParameterError(f"{path}: line {reader.line_num}: expected 'part name,label text'")
                out[row[0].strip()] = row[1].strip()
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise ParameterError(f"{path}: cannot read the label texts: {one_line(exc)}") from None
    return out


def label_texts(part_names: Sequence[str], texts: Mapping[Any, str] | None = None) -> list[str]:
    """The text of every part: its name unless ``texts`` maps its name or index to another one.

    Raises
    ------
    ParameterError
        A key of ``texts`` names no part.
    """
    out = [str(n) for n in part_names]
    if not texts:
        return out
    index = {n: i for i, n in enumerate(part_names)}
    for key, text in texts.items():
        if isinstance(key, int) or (isinstance(key, str) and key not in index and key.isdigit()):
            i = int(key)
            if not 0 <= i < len(out):
                raise ParameterError(f"label text for part {i}: the model has {len(out)} parts")
        elif key in index:
            i = index[key]
        else:
            raise ParameterError(f"label text for {key!r}: no part of that name")
        out[i] = "" if text is None else " ".join(str(text).split())
    return out
