"""What the labeling reads: models of named parts and optional label texts.

A model is a :class:`~meshvis.soup.Soup` whose ``part_id``/``part_names`` name the objects to
label (glTF nodes, OBJ objects or groups, ...).  Several files are combined into one soup
(:meth:`Soup.concatenate`); a file that holds a single unnamed part takes the file's
stem as its name, so ``skin.stl skull.stl`` label as "skin" and "skull".

Label texts default to the part names and can be overridden by a JSON object
(``{"part name": "label text"}``) or a two-column CSV file (``part name,label text``); an
empty text means "do not label this part".  Keys may also be part indices.
"""

from __future__ import annotations

import csv
import json
import os
from collections.abc import Mapping, Sequence
from typing import Any

from meshvis.errors import ModelError, ParameterError
from meshvis.io import as_soup, unique_names
from meshvis.soup import Soup


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


def read_texts(path: str | os.PathLike) -> dict[str, str]:
    """Read a label-text map from a ``.json`` object or a two-column ``.csv`` file."""
    path = os.fspath(path)
    if not os.path.isfile(path):
        raise ParameterError(f"{path}: label text file not found")
    try:
        if path.lower().endswith(".json"):
            with open(path, encoding="utf-8") as fh:
                data = json.load(fh)
            if not isinstance(data, dict):
                raise ParameterError(f"{path}: expected a JSON object mapping part names to texts")
            return {str(k): "" if v is None else str(v) for k, v in data.items()}
        with open(path, encoding="utf-8", newline="") as fh:
            rows = [r for r in csv.reader(fh) if r and not r[0].startswith("#")]
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ParameterError(f"{path}: cannot read label texts: {exc}") from None
    out = {}
    for k, row in enumerate(rows):
        if len(row) < 2:
            raise ParameterError(f"{path}: line {k + 1}: expected 'part name,label text'")
        out[row[0].strip()] = row[1].strip()
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
